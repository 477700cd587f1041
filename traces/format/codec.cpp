// Little-endian field encoding of every trace record, chunk framing (zstd, CRC-32) and the
// consistency rules both the writer and the reader apply; see codec.h and traces/FORMAT.md.
#include "traces/format/codec.h"

#include <fmt/format.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <memory>
#include <set>

#include "model/common/depth.h"
#include "model/common/error.h"

namespace nbsim::trace {

namespace {

static_assert(sizeof(float) == 4 && std::numeric_limits<float>::is_iec559, "floats are IEEE-754 binary32");
static_assert(sizeof(double) == 8 && std::numeric_limits<double>::is_iec559, "doubles are IEEE-754 binary64");

constexpr bool kLittleHost = std::endian::native == std::endian::little;

// Appends little-endian fields to a payload.
class Out {
 public:
  void u8(std::uint8_t v) { bytes_.push_back(v); }
  void boolean(bool v) { u8(v ? 1 : 0); }
  void u32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void u64(std::uint64_t v) {
    for (int i = 0; i < 8; ++i) bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
  void f32(float v) { u32(std::bit_cast<std::uint32_t>(v)); }
  void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }
  void count(std::size_t n) {
    NBSIM_CHECK(n <= std::numeric_limits<std::uint32_t>::max(), "a vector of more than 2^32-1 elements");
    u32(static_cast<std::uint32_t>(n));
  }
  void str(const std::string& s) {
    count(s.size());
    bytes_.insert(bytes_.end(), s.begin(), s.end());
  }
  // 4-byte elements (float, int32, uint32) without a count.
  template <class T>
  void words(const std::vector<T>& v) {
    static_assert(sizeof(T) == 4);
    if constexpr (kLittleHost) {
      const std::size_t at = bytes_.size();
      bytes_.resize(at + 4 * v.size());
      if (!v.empty()) std::memcpy(bytes_.data() + at, v.data(), 4 * v.size());
    } else {
      for (const T& x : v) u32(std::bit_cast<std::uint32_t>(x));
    }
  }
  template <class T>
  void counted_words(const std::vector<T>& v) {
    count(v.size());
    words(v);
  }
  void aabbs(const std::vector<Aabb>& v) {
    count(v.size());
    for (const Aabb& b : v) {
      for (float x : b.lo) f32(x);
      for (float x : b.hi) f32(x);
    }
  }
  void reserve(std::size_t n) { bytes_.reserve(n); }
  std::vector<std::uint8_t> take() { return std::move(bytes_); }

 private:
  std::vector<std::uint8_t> bytes_;
};

// Reads little-endian fields from a payload; every read is bounds-checked, and counts are checked
// against the bytes left before anything is allocated.
class In {
 public:
  explicit In(std::span<const std::uint8_t> p) : p_(p) {}

  std::size_t left() const { return p_.size() - pos_; }

  std::uint8_t u8(const char* field) {
    need(1, field);
    return p_[pos_++];
  }
  bool boolean(const char* field) {
    const std::uint8_t v = u8(field);
    if (v > 1) throw InputError(fmt::format("field '{}' is {}, not 0 or 1", field, v));
    return v == 1;
  }
  std::uint32_t u32(const char* field) {
    need(4, field);
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(p_[pos_++]) << (8 * i);
    return v;
  }
  std::uint64_t u64(const char* field) {
    need(8, field);
    std::uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(p_[pos_++]) << (8 * i);
    return v;
  }
  std::int32_t i32(const char* field) { return static_cast<std::int32_t>(u32(field)); }
  float f32(const char* field) { return std::bit_cast<float>(u32(field)); }
  double f64(const char* field) { return std::bit_cast<double>(u64(field)); }

  // An enum stored as one byte with values 0..max.
  template <class E>
  E enumeration(const char* field, E max) {
    const std::uint8_t v = u8(field);
    if (v > static_cast<std::uint8_t>(max))
      throw InputError(fmt::format("field '{}' is {}, outside the valid values 0..{}", field, v,
                                   static_cast<unsigned>(max)));
    return static_cast<E>(v);
  }

  // A u32 element count whose elements (elem_bytes each) must fit in the bytes left.
  std::size_t count(std::size_t elem_bytes, const char* field) {
    const std::uint32_t n = u32(field);
    if (n > left() / elem_bytes)
      throw InputError(fmt::format("field '{}' counts {} elements of {} bytes, but only {} payload bytes are left "
                                   "(it decodes short)", field, n, elem_bytes, left()));
    return n;
  }
  std::string str(std::size_t max_bytes, const char* field) {
    const std::size_t n = count(1, field);
    if (n > max_bytes)
      throw InputError(fmt::format("field '{}' is a string of {} bytes, above the limit of {}", field, n, max_bytes));
    std::string s(reinterpret_cast<const char*>(p_.data() + pos_), n);
    pos_ += n;
    return s;
  }
  // n 4-byte elements without a count (n already checked against left() by the caller or here).
  template <class T>
  void words(std::vector<T>& v, std::size_t n, const char* field) {
    static_assert(sizeof(T) == 4);
    if (n > left() / 4)
      throw InputError(fmt::format("field '{}' needs {} elements of 4 bytes, but only {} payload bytes are left "
                                   "(it decodes short)", field, n, left()));
    v.resize(n);
    if constexpr (kLittleHost) {
      if (n) std::memcpy(v.data(), p_.data() + pos_, 4 * n);
      pos_ += 4 * n;
    } else {
      for (T& x : v) x = std::bit_cast<T>(u32(field));
    }
  }
  template <class T>
  void counted_words(std::vector<T>& v, const char* field) {
    words(v, count(4, field), field);
  }
  void aabbs(std::vector<Aabb>& v, const char* field) {
    v.resize(count(24, field));
    for (Aabb& b : v) {
      for (float& x : b.lo) x = f32(field);
      for (float& x : b.hi) x = f32(field);
    }
  }
  // The whole payload must be used: bytes left over mean a damaged or mismatched record.
  void finish() const {
    if (pos_ != p_.size())
      throw InputError(fmt::format("{} bytes are left over after the last field (the payload of {} bytes decodes long)",
                                   p_.size() - pos_, p_.size()));
  }

 private:
  void need(std::size_t n, const char* field) const {
    if (left() < n)
      throw InputError(fmt::format("the payload of {} bytes ends at byte {} while reading field '{}' (it decodes short)",
                                   p_.size(), pos_, field));
  }

  std::span<const std::uint8_t> p_;
  std::size_t pos_ = 0;
};

void check_version(std::uint32_t version) {
  NBSIM_CHECK(version >= 1 && version <= kFormatVersion, fmt::format("decoding format version {}", version));
}

// A record that decoded but breaks a rule of the format.
void refuse_problem(const std::string& problem) {
  if (!problem.empty()) throw InputError(problem);
}

bool good_key_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '.' || c == '-';
}

std::string image_size_problem(const char* what, std::int32_t w, std::int32_t h) {
  if (w < 1 || h < 1 || w > kMaxImageSide || h > kMaxImageSide)
    return fmt::format("{} size {}x{} is outside 1x1 .. {}x{}", what, w, h, kMaxImageSide, kMaxImageSide);
  return {};
}

std::uint64_t area(std::int32_t w, std::int32_t h) {
  return static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h);
}

}  // namespace

bool is_known_chunk_type(std::uint32_t type) noexcept {
  switch (static_cast<ChunkType>(type)) {
    case ChunkType::Header:
    case ChunkType::Scene:
    case ChunkType::FrameBegin:
    case ChunkType::Draw:
    case ChunkType::Depth:
    case ChunkType::Levels:
    case ChunkType::Truth:
    case ChunkType::FrameEnd:
    case ChunkType::End:
      return true;
  }
  return false;
}

std::string chunk_type_name(std::uint32_t type) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const auto c = static_cast<char>((type >> (8 * i)) & 0xFF);
    if (c < 0x20 || c > 0x7E) return fmt::format("0x{:08x}", type);
    s += c;
  }
  return s;
}

std::uint32_t crc32(std::span<const std::uint8_t> bytes, std::uint32_t crc) noexcept {
  return static_cast<std::uint32_t>(::crc32_z(crc, bytes.data(), bytes.size()));
}

std::array<std::uint8_t, kPreambleBytes> encode_preamble(std::uint32_t version) {
  std::array<std::uint8_t, kPreambleBytes> p{};
  std::copy(kMagic.begin(), kMagic.end(), p.begin());
  for (int i = 0; i < 4; ++i) p[8 + i] = static_cast<std::uint8_t>(version >> (8 * i));
  const std::uint32_t crc = crc32(std::span(p).first(12));
  for (int i = 0; i < 4; ++i) p[12 + i] = static_cast<std::uint8_t>(crc >> (8 * i));
  return p;
}

std::vector<std::uint8_t> encode_chunk(ChunkType type, std::span<const std::uint8_t> payload, bool compress) {
  if (payload.size() > kMaxChunkBytes)
    throw InputError(fmt::format("a {} record of {} bytes exceeds the trace format's chunk limit of {} MiB",
                                 chunk_type_name(type), payload.size(), kMaxChunkBytes >> 20));
  // One buffer for header, payload and CRC: the payload is compressed (or copied) in place.
  compress = compress && payload.size() >= kCompressMinBytes;
  const std::size_t room = compress ? std::max(ZSTD_compressBound(payload.size()), payload.size()) : payload.size();
  std::vector<std::uint8_t> bytes(kChunkHeaderBytes + room + kChunkCrcBytes);
  std::uint8_t* body = bytes.data() + kChunkHeaderBytes;
  std::size_t stored = payload.size();
  std::uint32_t flags = 0;
  if (compress) {
    // One context per thread: creating one costs more than compressing a small payload.
    thread_local std::unique_ptr<ZSTD_CCtx, decltype(&ZSTD_freeCCtx)> ctx(ZSTD_createCCtx(), &ZSTD_freeCCtx);
    NBSIM_CHECK(ctx != nullptr, "ZSTD_createCCtx failed");
    const std::size_t n = ZSTD_compressCCtx(ctx.get(), body, room, payload.data(), payload.size(), kZstdLevel);
    NBSIM_CHECK(!ZSTD_isError(n), fmt::format("zstd compression failed: {}", ZSTD_getErrorName(n)));
    if (n < payload.size()) {
      stored = n;
      flags = kFlagZstd;
    }
  }
  if (!(flags & kFlagZstd) && !payload.empty()) std::memcpy(body, payload.data(), payload.size());
  Out header;
  header.u32(static_cast<std::uint32_t>(type));
  header.u32(flags);
  header.u64(stored);
  header.u64(payload.size());
  const std::vector<std::uint8_t> head = header.take();
  std::copy(head.begin(), head.end(), bytes.begin());
  bytes.resize(kChunkHeaderBytes + stored + kChunkCrcBytes);
  const std::uint32_t crc = crc32(std::span(bytes).first(kChunkHeaderBytes + stored));
  for (std::size_t i = 0; i < 4; ++i) bytes[kChunkHeaderBytes + stored + i] = static_cast<std::uint8_t>(crc >> (8 * i));
  return bytes;
}

// ---- consistency rules ------------------------------------------------------------------------

std::string record_problem(const Properties& properties) {
  if (properties.size() > kMaxProperties)
    return fmt::format("{} properties, above the limit of {}", properties.size(), kMaxProperties);
  std::set<std::string_view> seen;
  for (const auto& [key, value] : properties) {
    if (key.empty() || key.size() > kMaxKeyBytes || !std::all_of(key.begin(), key.end(), good_key_char))
      return fmt::format("property key '{}' is not 1 to {} characters of A-Z a-z 0-9 _ . -", key, kMaxKeyBytes);
    if (!seen.insert(key).second) return fmt::format("property key '{}' appears twice", key);
    if (value.size() > kMaxValueBytes)
      return fmt::format("property '{}' has a value of {} bytes, above the limit of {}", key, value.size(), kMaxValueBytes);
  }
  return {};
}

std::string record_problem(const SceneObjects& s) {
  if (s.triangles.size() != s.objects.size())
    return fmt::format("{} triangle counts for {} objects", s.triangles.size(), s.objects.size());
  const std::size_t m = s.node_bounds.size();
  if (s.node_left.size() != m || s.node_right.size() != m || s.node_first.size() != m || s.node_count.size() != m)
    return fmt::format("BVH vectors of different sizes (bounds {}, left {}, right {}, first {}, count {})", m,
                       s.node_left.size(), s.node_right.size(), s.node_first.size(), s.node_count.size());
  std::vector<std::uint8_t> parents(m, 0);
  for (std::size_t i = 0; i < m; ++i) {
    const std::int32_t l = s.node_left[i], r = s.node_right[i];
    for (const std::int32_t c : {l, r}) {
      if (c < -1 || c >= static_cast<std::int64_t>(m))
        return fmt::format("BVH node {} has child {}, outside -1 .. {}", i, c, static_cast<std::int64_t>(m) - 1);
      if (c >= 0 && ++parents[static_cast<std::size_t>(c)] > 1)
        return fmt::format("BVH node {} has more than one parent", c);
    }
    if ((l < 0) != (r < 0)) return fmt::format("BVH node {} has one child ({}, {}); nodes have two or none", i, l, r);
    if (static_cast<std::uint64_t>(s.node_first[i]) + s.node_count[i] > s.leaf_objects.size())
      return fmt::format("BVH node {} lists leaf objects [{}, {}) beyond the {} leaf entries", i, s.node_first[i],
                         static_cast<std::uint64_t>(s.node_first[i]) + s.node_count[i], s.leaf_objects.size());
  }
  // With at most one parent each, the nodes form a forest unless some lie on a cycle; those are
  // exactly the nodes not reachable from a parentless node.
  std::vector<std::uint8_t> reached(m, 0);
  std::vector<std::size_t> stack;
  for (std::size_t i = 0; i < m; ++i) {
    if (parents[i] != 0) continue;
    stack.push_back(i);
    while (!stack.empty()) {
      const std::size_t n = stack.back();
      stack.pop_back();
      reached[n] = 1;
      if (s.node_left[n] >= 0) stack.push_back(static_cast<std::size_t>(s.node_left[n]));
      if (s.node_right[n] >= 0) stack.push_back(static_cast<std::size_t>(s.node_right[n]));
    }
  }
  for (std::size_t i = 0; i < m; ++i)
    if (!reached[i]) return fmt::format("BVH node {} lies on a cycle", i);
  for (std::size_t i = 0; i < s.leaf_objects.size(); ++i)
    if (s.leaf_objects[i] >= s.objects.size())
      return fmt::format("leaf entry {} names object {}, but the scene has {} objects", i, s.leaf_objects[i], s.objects.size());
  return {};
}

std::string record_problem(const DrawRecord& d) {
  if (static_cast<std::uint8_t>(d.role) > static_cast<std::uint8_t>(DrawRole::IdBuffer))
    return fmt::format("draw role {} is not a DrawRole", static_cast<unsigned>(d.role));
  if (static_cast<std::uint8_t>(d.state.func) > static_cast<std::uint8_t>(DepthFunc::Always))
    return fmt::format("depth func {} is not a DepthFunc", static_cast<unsigned>(d.state.func));
  if (static_cast<std::uint8_t>(d.state.cull) > static_cast<std::uint8_t>(CullFace::FrontAndBack))
    return fmt::format("cull face {} is not a CullFace", static_cast<unsigned>(d.state.cull));
  if (static_cast<std::uint8_t>(d.state.clip) > static_cast<std::uint8_t>(ClipControl::ZeroToOne))
    return fmt::format("clip control {} is not a ClipControl", static_cast<unsigned>(d.state.clip));
  if (d.level >= kMaxLevels) return fmt::format("N-buffer level {} is not below {}", d.level, kMaxLevels);
  if (d.object < -1) return fmt::format("object id {} is below -1", d.object);
  if (d.node < -1) return fmt::format("BVH node id {} is below -1", d.node);
  if (d.bounds.w < 0 || d.bounds.h < 0)
    return fmt::format("bounds rectangle {}x{} has a negative side", d.bounds.w, d.bounds.h);
  return {};
}

std::string record_problem(const DepthSnapshot& d) {
  if (static_cast<std::uint8_t>(d.which) > static_cast<std::uint8_t>(DepthWhich::Final))
    return fmt::format("depth snapshot kind {} is not a DepthWhich", static_cast<unsigned>(d.which));
  if (auto p = image_size_problem("depth snapshot", d.width, d.height); !p.empty()) return p;
  if (d.texels.size() != area(d.width, d.height))
    return fmt::format("depth snapshot of {}x{} holds {} texels", d.width, d.height, d.texels.size());
  return {};
}

std::string record_problem(const NBufferLevels& l) {
  if (l.op > static_cast<std::uint8_t>(FarOp::Min)) return fmt::format("N-buffer op {} is not a FarOp", l.op);
  if (auto p = image_size_problem("N-buffer", l.width, l.height); !p.empty()) return p;
  if (l.levels < 1 || l.levels > kMaxLevels)
    return fmt::format("N-buffer level count {} is outside 1 .. {}", l.levels, kMaxLevels);
  if (l.texels.size() != area(l.width, l.height) * static_cast<std::uint64_t>(l.levels))
    return fmt::format("N-buffer of {} levels of {}x{} holds {} texels", l.levels, l.width, l.height, l.texels.size());
  return {};
}

std::string record_problem(const GroundTruth& t) {
  if (t.id_width == 0 && t.id_height == 0) {
    if (!t.ids.empty()) return fmt::format("ground truth holds {} ID-buffer pixels but no ID-buffer size", t.ids.size());
    return {};
  }
  if (auto p = image_size_problem("ID buffer", t.id_width, t.id_height); !p.empty()) return p;
  if (t.ids.size() != area(t.id_width, t.id_height))
    return fmt::format("ID buffer of {}x{} holds {} pixels", t.id_width, t.id_height, t.ids.size());
  if (const auto it = std::find_if(t.ids.begin(), t.ids.end(), [](std::int32_t id) { return id < -1; }); it != t.ids.end())
    return fmt::format("ID buffer pixel {} holds id {}, below -1", it - t.ids.begin(), *it);
  return {};
}

// ---- encoders (layout of kFormatVersion; FORMAT.md has one table per record) ------------------

std::vector<std::uint8_t> encode(const Properties& properties) {
  Out o;
  o.count(properties.size());
  for (const auto& [key, value] : properties) {
    o.str(key);
    o.str(value);
  }
  return o.take();
}

std::vector<std::uint8_t> encode(const SceneObjects& s) {
  Out o;
  o.reserve(28 + 28 * s.objects.size() + 40 * s.node_bounds.size() + 4 * s.leaf_objects.size());
  o.aabbs(s.objects);
  o.counted_words(s.triangles);
  o.aabbs(s.node_bounds);
  o.counted_words(s.node_left);
  o.counted_words(s.node_right);
  o.counted_words(s.node_first);
  o.counted_words(s.node_count);
  o.counted_words(s.leaf_objects);
  return o.take();
}

std::vector<std::uint8_t> encode(const FrameBegin& f) {
  Out o;
  o.u32(f.frame);
  o.u8(static_cast<std::uint8_t>(f.mode));
  for (float v : f.view) o.f32(v);
  for (float v : f.proj) o.f32(v);
  for (float v : f.eye) o.f32(v);
  return o.take();
}

std::vector<std::uint8_t> encode(const DrawRecord& d) {
  Out o;
  o.reserve(96 + 16 * d.clip_positions.size());
  o.u32(d.index);
  o.u8(static_cast<std::uint8_t>(d.role));
  o.i32(d.object);
  o.i32(d.node);
  o.u8(d.level);
  o.u8(static_cast<std::uint8_t>(d.state.func));
  o.boolean(d.state.write);
  o.boolean(d.state.test);
  o.u8(static_cast<std::uint8_t>(d.state.cull));
  o.boolean(d.state.front_ccw);
  o.u8(static_cast<std::uint8_t>(d.state.clip));
  o.boolean(d.state.depth_clamp);
  o.count(d.clip_positions.size());
  for (const auto& p : d.clip_positions)
    for (float v : p) o.f32(v);
  o.boolean(d.has_bounds);
  o.i32(d.bounds.x);
  o.i32(d.bounds.y);
  o.i32(d.bounds.w);
  o.i32(d.bounds.h);
  o.f32(d.bounds.nearest_depth);
  o.boolean(d.bounds.crosses_near);
  o.boolean(d.bounds.visible);
  o.u64(d.gl.fragments);
  o.u64(d.gl.samples_passed);
  o.u64(d.gl.clip_prims_in);
  o.u64(d.gl.clip_prims_out);
  return o.take();
}

std::vector<std::uint8_t> encode(const DepthSnapshot& d) {
  Out o;
  o.reserve(9 + 4 * d.texels.size());
  o.u8(static_cast<std::uint8_t>(d.which));
  o.i32(d.width);
  o.i32(d.height);
  o.words(d.texels);
  return o.take();
}

std::vector<std::uint8_t> encode(const NBufferLevels& l) {
  Out o;
  o.reserve(13 + 4 * l.texels.size());
  o.u8(l.op);
  o.i32(l.width);
  o.i32(l.height);
  o.i32(l.levels);
  o.words(l.texels);
  return o.take();
}

std::vector<std::uint8_t> encode(const GroundTruth& t) {
  Out o;
  o.reserve(24 + 4 * t.visible_pixels.size() + 4 * t.ids.size());
  o.counted_words(t.visible_pixels);
  o.u64(t.covered_pixels);
  o.i32(t.id_width);
  o.i32(t.id_height);
  o.words(t.ids);
  return o.take();
}

std::vector<std::uint8_t> encode(const FrameEnd& f) {
  Out o;
  o.u32(f.frame);
  o.u32(f.draws);
  o.f64(f.gl_ms);
  return o.take();
}

std::vector<std::uint8_t> encode(const EndMarker& e) {
  Out o;
  o.u64(e.chunks);
  o.u32(e.frames);
  return o.take();
}

// ---- decoders ---------------------------------------------------------------------------------
// Each reads the fields of version 1 in order. A field added in version N is read under
// `if (version >= N)` (older files keep its default), so every older version still reads.

Properties decode_properties(std::span<const std::uint8_t> payload, std::uint32_t version) {
  check_version(version);
  In in(payload);
  Properties props;
  const std::size_t n = in.count(8, "property count");  // a key and a value: two u32 lengths at least
  if (n > kMaxProperties) throw InputError(fmt::format("{} properties, above the limit of {}", n, kMaxProperties));
  props.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::string key = in.str(kMaxKeyBytes, "property key");
    std::string value = in.str(kMaxValueBytes, "property value");
    props.emplace_back(std::move(key), std::move(value));
  }
  in.finish();
  refuse_problem(record_problem(props));
  return props;
}

SceneObjects decode_scene(std::span<const std::uint8_t> payload, std::uint32_t version) {
  check_version(version);
  In in(payload);
  SceneObjects s;
  in.aabbs(s.objects, "objects");
  in.counted_words(s.triangles, "triangles");
  in.aabbs(s.node_bounds, "node_bounds");
  in.counted_words(s.node_left, "node_left");
  in.counted_words(s.node_right, "node_right");
  in.counted_words(s.node_first, "node_first");
  in.counted_words(s.node_count, "node_count");
  in.counted_words(s.leaf_objects, "leaf_objects");
  in.finish();
  refuse_problem(record_problem(s));
  return s;
}

FrameBegin decode_frame_begin(std::span<const std::uint8_t> payload, std::uint32_t version) {
  check_version(version);
  In in(payload);
  FrameBegin f;
  f.frame = in.u32("frame");
  f.mode = in.enumeration("mode", TestMode::None);
  for (float& v : f.view) v = in.f32("view");
  for (float& v : f.proj) v = in.f32("proj");
  for (float& v : f.eye) v = in.f32("eye");
  in.finish();
  return f;
}

DrawRecord decode_draw(std::span<const std::uint8_t> payload, std::uint32_t version) {
  check_version(version);
  In in(payload);
  DrawRecord d;
  d.index = in.u32("index");
  d.role = in.enumeration("role", DrawRole::IdBuffer);
  d.object = in.i32("object");
  d.node = in.i32("node");
  d.level = in.u8("level");
  d.state.func = in.enumeration("state.func", DepthFunc::Always);
  d.state.write = in.boolean("state.write");
  d.state.test = in.boolean("state.test");
  d.state.cull = in.enumeration("state.cull", CullFace::FrontAndBack);
  d.state.front_ccw = in.boolean("state.front_ccw");
  d.state.clip = in.enumeration("state.clip", ClipControl::ZeroToOne);
  d.state.depth_clamp = in.boolean("state.depth_clamp");
  d.clip_positions.resize(in.count(16, "clip_positions"));
  for (auto& p : d.clip_positions)
    for (float& v : p) v = in.f32("clip_positions");
  d.has_bounds = in.boolean("has_bounds");
  d.bounds.x = in.i32("bounds.x");
  d.bounds.y = in.i32("bounds.y");
  d.bounds.w = in.i32("bounds.w");
  d.bounds.h = in.i32("bounds.h");
  d.bounds.nearest_depth = in.f32("bounds.nearest_depth");
  d.bounds.crosses_near = in.boolean("bounds.crosses_near");
  d.bounds.visible = in.boolean("bounds.visible");
  d.gl.fragments = in.u64("gl.fragments");
  d.gl.samples_passed = in.u64("gl.samples_passed");
  d.gl.clip_prims_in = in.u64("gl.clip_prims_in");
  d.gl.clip_prims_out = in.u64("gl.clip_prims_out");
  in.finish();
  refuse_problem(record_problem(d));
  return d;
}

DepthSnapshot decode_depth(std::span<const std::uint8_t> payload, std::uint32_t version) {
  check_version(version);
  In in(payload);
  DepthSnapshot d;
  d.which = in.enumeration("which", DepthWhich::Final);
  d.width = in.i32("width");
  d.height = in.i32("height");
  refuse_problem(image_size_problem("depth snapshot", d.width, d.height));
  in.words(d.texels, area(d.width, d.height), "texels");
  in.finish();
  return d;
}

NBufferLevels decode_levels(std::span<const std::uint8_t> payload, std::uint32_t version) {
  check_version(version);
  In in(payload);
  NBufferLevels l;
  l.op = static_cast<std::uint8_t>(in.enumeration("op", FarOp::Min));
  l.width = in.i32("width");
  l.height = in.i32("height");
  l.levels = in.i32("levels");
  refuse_problem(image_size_problem("N-buffer", l.width, l.height));
  if (l.levels < 1 || l.levels > kMaxLevels)
    throw InputError(fmt::format("N-buffer level count {} is outside 1 .. {}", l.levels, kMaxLevels));
  in.words(l.texels, area(l.width, l.height) * static_cast<std::uint64_t>(l.levels), "texels");
  in.finish();
  return l;
}

GroundTruth decode_truth(std::span<const std::uint8_t> payload, std::uint32_t version) {
  check_version(version);
  In in(payload);
  GroundTruth t;
  in.counted_words(t.visible_pixels, "visible_pixels");
  t.covered_pixels = in.u64("covered_pixels");
  t.id_width = in.i32("id_width");
  t.id_height = in.i32("id_height");
  if (t.id_width != 0 || t.id_height != 0) {
    refuse_problem(image_size_problem("ID buffer", t.id_width, t.id_height));
    in.words(t.ids, area(t.id_width, t.id_height), "ids");
  }
  in.finish();
  refuse_problem(record_problem(t));
  return t;
}

FrameEnd decode_frame_end(std::span<const std::uint8_t> payload, std::uint32_t version) {
  check_version(version);
  In in(payload);
  FrameEnd f;
  f.frame = in.u32("frame");
  f.draws = in.u32("draws");
  f.gl_ms = in.f64("gl_ms");
  in.finish();
  return f;
}

EndMarker decode_end(std::span<const std::uint8_t> payload, std::uint32_t version) {
  check_version(version);
  In in(payload);
  EndMarker e;
  e.chunks = in.u64("chunks");
  e.frames = in.u32("frames");
  in.finish();
  return e;
}

}  // namespace nbsim::trace

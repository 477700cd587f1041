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
#include <type_traits>

#include "model/common/depth.h"
#include "model/common/error.h"
#include "traces/format/bytes.h"
#include "traces/format/schema.h"

namespace nbsim::trace {

namespace {

using bytes::In;
using bytes::kLittleHost;
using bytes::Out;

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

// The byte offset of the first byte that breaks UTF-8 (RFC 3629: no overlong forms, no
// surrogates, nothing above U+10FFFF), or npos when `s` is valid UTF-8. Header values end up in
// JSON (run.json, `trace info --json`), which holds only valid UTF-8.
std::size_t invalid_utf8_at(std::string_view s) {
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(s[i]); };
  std::size_t i = 0;
  while (i < s.size()) {
    const unsigned char c = byte(i);
    std::size_t n = 0;      // continuation bytes
    unsigned lo = 0x80, hi = 0xBF;  // the range of the first continuation byte
    if (c < 0x80) n = 0;
    else if (c >= 0xC2 && c <= 0xDF) n = 1;
    else if (c == 0xE0) n = 2, lo = 0xA0;
    else if ((c >= 0xE1 && c <= 0xEC) || c == 0xEE || c == 0xEF) n = 2;
    else if (c == 0xED) n = 2, hi = 0x9F;  // not the surrogates U+D800 .. U+DFFF
    else if (c == 0xF0) n = 3, lo = 0x90;
    else if (c >= 0xF1 && c <= 0xF3) n = 3;
    else if (c == 0xF4) n = 3, hi = 0x8F;  // not above U+10FFFF
    else return i;
    if (s.size() - i - 1 < n) return i;
    for (std::size_t k = 1; k <= n; ++k) {
      const unsigned b = byte(i + k);
      if (b < (k == 1 ? lo : 0x80u) || b > (k == 1 ? hi : 0xBFu)) return i;
    }
    i += n + 1;
  }
  return std::string_view::npos;
}

}  // namespace

std::uint32_t chunk_type_since(std::uint32_t type) noexcept {
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
      return 1;
    case ChunkType::DrawBatch:
    case ChunkType::Stencil:
    case ChunkType::Light:
      return 2;
  }
  return 0;
}

bool is_known_chunk_type(std::uint32_t type) noexcept { return chunk_type_since(type) != 0; }

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
  // zlib reads a null buffer as a request for the initial value and returns 0, whatever `crc`
  // was: an empty payload (whose data() may be null) must leave the running CRC unchanged.
  if (bytes.empty()) return crc;
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

std::vector<std::uint8_t> encode_chunk(ChunkType type, std::span<const std::uint8_t> payload, bool compress,
                                       std::uint32_t extra_flags) {
  NBSIM_CHECK((extra_flags & ~kFlagTechnique) == 0, "encode_chunk: only the technique flag may be added");
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
  header.u32(flags | extra_flags);
  header.u64(stored);
  header.u64(payload.size());
  const std::vector<std::uint8_t> head = header.take();
  std::copy(head.begin(), head.end(), bytes.begin());
  bytes.resize(kChunkHeaderBytes + stored + kChunkCrcBytes);
  const std::uint32_t crc = crc32(std::span(bytes).first(kChunkHeaderBytes + stored));
  for (std::size_t i = 0; i < 4; ++i) bytes[kChunkHeaderBytes + stored + i] = static_cast<std::uint8_t>(crc >> (8 * i));
  return bytes;
}

// ---- the visitors (schema.h's Io concept) ------------------------------------------------------

namespace {

template <class T>
constexpr const char* int_type_name() {
  if constexpr (std::is_same_v<T, std::uint8_t>) return "u8";
  else if constexpr (std::is_same_v<T, std::uint32_t>) return "u32";
  else if constexpr (std::is_same_v<T, std::int32_t>) return "i32";
  else return "u64";
}

template <class T>
std::string out_of_range(const char* name, T v, T lo, T hi) {
  if (hi == std::numeric_limits<T>::max())
    return fmt::format("field '{}' is {}, below {}", name, +v, +lo);
  return fmt::format("field '{}' is {}, outside {} .. {}", name, +v, +lo, +hi);
}

template <class E>
std::string bad_enum(const char* name, unsigned v) {
  return fmt::format("field '{}' is {}, outside the valid values 0..{} of {}", name, v, EnumInfo<E>::max, EnumInfo<E>::name);
}

// Writes the fields of the newest layout.
class EncodeIo {
 public:
  explicit EncodeIo(Out& o) : o_(o) {}
  std::uint32_t version() const { return kFormatVersion; }
  template <class F> void since(std::uint32_t v, F&& f) { if (kFormatVersion >= v) f(); }
  template <class F> void until(std::uint32_t v, F&& f) { if (kFormatVersion <= v) f(); }
  void u8(const char*, std::uint8_t& v, const char*) { o_.u8(v); }
  void u32(const char*, std::uint32_t& v, const char*) { o_.u32(v); }
  void u64(const char*, std::uint64_t& v, const char*) { o_.u64(v); }
  void i32(const char*, std::int32_t& v, const char*) { o_.i32(v); }
  void f32(const char*, float& v, const char*) { o_.f32(v); }
  void f64(const char*, double& v, const char*) { o_.f64(v); }
  void boolean(const char*, bool& v, const char*) { o_.boolean(v); }
  template <class T> void ranged(const char*, T& v, T, T, const char*, const char*) { put(v); }
  template <class E> void enumeration(const char*, E& v, const char*) { o_.u8(static_cast<std::uint8_t>(v)); }
  template <std::size_t N> void floats(const char*, std::array<float, N>& v, const char*) { for (float x : v) o_.f32(x); }
  void string(const char*, std::string& v, std::size_t, const char*) { o_.str(v); }
  template <class T> void words(const char*, std::vector<T>& v, const char*, const char*) { o_.counted_words(v); }
  template <class T> void image(const char* name, std::vector<T>& v, std::uint64_t count, const char*, const char*) {
    NBSIM_CHECK(v.size() == count, fmt::format("encoding field '{}' of {} elements, the record says {}", name, v.size(), count));
    if constexpr (sizeof(T) == 1) o_.raw(v);
    else o_.words(v);
  }
  template <class E, class F> void items(const char*, std::vector<E>& v, const char*, Element, F&& f, const char*) {
    o_.count(v.size());
    for (E& e : v) f(*this, e);
  }

 private:
  template <class T> void put(T v) {
    if constexpr (std::is_same_v<T, std::uint8_t>) o_.u8(v);
    else if constexpr (std::is_same_v<T, std::uint32_t>) o_.u32(v);
    else if constexpr (std::is_same_v<T, std::int32_t>) o_.i32(v);
    else o_.u64(v);
  }
  Out& o_;
};

// Reads the fields of the file's layout, refusing values outside their types and limits as soon
// as they are read (so a count is never computed from a bad size).
class DecodeIo {
 public:
  DecodeIo(In& in, std::uint32_t version) : in_(in), version_(version) {}
  std::uint32_t version() const { return version_; }
  template <class F> void since(std::uint32_t v, F&& f) { if (version_ >= v) f(); }
  template <class F> void until(std::uint32_t v, F&& f) { if (version_ <= v) f(); }
  void u8(const char* n, std::uint8_t& v, const char*) { v = in_.u8(n); }
  void u32(const char* n, std::uint32_t& v, const char*) { v = in_.u32(n); }
  void u64(const char* n, std::uint64_t& v, const char*) { v = in_.u64(n); }
  void i32(const char* n, std::int32_t& v, const char*) { v = in_.i32(n); }
  void f32(const char* n, float& v, const char*) { v = in_.f32(n); }
  void f64(const char* n, double& v, const char*) { v = in_.f64(n); }
  void boolean(const char* n, bool& v, const char*) { v = in_.boolean(n); }
  template <class T> void ranged(const char* n, T& v, T lo, T hi, const char*, const char*) {
    if constexpr (std::is_same_v<T, std::uint8_t>) v = in_.u8(n);
    else if constexpr (std::is_same_v<T, std::uint32_t>) v = in_.u32(n);
    else if constexpr (std::is_same_v<T, std::int32_t>) v = in_.i32(n);
    else v = in_.u64(n);
    if (v < lo || v > hi) throw InputError(out_of_range(n, v, lo, hi));
  }
  template <class E> void enumeration(const char* n, E& v, const char*) {
    const std::uint8_t b = in_.u8(n);
    if (b > EnumInfo<E>::max) throw InputError(bad_enum<E>(n, b));
    v = static_cast<E>(b);
  }
  template <std::size_t N> void floats(const char* n, std::array<float, N>& v, const char*) { for (float& x : v) x = in_.f32(n); }
  void string(const char* n, std::string& v, std::size_t max, const char*) { v = in_.str(max, n); }
  template <class T> void words(const char* n, std::vector<T>& v, const char*, const char*) { in_.counted_words(v, n); }
  template <class T> void image(const char* n, std::vector<T>& v, std::uint64_t count, const char*, const char*) {
    if constexpr (sizeof(T) == 1) in_.raw(v, count, n);
    else in_.words(v, count, n);
  }
  template <class E, class F> void items(const char* n, std::vector<E>& v, const char*, Element el, F&& f, const char*) {
    v.resize(in_.count(el.bytes, n));
    for (E& e : v) f(*this, e);
  }

 private:
  In& in_;
  std::uint32_t version_;
};

// Checks a record in memory against the newest layout's limits; keeps the first problem.
class CheckIo {
 public:
  std::string problem;
  std::uint32_t version() const { return kFormatVersion; }
  template <class F> void since(std::uint32_t v, F&& f) { if (kFormatVersion >= v) f(); }
  template <class F> void until(std::uint32_t v, F&& f) { if (kFormatVersion <= v) f(); }
  template <class T> void u8(const char*, T&, const char*) {}
  template <class T> void u32(const char*, T&, const char*) {}
  template <class T> void u64(const char*, T&, const char*) {}
  template <class T> void i32(const char*, T&, const char*) {}
  template <class T> void f32(const char*, T&, const char*) {}
  template <class T> void f64(const char*, T&, const char*) {}
  template <class T> void boolean(const char*, T&, const char*) {}
  template <class T> void ranged(const char* n, T& v, T lo, T hi, const char*, const char*) {
    if (v < lo || v > hi) note(out_of_range(n, v, lo, hi));
  }
  template <class E> void enumeration(const char* n, E& v, const char*) {
    if (static_cast<unsigned>(v) > EnumInfo<E>::max) note(bad_enum<E>(n, static_cast<unsigned>(v)));
  }
  template <std::size_t N> void floats(const char*, std::array<float, N>&, const char*) {}
  void string(const char* n, std::string& v, std::size_t max, const char*) {
    if (v.size() > max) note(fmt::format("field '{}' is a string of {} bytes, above the limit of {}", n, v.size(), max));
  }
  template <class T> void words(const char* n, std::vector<T>& v, const char*, const char*) { count(n, v.size()); }
  template <class T> void image(const char* n, std::vector<T>& v, std::uint64_t want, const char* text, const char*) {
    if (v.size() != want) note(fmt::format("field '{}' holds {} elements, but {} is {}", n, v.size(), text, want));
  }
  template <class E, class F> void items(const char* n, std::vector<E>& v, const char*, Element, F&& f, const char*) {
    count(n, v.size());
    for (E& e : v) f(*this, e);
  }

 private:
  void count(const char* n, std::size_t size) {
    if (size > std::numeric_limits<std::uint32_t>::max()) note(fmt::format("field '{}' has {} elements, above 2^32-1", n, size));
  }
  void note(std::string p) {
    if (problem.empty()) problem = std::move(p);
  }
};

// ---- rules that span several fields (the visitor checks each field on its own) ------------------

std::string extra_problem(const Properties& properties) {
  if (properties.size() > kMaxProperties)
    return fmt::format("{} properties, above the limit of {}", properties.size(), kMaxProperties);
  std::set<std::string_view> seen;
  for (const auto& [key, value] : properties) {
    if (key.empty() || key.size() > kMaxKeyBytes || !std::all_of(key.begin(), key.end(), good_key_char))
      return fmt::format("property key '{}' is not 1 to {} characters of A-Z a-z 0-9 _ . -", key, kMaxKeyBytes);
    if (!seen.insert(key).second) return fmt::format("property key '{}' appears twice", key);
    if (value.size() > kMaxValueBytes)
      return fmt::format("property '{}' has a value of {} bytes, above the limit of {}", key, value.size(), kMaxValueBytes);
    if (const std::size_t at = invalid_utf8_at(value); at != std::string_view::npos)
      return fmt::format("property '{}' has a value that is not UTF-8 (byte {} of the value, 0x{:02x})", key, at,
                         static_cast<unsigned char>(value[at]));
  }
  return {};
}

std::string extra_problem(const SceneObjects& s) {
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

std::string extra_problem(const GroundTruth& t) {
  if ((t.id_width == 0) != (t.id_height == 0))
    return fmt::format("ID buffer size {}x{}: a side is 0 only when both are (no ID buffer recorded)", t.id_width, t.id_height);
  if (const auto it = std::find_if(t.ids.begin(), t.ids.end(), [](std::int32_t id) { return id < -1; }); it != t.ids.end())
    return fmt::format("ID buffer pixel {} holds id {}, below -1", it - t.ids.begin(), *it);
  return {};
}

std::string name_problem(const char* what, const std::string& name) {
  if (name.empty() || !std::all_of(name.begin(), name.end(), good_key_char))
    return fmt::format("{} '{}' is not 1 to {} characters of A-Z a-z 0-9 _ . -", what, name, kMaxNameBytes);
  return {};
}

std::string extra_problem(const DrawRecord& d) {
  if (d.topology == Topology::Points && d.point_sizes.size() != d.clip_positions.size())
    return fmt::format("a point draw with {} vertices and {} point sizes (one per vertex)", d.clip_positions.size(),
                       d.point_sizes.size());
  if (d.topology != Topology::Points && !d.point_sizes.empty())
    return fmt::format("a {} draw with {} point sizes (only point draws have them)", to_string(d.topology), d.point_sizes.size());
  return {};
}

std::string extra_problem(const DrawBatch& b) {
  for (std::size_t i = 0; i < b.draws.size(); ++i)
    if (std::string p = extra_problem(b.draws[i]); !p.empty()) return fmt::format("draw {} of the batch: {}", i, p);
  return {};
}

std::string extra_problem(const DepthSnapshot& d) { return name_problem("depth image name", d.name); }
std::string extra_problem(const StencilSnapshot& s) { return name_problem("stencil image name", s.name); }
std::string extra_problem(const NBufferLevels& l) { return name_problem("N-buffer source name", l.source); }

template <class R>
std::string extra_problem(const R&) {
  return {};
}

template <class R>
std::string problem_of(const R& r) {
  if (std::string p = extra_problem(r); !p.empty()) return p;  // the more specific message first
  CheckIo io;
  fields(io, const_cast<R&>(r));  // CheckIo only reads
  return io.problem;
}

template <class R>
std::vector<std::uint8_t> encode_record(const R& r, std::size_t reserve) {
  Out o;
  o.reserve(reserve);
  EncodeIo io(o);
  fields(io, const_cast<R&>(r));  // EncodeIo only reads
  return o.take();
}

template <class R>
R decode_record(std::span<const std::uint8_t> payload, std::uint32_t version) {
  check_version(version);
  In in(payload);
  DecodeIo io(in, version);
  R r{};
  fields(io, r);
  in.finish();
  refuse_problem(extra_problem(r));
  return r;
}

}  // namespace

std::string record_problem(const Properties& r) { return problem_of(r); }
std::string record_problem(const SceneObjects& r) { return problem_of(r); }
std::string record_problem(const FrameBegin& r) { return problem_of(r); }
std::string record_problem(const DrawRecord& r) { return problem_of(r); }
std::string record_problem(const DepthSnapshot& r) { return problem_of(r); }
std::string record_problem(const NBufferLevels& r) { return problem_of(r); }
std::string record_problem(const GroundTruth& r) { return problem_of(r); }
std::string record_problem(const DrawBatch& r) { return problem_of(r); }
std::string record_problem(const StencilSnapshot& r) { return problem_of(r); }
std::string record_problem(const Camera& r) { return problem_of(r); }

std::vector<std::uint8_t> encode(const Properties& r) { return encode_record(r, 256); }
std::vector<std::uint8_t> encode(const SceneObjects& s) {
  return encode_record(s, 28 + 28 * s.objects.size() + 40 * s.node_bounds.size() + 4 * s.leaf_objects.size());
}
std::vector<std::uint8_t> encode(const FrameBegin& r) { return encode_record(r, 160); }
std::vector<std::uint8_t> encode(const DrawRecord& d) { return encode_record(d, 96 + 16 * d.clip_positions.size()); }
std::vector<std::uint8_t> encode(const DepthSnapshot& d) { return encode_record(d, 16 + 4 * d.texels.size()); }
std::vector<std::uint8_t> encode(const NBufferLevels& l) { return encode_record(l, 16 + 4 * l.texels.size()); }
std::vector<std::uint8_t> encode(const GroundTruth& t) {
  return encode_record(t, 24 + 4 * t.visible_pixels.size() + 4 * t.ids.size());
}
std::vector<std::uint8_t> encode(const FrameEnd& r) { return encode_record(r, 16); }
std::vector<std::uint8_t> encode(const DrawBatch& b) {
  std::size_t n = 4;
  for (const DrawRecord& d : b.draws) n += 160 + 20 * d.clip_positions.size();
  return encode_record(b, n);
}
std::vector<std::uint8_t> encode(const StencilSnapshot& s) { return encode_record(s, 16 + s.name.size() + s.texels.size()); }
std::vector<std::uint8_t> encode(const Camera& c) { return encode_record(c, 140); }
std::vector<std::uint8_t> encode(const EndMarker& r) { return encode_record(r, 12); }

// Each decoder reads the layout of the file's version: the visitor reads a field added in version
// N only when version >= N (older files keep its default), so every older version still reads.
Properties decode_properties(std::span<const std::uint8_t> p, std::uint32_t v) { return decode_record<Properties>(p, v); }
SceneObjects decode_scene(std::span<const std::uint8_t> p, std::uint32_t v) { return decode_record<SceneObjects>(p, v); }
FrameBegin decode_frame_begin(std::span<const std::uint8_t> p, std::uint32_t v) { return decode_record<FrameBegin>(p, v); }
DrawRecord decode_draw(std::span<const std::uint8_t> p, std::uint32_t v) { return decode_record<DrawRecord>(p, v); }
DepthSnapshot decode_depth(std::span<const std::uint8_t> p, std::uint32_t v) { return decode_record<DepthSnapshot>(p, v); }
NBufferLevels decode_levels(std::span<const std::uint8_t> p, std::uint32_t v) { return decode_record<NBufferLevels>(p, v); }
GroundTruth decode_truth(std::span<const std::uint8_t> p, std::uint32_t v) { return decode_record<GroundTruth>(p, v); }
FrameEnd decode_frame_end(std::span<const std::uint8_t> p, std::uint32_t v) { return decode_record<FrameEnd>(p, v); }
EndMarker decode_end(std::span<const std::uint8_t> p, std::uint32_t v) { return decode_record<EndMarker>(p, v); }
DrawBatch decode_draw_batch(std::span<const std::uint8_t> p, std::uint32_t v) { return decode_record<DrawBatch>(p, v); }
StencilSnapshot decode_stencil(std::span<const std::uint8_t> p, std::uint32_t v) { return decode_record<StencilSnapshot>(p, v); }
Camera decode_light(std::span<const std::uint8_t> p, std::uint32_t v) { return decode_record<Camera>(p, v); }

}  // namespace nbsim::trace

// TraceReader (framing and structure checks over a file or a memory buffer) and FrameReader (one
// frame at a time, with the per-record rules); see reader.h and traces/FORMAT.md.
#include "traces/format/reader.h"

#include <fmt/format.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>
#include <system_error>

#include "model/common/error.h"
#include "traces/format/codec.h"
#include "traces/format/technique_chunks.h"

namespace nbsim::trace {

class TraceReader::Source {
 public:
  virtual ~Source() = default;
  // Reads up to n bytes; fewer only at the end of the data.
  virtual std::size_t read(std::uint8_t* dst, std::size_t n) = 0;
  virtual std::uint64_t size() const = 0;
};

namespace {

class FileSource final : public TraceReader::Source {
 public:
  explicit FileSource(const std::filesystem::path& file) {
    const std::string name = file.string();
    std::error_code ec;
    const auto status = std::filesystem::status(file, ec);
    if (!std::filesystem::exists(status)) throw InputError(fmt::format("trace '{}' does not exist", name));
    if (!std::filesystem::is_regular_file(status)) throw InputError(fmt::format("trace '{}' is not a regular file", name));
    f_ = std::fopen(name.c_str(), "rb");
    if (!f_) throw InputError(fmt::format("trace '{}' cannot be opened: {}", name, std::strerror(errno)));
    size_ = std::filesystem::file_size(file, ec);
    if (ec) {
      std::fclose(f_);
      throw InputError(fmt::format("trace '{}' cannot be read: {}", name, ec.message()));
    }
  }
  ~FileSource() override { std::fclose(f_); }
  FileSource(const FileSource&) = delete;
  FileSource& operator=(const FileSource&) = delete;

  std::size_t read(std::uint8_t* dst, std::size_t n) override { return std::fread(dst, 1, n, f_); }
  std::uint64_t size() const override { return size_; }

 private:
  std::FILE* f_ = nullptr;
  std::uint64_t size_ = 0;
};

class MemorySource final : public TraceReader::Source {
 public:
  explicit MemorySource(std::vector<std::uint8_t> bytes) : bytes_(std::move(bytes)) {}
  std::size_t read(std::uint8_t* dst, std::size_t n) override {
    n = std::min(n, bytes_.size() - pos_);
    if (n) std::memcpy(dst, bytes_.data() + pos_, n);
    pos_ += n;
    return n;
  }
  std::uint64_t size() const override { return bytes_.size(); }

 private:
  std::vector<std::uint8_t> bytes_;
  std::size_t pos_ = 0;
};

std::uint32_t le32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}
std::uint64_t le64(const std::uint8_t* p) {
  return static_cast<std::uint64_t>(le32(p)) | static_cast<std::uint64_t>(le32(p + 4)) << 32;
}

struct Dctx {
  Dctx() : ctx(ZSTD_createDCtx()) { NBSIM_CHECK(ctx != nullptr, "ZSTD_createDCtx failed"); }
  ~Dctx() { ZSTD_freeDCtx(ctx); }
  Dctx(const Dctx&) = delete;
  Dctx& operator=(const Dctx&) = delete;
  ZSTD_DCtx* ctx;
};

}  // namespace

TraceReader::TraceReader(const std::filesystem::path& file)
    : src_(std::make_unique<FileSource>(file)), name_(file.string()) {
  open();
}

TraceReader::TraceReader(std::vector<std::uint8_t> bytes, std::string name)
    : src_(std::make_unique<MemorySource>(std::move(bytes))), name_(std::move(name)) {
  open();
}

TraceReader::~TraceReader() = default;
TraceReader::TraceReader(TraceReader&&) noexcept = default;
TraceReader& TraceReader::operator=(TraceReader&&) noexcept = default;

std::size_t TraceReader::read_bytes(std::uint8_t* dst, std::size_t n) {
  const std::size_t got = src_->read(dst, n);
  pos_ += got;
  return got;
}

void TraceReader::fail_at(std::uint64_t index, std::uint64_t offset, std::string_view type, std::string_view what) const {
  if (type.empty()) throw InputError(fmt::format("{}: chunk {} at byte {}: {}", name_, index, offset, what));
  throw InputError(fmt::format("{}: chunk {} ({}) at byte {}: {}", name_, index, type, offset, what));
}

void TraceReader::fail(const Chunk& chunk, std::string_view what) const {
  fail_at(chunk.index, chunk.offset, chunk_type_name(chunk.type), what);
}

void TraceReader::open() {
  size_ = src_->size();
  std::array<std::uint8_t, kPreambleBytes> pre{};
  const std::size_t got = read_bytes(pre.data(), pre.size());
  if (got == 0) throw InputError(fmt::format("{}: not an nbsim trace: the file is empty (0 bytes)", name_));
  if (!std::equal(pre.begin(), pre.begin() + static_cast<std::ptrdiff_t>(std::min(got, kMagic.size())), kMagic.begin()))
    throw InputError(fmt::format("{}: not an nbsim trace: no nbsim trace magic at byte 0", name_));
  if (got < pre.size())
    throw InputError(fmt::format("{}: preamble at byte 0: the file ends after {} of the {} preamble bytes (truncated)",
                                 name_, got, kPreambleBytes));
  const std::uint32_t stored_crc = le32(pre.data() + 12);
  if (const std::uint32_t crc = crc32(std::span(pre).first(12)); crc != stored_crc)
    throw InputError(fmt::format("{}: preamble at byte 0: CRC-32 mismatch (stored 0x{:08x}, computed 0x{:08x}): the file is damaged",
                                 name_, stored_crc, crc));
  version_ = le32(pre.data() + 8);
  if (version_ == 0)
    throw InputError(fmt::format("{}: preamble at byte 8: format version 0 does not exist", name_));
  if (version_ > kFormatVersion)
    throw InputError(fmt::format("{}: trace format version {} is newer than this nbsim reads (versions 1 to {}); "
                                 "update nbsim to read it", name_, version_, kFormatVersion));

  Chunk head = read_chunk();
  if (head.type != ChunkType::Header) fail(head, "the first chunk must be HEAD");
  Properties properties = decode<Properties>(head);
  try {
    header_ = parse_header(properties);
  } catch (const InputError& e) {
    fail(head, e.what());
  }
  frame_limit_ = header_.frame_byte_limit();
  if (auto c = next(); c && c->type == ChunkType::Scene)
    scene_ = decode<SceneObjects>(*c);
  else
    pending_ = std::move(c);
}

Chunk TraceReader::read_chunk() {
  Chunk c;
  c.index = next_index_;
  c.offset = pos_;
  std::array<std::uint8_t, kChunkHeaderBytes + kChunkCrcBytes> head{};
  const std::size_t got = read_bytes(head.data(), kChunkHeaderBytes);
  if (got == 0) {
    const std::string last = stats_.chunks ? fmt::format(" after chunk {}", c.index - 1) : std::string();
    fail_at(c.index, c.offset, "", fmt::format("the file ends here{} without an END chunk (truncated)", last));
  }
  const std::uint32_t type = got >= 4 ? le32(head.data()) : 0;
  const std::string type_name = got >= 4 ? chunk_type_name(type) : std::string();
  if (got < kChunkHeaderBytes)
    fail_at(c.index, c.offset, type_name,
            fmt::format("the file ends after {} of the {} chunk header bytes (truncated)", got, kChunkHeaderBytes));
  const std::uint32_t flags = le32(head.data() + 4);
  const std::uint64_t stored = le64(head.data() + 8), raw = le64(head.data() + 16);
  const std::uint64_t left = size_ - std::min(size_, pos_);
  if (stored > kMaxChunkBytes)
    fail_at(c.index, c.offset, type_name,
            fmt::format("stored length {} exceeds the format's chunk limit of {} bytes", stored, kMaxChunkBytes));
  if (stored + kChunkCrcBytes > left)
    fail_at(c.index, c.offset, type_name,
            fmt::format("stored length {} (plus the 4-byte CRC) points past the end of the file: {} bytes follow the header",
                        stored, left));
  if (raw > kMaxChunkBytes)
    fail_at(c.index, c.offset, type_name,
            fmt::format("raw length {} exceeds the format's chunk limit of {} bytes", raw, kMaxChunkBytes));
  // A frame is held in memory whole (FrameReader): its chunks together stay within the frame limit,
  // checked before this one is read or decompressed.
  if (in_frame_ && raw > frame_limit_ - frame_bytes_)
    fail_at(c.index, c.offset, type_name,
            fmt::format("frame {}'s chunks decode to {} bytes with this one ({} raw bytes), above the per-frame limit of "
                        "{} bytes ({})",
                        frame_, frame_bytes_ + raw, raw, frame_limit_, header_.frame_byte_limit_rule()));

  // A compressed payload is read into this thread's buffer, kept from chunk to chunk (only its
  // decompressed bytes are kept): no allocation and no clearing for every chunk.
  const bool packed = (flags & kFlagZstd) != 0;
  thread_local std::vector<std::uint8_t> packed_bytes;
  std::vector<std::uint8_t> own;
  if (packed && packed_bytes.size() < stored) packed_bytes.resize(static_cast<std::size_t>(stored));
  if (!packed) own.resize(static_cast<std::size_t>(stored));
  const std::span<std::uint8_t> data(packed ? packed_bytes.data() : own.data(), static_cast<std::size_t>(stored));
  if (read_bytes(data.data(), data.size()) != data.size() ||
      read_bytes(head.data() + kChunkHeaderBytes, kChunkCrcBytes) != kChunkCrcBytes)
    fail_at(c.index, c.offset, type_name, "the file ends inside the chunk (truncated while reading)");
  const std::uint32_t stored_crc = le32(head.data() + kChunkHeaderBytes);
  const std::uint32_t crc = crc32(data, crc32(std::span(head).first(kChunkHeaderBytes)));
  if (crc != stored_crc)
    fail_at(c.index, c.offset, type_name,
            fmt::format("CRC-32 mismatch (stored 0x{:08x}, computed 0x{:08x}): the chunk is damaged", stored_crc, crc));

  // The bytes are what the writer wrote; now check they mean something this version knows.
  const std::uint32_t known_flags = version_ >= 2 ? kKnownFlags : kKnownFlagsV1;
  if (flags & ~known_flags)
    fail_at(c.index, c.offset, type_name,
            fmt::format("unknown flags 0x{:08x} (format version {})", flags & ~known_flags, version_));
  c.technique = (flags & kFlagTechnique) != 0;
  if (c.technique) {
    if (is_known_chunk_type(type)) fail_at(c.index, c.offset, type_name, "a core chunk type flagged as a technique's chunk");
    if (type_name.size() != 4) fail_at(c.index, c.offset, type_name, "a technique's chunk type must be four printable characters");
  } else if (!is_known_chunk_type(type)) {
    fail_at(c.index, c.offset, type_name, "unknown chunk type");
  } else if (chunk_type_since(type) > version_) {
    fail_at(c.index, c.offset, type_name,
            fmt::format("chunk type {} exists since format version {}, the file is version {}", type_name,
                        chunk_type_since(type), version_));
  }
  c.type = static_cast<ChunkType>(type);
  c.stored_bytes = stored;
  c.compressed = packed;
  if (!c.compressed) {
    if (raw != stored) fail(c, fmt::format("raw length {} differs from stored length {} of an uncompressed payload", raw, stored));
    c.payload = std::move(own);
  } else {
    const unsigned long long declared = ZSTD_getFrameContentSize(data.data(), data.size());
    if (declared == ZSTD_CONTENTSIZE_ERROR || declared == ZSTD_CONTENTSIZE_UNKNOWN)
      fail(c, "the compressed payload is not a zstd frame with a content size");
    if (declared != raw)
      fail(c, fmt::format("the zstd frame holds {} bytes, the chunk header says {}", declared, raw));
    c.payload.resize(static_cast<std::size_t>(raw));
    thread_local Dctx dctx;
    const std::size_t n = ZSTD_decompressDCtx(dctx.ctx, c.payload.data(), c.payload.size(), data.data(), data.size());
    if (ZSTD_isError(n)) fail(c, fmt::format("zstd cannot decompress the payload: {}", ZSTD_getErrorName(n)));
    if (n != raw) fail(c, fmt::format("the payload decompresses to {} bytes, the chunk header says {}", n, raw));
  }
  if (in_frame_) frame_bytes_ += raw;
  ++next_index_;
  ++stats_.chunks;
  stats_.compressed_chunks += c.compressed;
  stats_.stored_bytes += stored;
  stats_.raw_bytes += raw;
  return c;
}

void TraceReader::check_structure(const Chunk& c) {
  if (c.technique) {
    if (!in_frame_) fail(c, "a technique's chunk outside a frame (no FRAM before it)");
    return;
  }
  switch (c.type) {
    case ChunkType::Header:
      fail(c, "a second HEAD chunk: HEAD is chunk 0 only");
    case ChunkType::Scene:
      if (c.index != 1) fail(c, "SCEN must directly follow HEAD (chunk 1)");
      return;
    case ChunkType::FrameBegin: {
      if (in_frame_) fail(c, fmt::format("FRAM inside frame {}: that frame's FEND is missing", frame_));
      const auto f = decode<FrameBegin>(c);
      if (any_frame_ && f.frame <= frame_)
        fail(c, fmt::format("frame number {} does not increase (the previous frame is {})", f.frame, frame_));
      in_frame_ = any_frame_ = true;
      frame_ = f.frame;
      frame_draws_ = 0;
      frame_bytes_ = 0;
      return;
    }
    case ChunkType::Draw:
    case ChunkType::DrawBatch:
    case ChunkType::Depth:
    case ChunkType::Levels:
    case ChunkType::Truth:
    case ChunkType::Stencil:
    case ChunkType::Light:
      if (!in_frame_) fail(c, "a frame record outside a frame (no FRAM before it)");
      if (c.type == ChunkType::Draw) {
        if (frame_draws_ >= kMaxDrawsPerFrame)
          fail(c, fmt::format("frame {} holds more than the per-frame limit of {} draws", frame_, kMaxDrawsPerFrame));
        ++frame_draws_;
        ++stats_.draws;
      } else if (c.type == ChunkType::DrawBatch) {
        // The batch's draw count leads its payload; FrameReader checks it against the draws.
        if (c.payload.size() < 4) fail(c, fmt::format("the payload of {} bytes is too short for a draw count (it decodes short)",
                                                      c.payload.size()));
        const std::uint32_t n = le32(c.payload.data());
        if (n == 0) fail(c, "an empty draw batch");
        if (n > kMaxDrawsPerFrame - frame_draws_)
          fail(c, fmt::format("the batch's {} draws bring frame {} to {} draws, above the per-frame limit of {} draws", n,
                              frame_, std::uint64_t{frame_draws_} + n, kMaxDrawsPerFrame));
        frame_draws_ += n;
        stats_.draws += n;
      }
      return;
    case ChunkType::FrameEnd: {
      if (!in_frame_) fail(c, "FEND outside a frame (no FRAM before it)");
      const auto f = decode<FrameEnd>(c);
      if (f.frame != frame_) fail(c, fmt::format("FEND of frame {} closes frame {}", f.frame, frame_));
      if (f.draws != frame_draws_)
        fail(c, fmt::format("FEND counts {} draws, but frame {} has {} (DRAW chunks and DRWS batches)", f.draws, frame_,
                            frame_draws_));
      in_frame_ = false;
      ++stats_.frames;
      return;
    }
    case ChunkType::End: {
      if (in_frame_) fail(c, fmt::format("END inside frame {}: that frame's FEND is missing", frame_));
      const auto e = decode<EndMarker>(c);
      if (e.chunks != c.index) fail(c, fmt::format("END counts {} chunks before it, the file has {}", e.chunks, c.index));
      if (e.frames != stats_.frames)
        fail(c, fmt::format("END counts {} frames, the file has {}", e.frames, stats_.frames));
      const std::uint64_t end_pos = pos_;
      std::uint8_t extra = 0;
      if (read_bytes(&extra, 1) != 0)
        fail(c, fmt::format("data follows the END chunk: it ends at byte {}, the file has {} bytes", end_pos, size_));
      end_ = e;
      return;
    }
  }
  NBSIM_CHECK(false, "read_chunk let an unknown chunk type through");
}

std::optional<Chunk> TraceReader::next() {
  if (pending_) {
    std::optional<Chunk> c = std::move(pending_);
    pending_.reset();
    return c;
  }
  if (end_) return std::nullopt;
  Chunk c = read_chunk();
  check_structure(c);
  if (c.type == ChunkType::End) return std::nullopt;
  return c;
}

template <class Record>
Record TraceReader::decode(const Chunk& chunk) const {
  NBSIM_CHECK(chunk.type == RecordChunk<Record>::type,
              fmt::format("decoding a {} chunk as {}", chunk_type_name(chunk.type), chunk_type_name(RecordChunk<Record>::type)));
  try {
    if constexpr (std::is_same_v<Record, Properties>) return decode_properties(chunk.payload, version_);
    else if constexpr (std::is_same_v<Record, SceneObjects>) return decode_scene(chunk.payload, version_);
    else if constexpr (std::is_same_v<Record, FrameBegin>) return decode_frame_begin(chunk.payload, version_);
    else if constexpr (std::is_same_v<Record, DrawRecord>) return decode_draw(chunk.payload, version_);
    else if constexpr (std::is_same_v<Record, DepthSnapshot>) return decode_depth(chunk.payload, version_);
    else if constexpr (std::is_same_v<Record, NBufferLevels>) return decode_levels(chunk.payload, version_);
    else if constexpr (std::is_same_v<Record, GroundTruth>) return decode_truth(chunk.payload, version_);
    else if constexpr (std::is_same_v<Record, FrameEnd>) return decode_frame_end(chunk.payload, version_);
    else if constexpr (std::is_same_v<Record, DrawBatch>) return decode_draw_batch(chunk.payload, version_);
    else if constexpr (std::is_same_v<Record, StencilSnapshot>) return decode_stencil(chunk.payload, version_);
    else if constexpr (std::is_same_v<Record, Camera>) return decode_light(chunk.payload, version_);
    else return decode_end(chunk.payload, version_);
  } catch (const InputError& e) {
    fail(chunk, e.what());
  }
}

template Properties TraceReader::decode<Properties>(const Chunk&) const;
template SceneObjects TraceReader::decode<SceneObjects>(const Chunk&) const;
template FrameBegin TraceReader::decode<FrameBegin>(const Chunk&) const;
template DrawRecord TraceReader::decode<DrawRecord>(const Chunk&) const;
template DepthSnapshot TraceReader::decode<DepthSnapshot>(const Chunk&) const;
template NBufferLevels TraceReader::decode<NBufferLevels>(const Chunk&) const;
template GroundTruth TraceReader::decode<GroundTruth>(const Chunk&) const;
template FrameEnd TraceReader::decode<FrameEnd>(const Chunk&) const;
template EndMarker TraceReader::decode<EndMarker>(const Chunk&) const;
template DrawBatch TraceReader::decode<DrawBatch>(const Chunk&) const;
template StencilSnapshot TraceReader::decode<StencilSnapshot>(const Chunk&) const;
template Camera TraceReader::decode<Camera>(const Chunk&) const;

// ---- FrameReader ------------------------------------------------------------------------------

FrameReader::FrameReader(const std::filesystem::path& file) : trace_(file) {}
FrameReader::FrameReader(TraceReader trace) : trace_(std::move(trace)) {}

void FrameReader::require_viewport_depths(std::vector<std::string> depth_names) {
  viewport_depths_ = std::move(depth_names);
}

std::optional<Frame> FrameReader::next() {
  std::optional<Chunk> c = trace_.next();
  if (!c) return std::nullopt;
  // TraceReader's structure checks guarantee FRAM here, then frame records, then FEND.
  NBSIM_CHECK(c->type == ChunkType::FrameBegin, "TraceReader let a frame record through outside a frame");
  Frame f;
  f.ordinal = ordinal_;
  f.offset = c->offset;
  f.begin = trace_.decode<FrameBegin>(*c);
  const SceneObjects* scene = trace_.scene();
  const auto objects = scene ? static_cast<std::int64_t>(scene->objects.size()) : 0;
  const auto nodes = scene ? static_cast<std::int64_t>(scene->node_bounds.size()) : 0;
  const auto add_draw = [&](DrawRecord d, const Chunk& chunk) {
    if (d.index != f.draws.size())
      trace_.fail(chunk, fmt::format("draw index {} in frame {}, expected {} (draws count from 0 in file order)", d.index,
                                     f.begin.frame, f.draws.size()));
    if (scene && d.object >= objects)
      trace_.fail(chunk, fmt::format("draw {} names object {}, but the scene has {} objects", d.index, d.object, objects));
    if (scene && d.node >= nodes)
      trace_.fail(chunk, fmt::format("draw {} names BVH node {}, but the scene has {} nodes", d.index, d.node, nodes));
    f.draws.push_back(std::move(d));
  };
  for (;;) {
    c = trace_.next();
    NBSIM_CHECK(c.has_value(), "TraceReader ended inside a frame");
    if (c->technique) {
      try {
        f.technique_records.push_back(decode_technique(static_cast<std::uint32_t>(c->type), c->payload));
      } catch (const InputError& e) {
        trace_.fail(*c, e.what());
      }
      continue;
    }
    switch (c->type) {
      case ChunkType::Draw:
        add_draw(trace_.decode<DrawRecord>(*c), *c);
        break;
      case ChunkType::DrawBatch: {
        DrawBatch batch = trace_.decode<DrawBatch>(*c);
        for (DrawRecord& d : batch.draws) add_draw(std::move(d), *c);
        break;
      }
      case ChunkType::Depth: {
        DepthSnapshot d = trace_.decode<DepthSnapshot>(*c);
        if (const std::optional<Viewport>& v = trace_.header().viewport;
            v && (d.width != v->width || d.height != v->height) &&
            std::find(viewport_depths_.begin(), viewport_depths_.end(), d.name) != viewport_depths_.end())
          trace_.fail(*c, fmt::format("depth image '{}' is {}x{}, but the header's viewport is {}x{}: replay compares it "
                                      "with the model's depth buffer, which has the viewport's size",
                                      d.name, d.width, d.height, v->width, v->height));
        if (f.depth(d.name))
          trace_.fail(*c, fmt::format("a second '{}' depth snapshot in frame {}", d.name, f.begin.frame));
        f.depths.push_back(std::move(d));
        break;
      }
      case ChunkType::Stencil: {
        StencilSnapshot s = trace_.decode<StencilSnapshot>(*c);
        if (f.stencil(s.name))
          trace_.fail(*c, fmt::format("a second '{}' stencil snapshot in frame {}", s.name, f.begin.frame));
        f.stencils.push_back(std::move(s));
        break;
      }
      case ChunkType::Light:
        if (f.light) trace_.fail(*c, fmt::format("a second light camera in frame {}", f.begin.frame));
        f.light = trace_.decode<Camera>(*c);
        break;
      case ChunkType::Levels: {
        NBufferLevels l = trace_.decode<NBufferLevels>(*c);
        if (f.nbuffer(l.source, static_cast<FarOp>(l.op)))
          trace_.fail(*c, fmt::format("a second N-buffer with op '{}' built from '{}' in frame {}",
                                      to_string(static_cast<FarOp>(l.op)), l.source, f.begin.frame));
        f.levels.push_back(std::move(l));
        break;
      }
      case ChunkType::Truth: {
        if (f.truth) trace_.fail(*c, fmt::format("a second ground truth in frame {}", f.begin.frame));
        GroundTruth t = trace_.decode<GroundTruth>(*c);
        if (scene && static_cast<std::int64_t>(t.visible_pixels.size()) != objects)
          trace_.fail(*c, fmt::format("ground truth for {} objects, but the scene has {}", t.visible_pixels.size(), objects));
        if (scene)
          for (std::size_t i = 0; i < t.ids.size(); ++i)
            if (t.ids[i] >= objects)
              trace_.fail(*c, fmt::format("ID-buffer pixel {} holds object {}, but the scene has {} objects", i, t.ids[i], objects));
        f.truth = std::move(t);
        break;
      }
      case ChunkType::FrameEnd:
        f.end = trace_.decode<FrameEnd>(*c);
        ++ordinal_;
        return f;
      default:
        NBSIM_CHECK(false, "TraceReader let a non-frame chunk into a frame");
    }
  }
}

}  // namespace nbsim::trace

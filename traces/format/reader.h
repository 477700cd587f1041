// TraceReader and FrameReader: stream a depth trace (traces/FORMAT.md) chunk by chunk or frame by
// frame for replay, `nbsim trace` and tests. Memory stays bounded by one chunk (one frame for
// FrameReader) however long the trace; every damage is refused with an InputError naming the file,
// the chunk (index and type) and its byte offset.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "model/common/depth.h"
#include "traces/format/header.h"
#include "traces/format/records.h"

namespace nbsim::trace {

// One chunk as read from the file, payload decompressed and checked against its CRC-32.
struct Chunk {
  ChunkType type = ChunkType::End;
  std::uint64_t index = 0;         // position in the file: 0 is HEAD
  std::uint64_t offset = 0;        // byte offset of the chunk header in the file
  std::uint64_t stored_bytes = 0;  // payload bytes in the file (compressed or not)
  bool compressed = false;
  bool technique = false;          // a technique's chunk type (kFlagTechnique): `type` is its fourcc
  std::vector<std::uint8_t> payload;  // the decoded payload
};

// Running totals of what the reader has read so far.
struct TraceStats {
  std::uint64_t chunks = 0;             // including HEAD (and END once read)
  std::uint64_t compressed_chunks = 0;
  std::uint64_t stored_bytes = 0;       // payload bytes in the file
  std::uint64_t raw_bytes = 0;          // payload bytes after decompression
  std::uint32_t frames = 0;             // complete frames (FEND read)
  std::uint64_t draws = 0;
};

class TraceReader {
 public:
  // Opens the file and reads the preamble, HEAD (parsed into the typed header) and (when it
  // follows) SCEN. Throws InputError when the file is missing, not a trace, damaged there, of a
  // newer format version, or when a header property has a malformed value.
  explicit TraceReader(const std::filesystem::path& file);
  // The same over bytes in memory (tests, fuzzing); `name` stands for the file in messages.
  TraceReader(std::vector<std::uint8_t> bytes, std::string name);
  ~TraceReader();
  TraceReader(TraceReader&&) noexcept;
  TraceReader& operator=(TraceReader&&) noexcept;

  const std::string& name() const noexcept { return name_; }
  std::uint64_t file_bytes() const noexcept { return size_; }
  std::uint32_t version() const noexcept { return version_; }
  // The header, parsed and checked once when the trace was opened (header.h).
  const Header& header() const noexcept { return header_; }
  const Properties& properties() const noexcept { return header_.properties; }
  // The value of a header property as written, or nullptr.
  const std::string* property(std::string_view key) const noexcept { return header_.property(key); }
  // The scene, or nullptr when the trace has no SCEN chunk.
  const SceneObjects* scene() const noexcept { return scene_ ? &*scene_ : nullptr; }

  // The next chunk after HEAD and SCEN (which the constructor consumed), or nullopt once END has
  // been read. Checks framing (lengths, CRC-32, zstd) and structure (FORMAT.md "Structure": chunk
  // order, frame numbers, FEND and END counts, nothing after END) and throws InputError otherwise.
  // The per-record rules that need a record's fields (draw indices, one snapshot per kind, ids
  // within the scene) are FrameReader's.
  std::optional<Chunk> next();
  // The END marker once next() has returned nullopt.
  const std::optional<EndMarker>& end() const noexcept { return end_; }
  const TraceStats& stats() const noexcept { return stats_; }

  // Decodes a chunk's payload as the record its type holds (Record is one of the records.h
  // types, matching chunk.type); throws InputError naming the chunk when the payload is bad.
  template <class Record>
  Record decode(const Chunk& chunk) const;

  // Throws InputError "<file>: chunk <index> (<TYPE>) at byte <offset>: <what>".
  [[noreturn]] void fail(const Chunk& chunk, std::string_view what) const;

  class Source;  // where the bytes come from (file or memory)

 private:
  void open();
  Chunk read_chunk();
  void check_structure(const Chunk& chunk);
  std::size_t read_bytes(std::uint8_t* dst, std::size_t n);
  [[noreturn]] void fail_at(std::uint64_t index, std::uint64_t offset, std::string_view type, std::string_view what) const;

  std::unique_ptr<Source> src_;
  std::string name_;
  std::uint64_t size_ = 0;
  std::uint64_t pos_ = 0;
  std::uint32_t version_ = 0;
  Header header_;
  std::optional<SceneObjects> scene_;
  std::optional<Chunk> pending_;  // read by the constructor after HEAD, not SCEN
  std::optional<EndMarker> end_;
  TraceStats stats_;
  std::uint64_t next_index_ = 0;
  bool in_frame_ = false;
  bool any_frame_ = false;
  std::uint32_t frame_ = 0;        // the open (or last) frame's number
  std::uint32_t frame_draws_ = 0;  // draws in the open frame (DRAW chunks and DRWS batches)
  std::uint64_t frame_bytes_ = 0;  // raw bytes of the open frame's chunks so far
  std::uint64_t frame_limit_ = 0;  // header_.frame_byte_limit()
};

// One frame, FRAM .. FEND, decoded (model/scene/frame.h).
using scene::Frame;

// Groups a trace's chunks into frames, checking the per-record rules of FORMAT.md "Structure".
class FrameReader {
 public:
  explicit FrameReader(const std::filesystem::path& file);
  explicit FrameReader(TraceReader trace);

  // From now on, refuses (naming the chunk) a depth image named in `depth_names` whose size is
  // not the header's viewport. Replay asks for it for the depth images it compares with the
  // model's depth buffer, which has the viewport's size ("after_occluders", "final"); the format
  // itself allows any size (a technique's litmaps need not match the viewport). No effect when
  // the header has no viewport.
  void require_viewport_depths(std::vector<std::string> depth_names);

  // The next frame, or nullopt after the last one (END read and checked).
  std::optional<Frame> next();
  TraceReader& trace() noexcept { return trace_; }
  const TraceReader& trace() const noexcept { return trace_; }

 private:
  TraceReader trace_;
  std::uint64_t ordinal_ = 0;
  std::vector<std::string> viewport_depths_;  // require_viewport_depths()
};

}  // namespace nbsim::trace

// TraceWriter: what the GL capture calls to store a depth trace (traces/FORMAT.md), chunk by chunk,
// in the order the format requires. Memory stays bounded by the record being written.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "traces/format/header.h"
#include "traces/format/records.h"

namespace nbsim::trace {

class TraceWriter {
 public:
  // Creates (or replaces) the file and writes the preamble and the HEAD chunk. Throws InputError
  // naming the file when it cannot be created or the properties break a rule of the format.
  TraceWriter(const std::filesystem::path& file, const Properties& properties);
  // Closes the file. Without close() the trace has no END chunk and every reader refuses it as
  // truncated, which is what a capture that failed half-way should leave behind.
  ~TraceWriter();
  TraceWriter(const TraceWriter&) = delete;
  TraceWriter& operator=(const TraceWriter&) = delete;

  // The order is the format's (FORMAT.md "Structure"): the scene at most once, right after the
  // header; then frames, each begin_frame .. end_frame with the frame's records in between.
  // Breaking the order or writing an inconsistent record is a bug of the caller: it aborts.
  // I/O failures and records above the chunk limit throw InputError naming the file.
  void write(const SceneObjects& scene);
  void begin_frame(const FrameBegin& frame);
  // Draws are stored in DRWS batches (kDrawsPerBatch, kBatchBytes): a batch is flushed when it is
  // full, before any other record of the frame and at end_frame.
  void write(const DrawRecord& draw);  // draw.index must count the frame's draws from 0
  void write(const DepthSnapshot& depth);        // names unique in the frame
  void write(const NBufferLevels& levels);       // (source, op) unique in the frame
  void write(const StencilSnapshot& stencil);    // names unique in the frame
  void write_light(const Camera& light);         // at most once a frame
  void write(const TechniqueRecord& record);     // a registered type, or a raw record read from a file
  void write(const GroundTruth& truth);
  void end_frame(const FrameEnd& frame);  // frame.frame and frame.draws must match the frame
  // Writes END and closes the file; throws InputError when the data cannot be flushed.
  void close();

  std::uint64_t bytes_written() const noexcept { return bytes_; }
  std::uint64_t chunks_written() const noexcept { return chunks_; }
  std::uint32_t frames_written() const noexcept { return frames_; }

 private:
  void put(ChunkType type, const std::vector<std::uint8_t>& payload, std::uint32_t extra_flags = 0);
  void flush_draws();
  void put_bytes(const std::uint8_t* data, std::size_t n);
  void require_frame(const char* what) const;

  std::string name_;
  std::FILE* file_ = nullptr;
  std::uint64_t bytes_ = 0;
  std::uint64_t chunks_ = 0;
  std::uint32_t frames_ = 0;
  bool has_scene_ = false;
  std::size_t scene_objects_ = 0, scene_nodes_ = 0;
  bool in_frame_ = false;
  bool any_frame_ = false;
  std::uint32_t frame_ = 0;  // the open (or last) frame's number
  std::uint32_t draws_ = 0;
  DrawBatch pending_;               // draws not yet written
  std::size_t pending_bytes_ = 0;   // their payload bytes, about
  // What the open frame holds already (the format allows one of each).
  std::set<std::string> depths_, stencils_;
  std::set<std::pair<std::string, std::uint8_t>> levels_;
  bool light_ = false, truth_ = false;
  // The per-frame limit readers enforce (FORMAT.md "Limits"): a frame the reader would refuse is
  // refused here, with an InputError, instead of written.
  Header header_;                  // the typed header (defaults when a property is malformed)
  std::uint64_t frame_bytes_ = 0;  // payload bytes of the open frame's chunks so far
};

}  // namespace nbsim::trace

// TraceWriter: frames records into chunks (codec.h) and appends them to the file in format order.
#include "traces/format/writer.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>

#include "model/common/error.h"
#include "traces/format/codec.h"

namespace nbsim::trace {

namespace {

constexpr std::uint32_t kSeenTruth = 1u << 2;
std::uint32_t seen_depth_bit(DepthWhich w) { return 1u << static_cast<unsigned>(w); }
std::uint32_t seen_levels_bit(std::uint8_t op) { return 1u << (3u + op); }

void check_record(const std::string& problem, const char* what) {
  NBSIM_CHECK(problem.empty(), fmt::format("TraceWriter: inconsistent {} record: {}", what, problem));
}

}  // namespace

TraceWriter::TraceWriter(const std::filesystem::path& file, const Properties& properties) : name_(file.string()) {
  if (const std::string p = record_problem(properties); !p.empty())
    throw InputError(fmt::format("cannot write trace '{}': {}", name_, p));
  file_ = std::fopen(name_.c_str(), "wb");
  if (!file_) throw InputError(fmt::format("cannot create trace '{}': {}", name_, std::strerror(errno)));
  const auto pre = encode_preamble(kFormatVersion);
  put_bytes(pre.data(), pre.size());
  put(ChunkType::Header, encode(properties));
}

TraceWriter::~TraceWriter() {
  if (file_) std::fclose(file_);
}

void TraceWriter::put_bytes(const std::uint8_t* data, std::size_t n) {
  NBSIM_CHECK(file_ != nullptr, "TraceWriter: write after close()");
  if (std::fwrite(data, 1, n, file_) != n)
    throw InputError(fmt::format("cannot write trace '{}': {}", name_, std::strerror(errno)));
  bytes_ += n;
}

void TraceWriter::put(ChunkType type, const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> chunk;
  try {
    chunk = encode_chunk(type, payload);
  } catch (const InputError& e) {
    throw InputError(fmt::format("cannot write trace '{}': {}", name_, e.what()));
  }
  put_bytes(chunk.data(), chunk.size());
  ++chunks_;
}

void TraceWriter::require_frame(const char* what) const {
  NBSIM_CHECK(in_frame_, fmt::format("TraceWriter: {} written outside begin_frame() .. end_frame()", what));
}

void TraceWriter::write(const SceneObjects& scene) {
  NBSIM_CHECK(chunks_ == 1 && !in_frame_, "TraceWriter: the scene must be written once, right after the header");
  check_record(record_problem(scene), "SCEN");
  put(ChunkType::Scene, encode(scene));
  has_scene_ = true;
  scene_objects_ = scene.objects.size();
  scene_nodes_ = scene.node_bounds.size();
}

void TraceWriter::begin_frame(const FrameBegin& frame) {
  NBSIM_CHECK(!in_frame_, fmt::format("TraceWriter: begin_frame({}) inside frame {}", frame.frame, frame_));
  NBSIM_CHECK(!any_frame_ || frame.frame > frame_,
              fmt::format("TraceWriter: frame numbers must increase ({} after {})", frame.frame, frame_));
  NBSIM_CHECK(static_cast<std::uint8_t>(frame.mode) <= static_cast<std::uint8_t>(TestMode::None),
              "TraceWriter: FrameBegin.mode is not a TestMode");
  put(ChunkType::FrameBegin, encode(frame));
  in_frame_ = any_frame_ = true;
  frame_ = frame.frame;
  draws_ = 0;
  seen_ = 0;
}

void TraceWriter::write(const DrawRecord& draw) {
  require_frame("a DRAW record");
  check_record(record_problem(draw), "DRAW");
  NBSIM_CHECK(draw.index == draws_,
              fmt::format("TraceWriter: draw index {} in frame {}, expected {}", draw.index, frame_, draws_));
  if (has_scene_) {
    NBSIM_CHECK(draw.object < static_cast<std::int64_t>(scene_objects_),
                fmt::format("TraceWriter: draw {} names object {} of {}", draw.index, draw.object, scene_objects_));
    NBSIM_CHECK(draw.node < static_cast<std::int64_t>(scene_nodes_),
                fmt::format("TraceWriter: draw {} names BVH node {} of {}", draw.index, draw.node, scene_nodes_));
  }
  put(ChunkType::Draw, encode(draw));
  ++draws_;
}

void TraceWriter::write(const DepthSnapshot& depth) {
  require_frame("a DPTH record");
  check_record(record_problem(depth), "DPTH");
  NBSIM_CHECK(!(seen_ & seen_depth_bit(depth.which)),
              fmt::format("TraceWriter: a second '{}' depth snapshot in frame {}", to_string(depth.which), frame_));
  put(ChunkType::Depth, encode(depth));
  seen_ |= seen_depth_bit(depth.which);
}

void TraceWriter::write(const NBufferLevels& levels) {
  require_frame("an NBLV record");
  check_record(record_problem(levels), "NBLV");
  NBSIM_CHECK(!(seen_ & seen_levels_bit(levels.op)),
              fmt::format("TraceWriter: a second N-buffer with op {} in frame {}", levels.op, frame_));
  put(ChunkType::Levels, encode(levels));
  seen_ |= seen_levels_bit(levels.op);
}

void TraceWriter::write(const GroundTruth& truth) {
  require_frame("a TRTH record");
  check_record(record_problem(truth), "TRTH");
  NBSIM_CHECK(!(seen_ & kSeenTruth), fmt::format("TraceWriter: a second ground truth in frame {}", frame_));
  if (has_scene_) {
    NBSIM_CHECK(truth.visible_pixels.size() == scene_objects_,
                fmt::format("TraceWriter: ground truth for {} objects, the scene has {}", truth.visible_pixels.size(),
                            scene_objects_));
    for (const std::int32_t id : truth.ids)
      NBSIM_CHECK(id < static_cast<std::int64_t>(scene_objects_),
                  fmt::format("TraceWriter: ID buffer holds object {} of {}", id, scene_objects_));
  }
  put(ChunkType::Truth, encode(truth));
  seen_ |= kSeenTruth;
}

void TraceWriter::end_frame(const FrameEnd& frame) {
  require_frame("a FEND record");
  NBSIM_CHECK(frame.frame == frame_, fmt::format("TraceWriter: end_frame({}) closes frame {}", frame.frame, frame_));
  NBSIM_CHECK(frame.draws == draws_,
              fmt::format("TraceWriter: FrameEnd.draws is {}, but frame {} has {} DRAW records", frame.draws, frame_, draws_));
  put(ChunkType::FrameEnd, encode(frame));
  in_frame_ = false;
  ++frames_;
}

void TraceWriter::close() {
  NBSIM_CHECK(file_ != nullptr, "TraceWriter: close() twice");
  NBSIM_CHECK(!in_frame_, fmt::format("TraceWriter: close() inside frame {} (no end_frame)", frame_));
  put(ChunkType::End, encode(EndMarker{chunks_, frames_}));
  const bool flushed = std::fflush(file_) == 0;
  const int err = errno;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!flushed || !closed) throw InputError(fmt::format("cannot write trace '{}': {}", name_, std::strerror(err)));
}

}  // namespace nbsim::trace

// TraceWriter: frames records into chunks (codec.h) and appends them to the file in format order.
#include "traces/format/writer.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>

#include "model/common/error.h"
#include "traces/format/codec.h"
#include "traces/format/technique_chunks.h"

namespace nbsim::trace {

namespace {

void check_record(const std::string& problem, const char* what) {
  NBSIM_CHECK(problem.empty(), fmt::format("TraceWriter: inconsistent {} record: {}", what, problem));
}

}  // namespace

TraceWriter::TraceWriter(const std::filesystem::path& file, const Properties& properties) : name_(file.string()) {
  if (const std::string p = record_problem(properties); !p.empty())
    throw InputError(fmt::format("cannot write trace '{}': {}", name_, p));
  try {
    header_ = parse_header(properties);
  } catch (const InputError&) {
    // A malformed typed value: readers refuse the file anyway (tests write such files on purpose).
    header_ = Header{};
  }
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

void TraceWriter::put(ChunkType type, const std::vector<std::uint8_t>& payload, std::uint32_t extra_flags) {
  if (in_frame_) {
    if (payload.size() > header_.frame_byte_limit() - frame_bytes_)
      throw InputError(fmt::format("cannot write trace '{}': frame {}'s records come to {} bytes with this {} record, above "
                                   "the per-frame limit of {} bytes ({})",
                                   name_, frame_, frame_bytes_ + payload.size(), chunk_type_name(type),
                                   header_.frame_byte_limit(), header_.frame_byte_limit_rule()));
    frame_bytes_ += payload.size();
  }
  std::vector<std::uint8_t> chunk;
  try {
    chunk = encode_chunk(type, payload, true, extra_flags);
  } catch (const InputError& e) {
    throw InputError(fmt::format("cannot write trace '{}': {}", name_, e.what()));
  }
  put_bytes(chunk.data(), chunk.size());
  ++chunks_;
}

void TraceWriter::require_frame(const char* what) const {
  NBSIM_CHECK(in_frame_, fmt::format("TraceWriter: {} written outside begin_frame() .. end_frame()", what));
}

void TraceWriter::flush_draws() {
  if (pending_.draws.empty()) return;
  put(ChunkType::DrawBatch, encode(pending_));
  pending_.draws.clear();
  pending_bytes_ = 0;
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
  frame_bytes_ = 0;
  depths_.clear();
  stencils_.clear();
  levels_.clear();
  light_ = truth_ = false;
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
  if (draws_ >= kMaxDrawsPerFrame)
    throw InputError(fmt::format("cannot write trace '{}': frame {} holds more than the per-frame limit of {} draws", name_,
                                 frame_, kMaxDrawsPerFrame));
  pending_.draws.push_back(draw);
  pending_bytes_ += 160 + 20 * draw.clip_positions.size();
  ++draws_;
  if (pending_.draws.size() >= kDrawsPerBatch || pending_bytes_ >= kBatchBytes) flush_draws();
}

void TraceWriter::write(const DepthSnapshot& depth) {
  require_frame("a DPTH record");
  check_record(record_problem(depth), "DPTH");
  NBSIM_CHECK(depths_.insert(depth.name).second,
              fmt::format("TraceWriter: a second '{}' depth snapshot in frame {}", depth.name, frame_));
  flush_draws();
  put(ChunkType::Depth, encode(depth));
}

void TraceWriter::write(const NBufferLevels& levels) {
  require_frame("an NBLV record");
  check_record(record_problem(levels), "NBLV");
  NBSIM_CHECK(levels_.emplace(levels.source, levels.op).second,
              fmt::format("TraceWriter: a second N-buffer with op {} built from '{}' in frame {}", levels.op, levels.source, frame_));
  flush_draws();
  put(ChunkType::Levels, encode(levels));
}

void TraceWriter::write(const StencilSnapshot& stencil) {
  require_frame("an STNC record");
  check_record(record_problem(stencil), "STNC");
  NBSIM_CHECK(stencils_.insert(stencil.name).second,
              fmt::format("TraceWriter: a second '{}' stencil snapshot in frame {}", stencil.name, frame_));
  flush_draws();
  put(ChunkType::Stencil, encode(stencil));
}

void TraceWriter::write_light(const Camera& light) {
  require_frame("an LGHT record");
  NBSIM_CHECK(!light_, fmt::format("TraceWriter: a second light camera in frame {}", frame_));
  light_ = true;
  flush_draws();
  put(ChunkType::Light, encode(light));
}

void TraceWriter::write(const TechniqueRecord& record) {
  require_frame("a technique's record");
  NBSIM_CHECK(!is_known_chunk_type(record.type) && chunk_type_name(record.type).size() == 4,
              fmt::format("TraceWriter: technique record type {} is a core type or not four printable characters",
                          chunk_type_name(record.type)));
  NBSIM_CHECK(!record.decoded || find_technique_chunk(record.type) != nullptr,
              fmt::format("TraceWriter: technique record type {} is not registered", chunk_type_name(record.type)));
  flush_draws();
  put(static_cast<ChunkType>(record.type), encode(record), kFlagTechnique);
}

void TraceWriter::write(const GroundTruth& truth) {
  require_frame("a TRTH record");
  check_record(record_problem(truth), "TRTH");
  NBSIM_CHECK(!truth_, fmt::format("TraceWriter: a second ground truth in frame {}", frame_));
  if (has_scene_) {
    NBSIM_CHECK(truth.visible_pixels.size() == scene_objects_,
                fmt::format("TraceWriter: ground truth for {} objects, the scene has {}", truth.visible_pixels.size(),
                            scene_objects_));
    for (const std::int32_t id : truth.ids)
      NBSIM_CHECK(id < static_cast<std::int64_t>(scene_objects_),
                  fmt::format("TraceWriter: ID buffer holds object {} of {}", id, scene_objects_));
  }
  flush_draws();
  put(ChunkType::Truth, encode(truth));
  truth_ = true;
}

void TraceWriter::end_frame(const FrameEnd& frame) {
  require_frame("a FEND record");
  NBSIM_CHECK(frame.frame == frame_, fmt::format("TraceWriter: end_frame({}) closes frame {}", frame.frame, frame_));
  NBSIM_CHECK(frame.draws == draws_,
              fmt::format("TraceWriter: FrameEnd.draws is {}, but frame {} has {} DRAW records", frame.draws, frame_, draws_));
  flush_draws();
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

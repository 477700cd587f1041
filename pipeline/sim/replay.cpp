// Trace replay through the SystemC model and the counter comparison; see replay.h.
#include "pipeline/sim/replay.h"

#include <fmt/format.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <cmath>
#include <fstream>

#include "model/common/error.h"
#include "model/sim/kernel.h"
#include "model/sim/timeline.h"
#include "pipeline/sim/prefetch.h"
#include "io/json_spill.h"
#include "traces/format/reader.h"
#include "io/output_folder.h"

namespace nbsim::pipeline {

namespace {

// Collects the depth unit's results, compares them with GL's, and writes the CSV files.
class Collector : public depth::ResultSink {
 public:
  Collector(ReplaySummary& s, const ReplayOptions& o, const stats::Registry& registry) : s_(s), o_(o), registry_(registry) {
    if (o.out) {
      draws_.open(*o.out / "draws.csv");
      frames_.open(*o.out / "frames.csv");
      if (!draws_ || !frames_) throw InputError(fmt::format("cannot write into '{}'", o.out->string()));
      draws_ << "frame,draw,object,role,triangles,model_prims_out,gl_prims_out,model_fragments,gl_fragments,"
                "model_passed,gl_passed,depth_tests,culled,lookups,done_cycle\n";
      frames_ << "frame,draws,model_fragments,gl_fragments,model_passed,gl_passed,depth_tests,depth_pixels_matching,"
                 "depth_pixels,end_cycle,cycles\n";
      per_frame_.emplace();
    }
  }

  void draw_done(const cp::Work& w, const depth::DrawResult& r) override {
    const trace::DrawRecord& d = w.record();
    ++frame_.draws;
    s_.depth_tests += r.depth.depth_tests;
    frame_.depth_tests += r.depth.depth_tests;
    if (w.own) {
      // A draw the program made itself (query boxes, draws it decided otherwise than GL):
      // GL drew nothing like it, so it is counted apart from the comparison with GL's counters.
      ++s_.own_draws;
    } else {
      ++s_.draws;
      s_.fragments_model += r.depth.fragments;
      s_.fragments_gl += d.gl.fragments;
      s_.passed_model += r.depth.passed;
      s_.passed_gl += d.gl.samples_passed;
      frame_.fragments_model += r.depth.fragments, frame_.fragments_gl += d.gl.fragments;
      frame_.passed_model += r.depth.passed, frame_.passed_gl += d.gl.samples_passed;
      if (r.depth.fragments == d.gl.fragments && r.depth.passed == d.gl.samples_passed) ++s_.draws_exact;
      if (d.role == trace::DrawRole::Visible && r.depth.passed < d.gl.samples_passed) ++visible_draws_passed_below_gl;
    }
    if (draws_.is_open())
      draws_ << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", w.frame->begin.frame, d.index, d.object,
                            trace::to_string(d.role),
                            d.topology == trace::Topology::Points ? d.clip_positions.size() : d.clip_positions.size() / 3,
                            r.geometry.prims_out, d.gl.clip_prims_out,
                            r.depth.fragments, d.gl.fragments, r.depth.passed, d.gl.samples_passed, r.depth.depth_tests,
                            "none", 0, r.done_cycle);
  }

  void snapshot(const cp::Work& w, const DepthImage& depth) override {
    const trace::DepthSnapshot* gl = w.frame->depth(w.which);
    if (!gl) return;  // GL did not record this one
    if (gl->width != depth.width || gl->height != depth.height)
      throw InputError(fmt::format("frame {}: GL's depth snapshot is {}x{}, the viewport {}x{}", w.frame->begin.frame,
                                   gl->width, gl->height, depth.width, depth.height));
    // Equal texels (nearly all) match with an error of 0, which changes no maximum: only the others
    // take the double-precision difference.
    std::uint64_t matching = 0;
    double worst = s_.depth_max_abs_error;
    const float* model = depth.texels.data();
    const float* glt = gl->texels.data();
    for (std::size_t i = 0, n = depth.texels.size(); i < n; ++i) {
      if (model[i] == glt[i]) {
        ++matching;
        continue;
      }
      const double e = std::fabs(static_cast<double>(model[i]) - static_cast<double>(glt[i]));
      worst = std::max(worst, e);
      if (e <= o_.depth_tolerance) ++matching;
    }
    s_.depth_max_abs_error = worst;
    frame_.depth_matching += matching;
    frame_.depth_pixels += depth.texels.size();
    s_.depth_pixels += depth.texels.size();
  }

  void stencil_at_frame_end(const cp::Work& w, const raster::StencilImage& stencil) override {
    const trace::StencilSnapshot* gl = w.frame->stencil(kStencilSnapshotName);
    if (!gl) return;  // GL did not record the frame's stencil buffer
    if (gl->width != stencil.width || gl->height != stencil.height)
      throw InputError(fmt::format("frame {}: GL's '{}' stencil image is {}x{}, the viewport {}x{}", w.frame->begin.frame,
                                   kStencilSnapshotName, gl->width, gl->height, stencil.width, stencil.height));
    std::uint64_t matching = 0;
    for (std::size_t i = 0; i < stencil.texels.size(); ++i) {
      if (stencil.texels[i] == gl->texels[i]) {
        ++matching;
      } else if (s_.stencil_mismatches.size() < ReplaySummary::kMaxStencilMismatches) {
        const int x = static_cast<int>(i % static_cast<std::size_t>(stencil.width));
        const int y = static_cast<int>(i / static_cast<std::size_t>(stencil.width));
        s_.stencil_mismatches.push_back({w.frame->begin.frame, x, y, stencil.texels[i], gl->texels[i]});
      }
    }
    s_.stencil_pixels += stencil.texels.size();
    s_.stencil_pixels_matching += matching;
    frame_.stencil_pixels = stencil.texels.size();
    frame_.stencil_matching = matching;
  }

  void frame_done(const cp::Work& w, std::uint64_t cycle) override {
    ++s_.frames;
    s_.depth_pixels_matching += frame_.depth_matching;
    if (frames_.is_open())
      frames_ << fmt::format("{},{},{},{},{},{},{},{},{},{},{}\n", w.frame->begin.frame, frame_.draws, frame_.fragments_model,
                             frame_.fragments_gl, frame_.passed_model, frame_.passed_gl, frame_.depth_tests,
                             frame_.depth_matching, frame_.depth_pixels, cycle, cycle - last_cycle_);
    nlohmann::ordered_json pf = {{"frame", w.frame->begin.frame}, {"draws", frame_.draws}, {"depth_tests", frame_.depth_tests},
                                 {"cycles", cycle - last_cycle_}};
    if (frame_.stencil_pixels) {
      pf["stencil_pixels"] = frame_.stencil_pixels;
      pf["stencil_pixels_matching"] = frame_.stencil_matching;
    }
    if (results_ && !results_->group.empty()) {
      if (const stats::Group* g = registry_.find(std::string(results_->group))) {
        const nlohmann::ordered_json now = g->values();
        if (results_->frame_values) results_->frame_values(now, last_program_, pf);
        last_program_ = now;
        if (!results_->per_frame_keys.empty()) {
          program_frames_.push_back(w.frame->begin.frame);
          for (const char* key : results_->per_frame_keys) program_frames_.push_back(pf.value(key, std::uint64_t{0}));
          program_frames_.push_back(cycle - last_cycle_);
        }
      }
    }
    if (per_frame_) per_frame_->push_back(pf);
    last_cycle_ = cycle;
    for (const auto& d : w.frame->draws)
      if (d.clip_positions.empty()) ++s_.passes_not_replayed;
    frame_ = {};
    if (o_.progress) o_.progress(s_.frames, total_frames);
  }

  void stopped(std::uint64_t cycle) override { s_.cycles = cycle; }

  std::uint64_t total_frames = 0;
  std::uint64_t visible_draws_passed_below_gl = 0;  // drawn candidates with fewer passed samples than GL's
  std::uint64_t last_frame_cycle() const noexcept { return last_cycle_; }
  void write_run_json(std::FILE* f, const nlohmann::ordered_json& run) { per_frame_->write_document(f, run); }
  // run.json's "frames", one object a frame: spilled to a temporary file as each frame ends (a
  // run with an output folder only), so that memory does not grow with the trace's length.
  std::optional<io::SpilledJsonArray> per_frame_;
  // The program's results (programs.h), set once its program is built; null: none.
  const ProgramResults* results_ = nullptr;
  // The values its summary keeps frame by frame (ProgramResults::per_frame_keys): the frame's
  // number, the keys' values and its cycles, one frame after another; the one per-frame record a
  // replay keeps in memory (a few words a frame), because ReplaySummary returns them.
  std::vector<std::uint64_t> program_frames_;

 private:
  struct FrameTotals {
    std::uint64_t draws = 0, fragments_model = 0, fragments_gl = 0, passed_model = 0, passed_gl = 0, depth_tests = 0;
    std::uint64_t depth_matching = 0, depth_pixels = 0;
    std::uint64_t stencil_matching = 0, stencil_pixels = 0;
  };
  ReplaySummary& s_;
  const ReplayOptions& o_;
  const stats::Registry& registry_;
  nlohmann::ordered_json last_program_ = nlohmann::ordered_json::object();  // the program's group at the last frame end
  std::ofstream draws_, frames_;
  FrameTotals frame_;
  std::uint64_t last_cycle_ = 0;
};

// The files a run writes, each added before it is opened and removed again unless the run
// completes: a failed run (a damaged trace found mid-run, a record the model cannot replay) leaves
// no empty or partial CSV, JSON or timeline behind for analysis/ to mistake for a result.
class RunOutputs {
 public:
  RunOutputs() = default;
  void add(std::filesystem::path file) { files_.push_back(std::move(file)); }
  ~RunOutputs() {
    std::error_code ec;
    for (const std::filesystem::path& f : files_) std::filesystem::remove(f, ec);
  }
  RunOutputs(const RunOutputs&) = delete;
  RunOutputs& operator=(const RunOutputs&) = delete;
  void keep() noexcept { files_.clear(); }

 private:
  std::vector<std::filesystem::path> files_;
};



}  // namespace

double ReplaySummary::fragment_error() const { return relative_error(fragments_model, fragments_gl); }
double ReplaySummary::passed_error() const { return relative_error(passed_model, passed_gl); }

bool ReplaySummary::within_thresholds() const {
  const bool draws_ok = draws == 0 || static_cast<double>(draws_exact) >= 0.99 * static_cast<double>(draws);
  const bool depth_ok = depth_pixels == 0 || static_cast<double>(depth_pixels_matching) >= 0.9999 * static_cast<double>(depth_pixels);
  const bool stencil_ok = stencil_pixels_matching == stencil_pixels;
  return fragment_error() <= kCounterErrorLimit && passed_error() <= kCounterErrorLimit && draws_ok && depth_ok && stencil_ok && program_exact;
}

nlohmann::ordered_json ReplaySummary::to_json() const {
  nlohmann::ordered_json j;
  j["frames"] = frames;
  j["draws"] = draws;
  j["draws_exact"] = draws_exact;
  if (own_draws) j["own_draws"] = own_draws;
  j["passes_not_replayed"] = passes_not_replayed;
  j["fragments_model"] = fragments_model;
  j["fragments_gl"] = fragments_gl;
  j["fragment_error"] = fragment_error();
  j["passed_model"] = passed_model;
  j["passed_gl"] = passed_gl;
  j["passed_error"] = passed_error();
  j["depth_tests"] = depth_tests;
  j["depth_pixels"] = depth_pixels;
  j["depth_pixels_matching"] = depth_pixels_matching;
  j["depth_max_abs_error"] = depth_max_abs_error;
  if (stencil_tests || stencil_pixels) {
    j["stencil_tests"] = stencil_tests;
    j["stencil_pixels"] = stencil_pixels;
    j["stencil_pixels_matching"] = stencil_pixels_matching;
    nlohmann::ordered_json m = nlohmann::ordered_json::array();
    for (const StencilMismatch& p : stencil_mismatches)
      m.push_back({{"frame", p.frame}, {"x", p.x}, {"y", p.y}, {"model", p.model}, {"gl", p.gl}});
    j["stencil_mismatches"] = m;
  }
  j["cycles"] = cycles;
  j["host_seconds"] = host_seconds;
  j["depth_tests_per_host_second"] = host_seconds > 0 ? static_cast<double>(depth_tests) / host_seconds : 0.0;
  j["cycles_per_host_second"] = host_seconds > 0 ? static_cast<double>(cycles) / host_seconds : 0.0;
  j["within_thresholds"] = within_thresholds();
  if (!program.is_null()) j[program_name] = program;
  return j;
}

ReplaySummary replay(const ReplayOptions& o) {
  // The VCD samples SystemC time, which decoupled units run ahead of: its busy bits would be wrong.
  if (o.vcd && o.config.quantum_cycles > 0)
    throw InputError(fmt::format(
        "--vcd records SystemC time, which the units run ahead of with gpu.quantum_cycles={}: use --timeline "
        "(it records each unit's own time) or gpu.quantum_cycles=0",
        o.config.quantum_cycles));
  if (o.out) io::create_output_folder(*o.out);
  auto frames = std::make_shared<trace::FrameReader>(o.trace);
  const trace::TraceReader& tr = frames->trace();
  const trace::Header& head = tr.header();  // parsed and checked when the trace was opened
  if (!head.viewport) throw InputError(fmt::format("{}: the header has no 'viewport' property", o.trace.string()));
  const int w = head.viewport->width, h = head.viewport->height;
  // The depth images compared with the model's buffer must have its size: checked as each is read.
  frames->require_viewport_depths(
      {std::string(to_string(trace::DepthWhich::AfterOccluders)), std::string(to_string(trace::DepthWhich::Final))});
  const float clear_depth = head.depth_clear;

  RunOutputs outputs;  // declared before the writers, so that it removes their files after they close
  if (o.out)
    for (const char* f : {"draws.csv", "frames.csv", "culls.csv", "run.json"}) outputs.add(*o.out / f);
  ReplaySummary s;
  stats::Registry registry;
  Collector sink(s, o, registry);
  if (head.frames) sink.total_frames = *head.frames;
  sim::install_report_handler();
  // The trace as the programs see it.
  TraceView view;
  view.width_px = w;
  view.height_px = h;
  view.op = head.far_op();
  view.depth_func = view.op == FarOp::Min ? trace::DepthFunc::Greater : trace::DepthFunc::Less;
  view.scene = tr.scene();
  // Frames are read and decoded one ahead on a thread of their own (prefetch.h): the same frames in
  // the same order, a damaged one refused by the same message when the replay reaches it.
  auto ahead = std::make_shared<sim::Prefetch<trace::Frame>>([frames] { return frames->next(); });
  Gpu gpu("gpu", registry, o.config, w, h, [ahead] { return ahead->next(); }, clear_depth, sink, head, view,
          o.out ? &*o.out : nullptr);
  if (o.config.program != "off")
    if (const ProgramRow* row = find_program(head.technique)) sink.results_ = &row->results;
  for (const auto& [k, v] : tr.properties()) {  // DEPTH24_STENCIL8 captures compare 24-bit depths
    if (k != "depth_format") continue;
    const std::optional<raster::DepthFormat> f = raster::parse_depth_format(v);
    if (!f)
      throw InputError(fmt::format("{}: the header's depth_format '{}' is not one the model replays (DEPTH_COMPONENT32F, "
                                   "DEPTH32F_STENCIL8, DEPTH24_STENCIL8, DEPTH_COMPONENT24)",
                                   o.trace.string(), v));
    gpu.set_depth_format(*f);
  }
  std::optional<sim::Timeline> timeline;  // only when asked: units then report their busy spans
  if (o.timeline || o.vcd) {
    sim::TimelineOptions to;
    to.json = o.timeline, to.vcd = o.vcd;
    if (o.timeline) outputs.add(*o.timeline);
    if (o.vcd) outputs.add(*o.vcd);
    timeline.emplace(std::move(to));
    timeline->attach_units();
  }
  const auto t0 = std::chrono::steady_clock::now();
  sc_core::sc_start();
  if (timeline) s.timeline_events = timeline->close().events, s.timeline_dropped = timeline->summary().dropped;
  sim::rethrow_thread_failure();  // a damaged trace read mid-run, as an InputError
  s.host_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  s.stats = registry.values();
  s.stencil_tests = stat(s.stats["gpu.depth"], "stencil_tests");
  if (sink.results_ && s.stats.contains(std::string(sink.results_->group)) && sink.results_->summary) {
    const ProgramResults& r = *sink.results_;
    const SummaryInputs in{s.stats[std::string(r.group)], s.stats, o.config, head, gpu.program(), sink.last_frame_cycle(),
                            sink.visible_draws_passed_below_gl};
    s.program = r.summary(in);
    if (!r.per_frame_keys.empty()) {
      nlohmann::ordered_json per_frame = nlohmann::ordered_json::array();
      const std::size_t width = r.per_frame_keys.size() + 2;
      for (std::size_t at = 0; at + width <= sink.program_frames_.size(); at += width) {
        nlohmann::ordered_json f;
        f["frame"] = sink.program_frames_[at];
        for (std::size_t k = 0; k < r.per_frame_keys.size(); ++k) f[r.per_frame_keys[k]] = sink.program_frames_[at + 1 + k];
        f["cycles"] = sink.program_frames_[at + width - 1];
        per_frame.push_back(std::move(f));
      }
      s.program["per_frame"] = per_frame;
    }
    s.program_name = r.summary_key.empty() ? head.technique : std::string(r.summary_key);
    s.program_exact = !r.exact || r.exact(s.program);
  }

  if (o.out) {
    nlohmann::ordered_json run;
    run["nbsim_version"] = NBSIM_VERSION;
    run["trace"] = o.trace.string();
    nlohmann::ordered_json props = nlohmann::ordered_json::object();
    for (const auto& [k, v] : tr.properties()) props[k] = v;
    run["trace_properties"] = props;
    run["config"] = o.config_values;
    run["summary"] = s.to_json();
    run["stats"] = s.stats;
    run["stats_described"] = registry.describe();
    run["frames"] = io::SpilledJsonArray::placeholder();  // the frames, streamed back from their temporary file
    const std::filesystem::path path = *o.out / "run.json";
    std::FILE* f = std::fopen(path.string().c_str(), "wb");
    if (!f) throw InputError(fmt::format("cannot write '{}': {}", path.string(), std::strerror(errno)));
    try {
      sink.write_run_json(f, run);
    } catch (...) {
      std::fclose(f);
      throw;
    }
    if (std::fclose(f) != 0) throw InputError(fmt::format("cannot write '{}': {}", path.string(), std::strerror(errno)));
  }
  outputs.keep();
  return s;
}

}  // namespace nbsim::pipeline

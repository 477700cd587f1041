// Trace replay through the SystemC model and the counter comparison; see replay.h.
#include "pipeline/sim/replay.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <fstream>

#include "model/common/error.h"
#include "model/sim/kernel.h"
#include "model/sim/timeline.h"
#include "traces/format/reader.h"

namespace nbsim::pipeline {

namespace {

// What the cull stage did over the whole replay (culling modes).
struct CullTotals {
  std::string mode, granularity;
  std::uint64_t frames = 0, frames_with_truth = 0;
  std::uint64_t query_depth_tests = 0, box_depth_tests = 0, lookups = 0, max_lookups = 0;
  std::uint64_t update_texels = 0, clear_texels = 0, drawn_depth_tests = 0, cycles = 0;
  std::uint64_t in_frustum = 0, occluders = 0, candidates = 0, bounds_tests = 0, node_tests = 0, crossing_near = 0;
  std::uint64_t found_visible = 0, culled = 0, undrawable = 0, candidates_not_visible = 0, false_culls = 0;
  // cull.granularity=primitive: per-triangle tests of the drawn candidates (model/cull/primitive.h);
  // their lookups are in query_depth_tests and lookups are not.
  std::uint64_t primitive_tests = 0, primitives_culled = 0, primitive_lookups = 0, primitive_fragments_culled = 0;
  std::uint64_t primitive_false_culls = 0;
  // Drawn candidates (Visible draws) whose passed samples are fewer than GL recorded for the same
  // draw: a triangle culled with a visible fragment shows up here, GL's counters being the ground
  // truth (the model's other draws are bit-exact with GL's; see Collector::draw_done).
  std::uint64_t visible_draws_passed_below_gl = 0;

  void add(const cull::CullReport& r, std::uint64_t frame_depth_tests, std::uint64_t frame_cycles) {
    ++frames;
    frames_with_truth += r.has_truth ? 1 : 0;
    query_depth_tests += r.query_depth_tests();
    box_depth_tests += r.box_depth_tests;
    lookups += r.lookups;
    max_lookups = std::max(max_lookups, r.max_lookups);
    update_texels += r.update_texels;
    clear_texels += r.clear_texels;
    drawn_depth_tests += frame_depth_tests - r.box_depth_tests;  // occluders and visible objects
    cycles += frame_cycles;
    in_frustum += r.in_frustum, occluders += r.occluders, candidates += r.candidates;
    bounds_tests += r.bounds_tests, node_tests += r.node_tests, crossing_near += r.crossing_near;
    found_visible += r.found_visible, culled += r.culled, undrawable += r.undrawable;
    candidates_not_visible += r.candidates_not_visible, false_culls += r.false_culls;
    primitive_tests += r.primitive_tests, primitives_culled += r.primitives_culled;
    primitive_lookups += r.primitive_lookups, primitive_fragments_culled += r.primitive_fragments_culled;
    primitive_false_culls += r.primitive_false_culls;
  }

  std::uint64_t total_depth_tests() const { return query_depth_tests + update_texels + drawn_depth_tests; }

  nlohmann::ordered_json to_json() const {
    const auto per_frame = [this](std::uint64_t v) { return frames ? static_cast<double>(v) / static_cast<double>(frames) : 0.0; };
    nlohmann::ordered_json j;
    j["mode"] = mode;
    j["frames"] = frames;
    j["query_depth_tests"] = query_depth_tests;
    j["query_depth_tests_per_frame"] = per_frame(query_depth_tests);
    j["box_depth_tests"] = box_depth_tests;
    j["lookups"] = lookups;
    j["max_lookups_per_test"] = max_lookups;
    j["update_texels"] = update_texels;
    j["update_texels_per_frame"] = per_frame(update_texels);
    j["clear_texels_per_frame"] = per_frame(clear_texels);
    j["drawn_depth_tests"] = drawn_depth_tests;
    j["drawn_depth_tests_per_frame"] = per_frame(drawn_depth_tests);
    j["total_depth_tests"] = total_depth_tests();
    j["total_depth_tests_per_frame"] = per_frame(total_depth_tests());
    j["cycles"] = cycles;
    j["cycles_per_frame"] = per_frame(cycles);
    j["in_frustum"] = in_frustum;
    j["occluders"] = occluders;
    j["candidates"] = candidates;
    j["bounds_tests"] = bounds_tests;
    j["node_tests"] = node_tests;
    j["crossing_near"] = crossing_near;
    j["found_visible"] = found_visible;
    j["culled"] = culled;
    j["undrawable"] = undrawable;
    j["frames_with_truth"] = frames_with_truth;
    j["candidates_not_visible"] = candidates_not_visible;
    j["false_culls"] = false_culls;
    j["culling_efficiency"] = candidates_not_visible ? static_cast<double>(culled) / static_cast<double>(candidates_not_visible) : 1.0;
    j["granularity"] = granularity;
    j["primitive_tests"] = primitive_tests;
    j["primitive_tests_per_frame"] = per_frame(primitive_tests);
    j["primitives_culled"] = primitives_culled;
    j["primitives_culled_per_frame"] = per_frame(primitives_culled);
    j["primitive_lookups"] = primitive_lookups;
    j["primitive_lookups_per_frame"] = per_frame(primitive_lookups);
    j["primitive_fragments_culled"] = primitive_fragments_culled;
    j["primitive_fragments_culled_per_frame"] = per_frame(primitive_fragments_culled);
    j["primitive_false_culls"] = primitive_false_culls;
    j["visible_draws_passed_below_gl"] = visible_draws_passed_below_gl;
    return j;
  }
};

// Collects the depth unit's results, compares them with GL's, and writes the CSV files.
class Collector : public depth::ResultSink {
 public:
  Collector(ReplaySummary& s, const ReplayOptions& o) : s_(s), o_(o) {
    if (o.out) {
      draws_.open(*o.out / "draws.csv");
      frames_.open(*o.out / "frames.csv");
      if (!draws_ || !frames_) throw InputError(fmt::format("cannot write into '{}'", o.out->string()));
      draws_ << "frame,draw,object,role,triangles,model_prims_out,gl_prims_out,model_fragments,gl_fragments,"
                "model_passed,gl_passed,depth_tests,culled,lookups,done_cycle\n";
      frames_ << "frame,draws,model_fragments,gl_fragments,model_passed,gl_passed,depth_tests,depth_pixels_matching,"
                 "depth_pixels,end_cycle,cycles\n";
      // Every bounds test a culling mode made (empty with cull.mode=trace, which only replays).
      culls_.open(*o.out / "culls.csv");
      if (!culls_) throw InputError(fmt::format("cannot write into '{}'", o.out->string()));
      culls_ << "frame,mode,object,node,x,y,w,h,nearest_depth,crosses_near,decision,depth_tests,truth_visible_pixels,false_cull\n";
    }
  }

  void draw_done(const cp::Work& w, const depth::DrawResult& r) override {
    const trace::DrawRecord& d = w.record();
    ++s_.draws;
    ++frame_.draws;
    s_.fragments_model += r.depth.fragments;
    s_.fragments_gl += d.gl.fragments;
    s_.passed_model += r.depth.passed;
    s_.passed_gl += d.gl.samples_passed;
    s_.depth_tests += r.depth.depth_tests;
    frame_.fragments_model += r.depth.fragments, frame_.fragments_gl += d.gl.fragments;
    frame_.passed_model += r.depth.passed, frame_.passed_gl += d.gl.samples_passed;
    frame_.depth_tests += r.depth.depth_tests;
    if (r.depth.fragments == d.gl.fragments && r.depth.passed == d.gl.samples_passed) ++s_.draws_exact;
    if (d.role == trace::DrawRole::Visible && r.depth.passed < d.gl.samples_passed) ++cull.visible_draws_passed_below_gl;
    if (draws_.is_open())
      draws_ << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", w.frame->begin.frame, d.index, d.object,
                            trace::to_string(d.role), d.clip_positions.size() / 3, r.geometry.prims_out, d.gl.clip_prims_out,
                            r.depth.fragments, d.gl.fragments, r.depth.passed, d.gl.samples_passed, r.depth.depth_tests,
                            "none", 0, r.done_cycle);
  }

  void snapshot(const cp::Work& w, const DepthImage& depth) override {
    const trace::DepthSnapshot* gl = w.frame->depth(w.which);
    if (!gl) return;  // GL did not record this one
    if (gl->width != depth.width || gl->height != depth.height)
      throw InputError(fmt::format("frame {}: GL's depth snapshot is {}x{}, the viewport {}x{}", w.frame->begin.frame,
                                   gl->width, gl->height, depth.width, depth.height));
    for (std::size_t i = 0; i < depth.texels.size(); ++i) {
      const double e = std::fabs(static_cast<double>(depth.texels[i]) - static_cast<double>(gl->texels[i]));
      s_.depth_max_abs_error = std::max(s_.depth_max_abs_error, e);
      if (e <= o_.depth_tolerance) ++frame_.depth_matching;
    }
    frame_.depth_pixels += depth.texels.size();
    s_.depth_pixels += depth.texels.size();
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
    if (const cull::CullReport* r = w.cull_report.get()) {
      cull.add(*r, frame_.depth_tests, cycle - last_cycle_);
      if (culls_.is_open()) write_tests(w, *r);
      pf["query_depth_tests"] = r->query_depth_tests();
      pf["update_texels"] = r->update_texels;
      pf["total_depth_tests"] = r->query_depth_tests() + r->update_texels + (frame_.depth_tests - r->box_depth_tests);
      pf["bounds_tests"] = r->bounds_tests;
      pf["candidates"] = r->candidates;
      pf["culled"] = r->culled;
      pf["candidates_not_visible"] = r->candidates_not_visible;
      pf["false_culls"] = r->false_culls;
      pf["undrawable"] = r->undrawable;
      pf["primitive_tests"] = r->primitive_tests;
      pf["primitives_culled"] = r->primitives_culled;
      pf["primitive_lookups"] = r->primitive_lookups;
      pf["primitive_fragments_culled"] = r->primitive_fragments_culled;
      pf["primitive_false_culls"] = r->primitive_false_culls;
    }
    per_frame_.push_back(std::move(pf));
    last_cycle_ = cycle;
    for (const auto& d : w.frame->draws)
      if (d.clip_positions.empty()) ++s_.passes_not_replayed;
    frame_ = {};
    if (o_.progress) o_.progress(s_.frames, total_frames);
  }

  void stopped(std::uint64_t cycle) override { s_.cycles = cycle; }

  // One culls.csv row per bounds test: what was tested, the decision, its cost, the ground truth.
  void write_tests(const cp::Work& w, const cull::CullReport& r) {
    const trace::GroundTruth* truth = w.frame->truth ? &*w.frame->truth : nullptr;
    for (const cull::CullReport::Test& t : r.tests) {
      std::string pixels = "";
      bool false_cull = false;
      if (t.object >= 0 && truth && static_cast<std::size_t>(t.object) < truth->visible_pixels.size()) {
        const std::uint32_t px = truth->visible_pixels[static_cast<std::size_t>(t.object)];
        pixels = std::to_string(px);
        false_cull = px > 0 && !t.bounds.visible;
      }
      culls_ << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", w.frame->begin.frame, cull::to_string(r.mode),
                            t.object, t.node, t.bounds.x, t.bounds.y, t.bounds.w, t.bounds.h, t.bounds.nearest_depth,
                            t.bounds.crosses_near ? 1 : 0, t.bounds.visible ? "visible" : "culled", t.depth_tests, pixels,
                            false_cull ? 1 : 0);
    }
  }

  std::uint64_t total_frames = 0;
  CullTotals cull;
  nlohmann::ordered_json per_frame_ = nlohmann::ordered_json::array();

 private:
  struct FrameTotals {
    std::uint64_t draws = 0, fragments_model = 0, fragments_gl = 0, passed_model = 0, passed_gl = 0, depth_tests = 0;
    std::uint64_t depth_matching = 0, depth_pixels = 0;
  };
  ReplaySummary& s_;
  const ReplayOptions& o_;
  std::ofstream draws_, frames_, culls_;
  FrameTotals frame_;
  std::uint64_t last_cycle_ = 0;
};

double rel(std::uint64_t a, std::uint64_t b) {
  if (b == 0) return a == 0 ? 0.0 : 1.0;
  return std::fabs(static_cast<double>(a) - static_cast<double>(b)) / static_cast<double>(b);
}

}  // namespace

double ReplaySummary::fragment_error() const { return rel(fragments_model, fragments_gl); }
double ReplaySummary::passed_error() const { return rel(passed_model, passed_gl); }

bool ReplaySummary::within_thresholds() const {
  const bool draws_ok = draws == 0 || static_cast<double>(draws_exact) >= 0.99 * static_cast<double>(draws);
  const bool depth_ok = depth_pixels == 0 || static_cast<double>(depth_pixels_matching) >= 0.9999 * static_cast<double>(depth_pixels);
  return fragment_error() <= 1e-4 && passed_error() <= 1e-4 && draws_ok && depth_ok;
}

nlohmann::ordered_json ReplaySummary::to_json() const {
  nlohmann::ordered_json j;
  j["frames"] = frames;
  j["draws"] = draws;
  j["draws_exact"] = draws_exact;
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
  j["cycles"] = cycles;
  j["host_seconds"] = host_seconds;
  j["depth_tests_per_host_second"] = host_seconds > 0 ? static_cast<double>(depth_tests) / host_seconds : 0.0;
  j["cycles_per_host_second"] = host_seconds > 0 ? static_cast<double>(cycles) / host_seconds : 0.0;
  j["within_thresholds"] = within_thresholds();
  if (!cull.is_null()) j["cull"] = cull;
  return j;
}

ReplaySummary replay(const ReplayOptions& o) {
  // The VCD samples SystemC time, which decoupled units run ahead of: its busy bits would be wrong.
  if (o.vcd && o.config.quantum_cycles > 0)
    throw InputError(fmt::format(
        "--vcd records SystemC time, which the units run ahead of with gpu.quantum_cycles={}: use --timeline "
        "(it records each unit's own time) or gpu.quantum_cycles=0",
        o.config.quantum_cycles));
  if (o.out) {
    std::error_code ec;
    std::filesystem::create_directories(*o.out, ec);
    if (ec) throw InputError(fmt::format("cannot create output folder '{}': {}", o.out->string(), ec.message()));
  }
  auto frames = std::make_shared<trace::FrameReader>(o.trace);
  const trace::TraceReader& tr = frames->trace();
  const trace::Header& head = tr.header();  // parsed and checked when the trace was opened
  if (!head.viewport) throw InputError(fmt::format("{}: the header has no 'viewport' property", o.trace.string()));
  const int w = head.viewport->width, h = head.viewport->height;
  const float clear_depth = head.depth_clear;

  ReplaySummary s;
  Collector sink(s, o);
  if (head.frames) sink.total_frames = *head.frames;
  stats::Registry registry;
  sim::install_report_handler();
  // The cull stage's view of the trace (culling modes only read it).
  cull::CullSetup setup;
  setup.width_px = w;
  setup.height_px = h;
  setup.op = head.far_op();
  setup.depth_func = setup.op == FarOp::Min ? trace::DepthFunc::Greater : trace::DepthFunc::Less;
  setup.near_m = head.near_m;
  setup.nearest_margin = head.nearest_margin;
  setup.zero_to_one = head.clip_control == trace::ClipControl::ZeroToOne;
  setup.scene = tr.scene();
  setup.fused_interpolation = o.config.depth.fused_interpolation;
  sink.cull.mode = o.config.cull.mode;
  sink.cull.granularity = o.config.cull.granularity;
  Gpu gpu("gpu", registry, o.config, w, h, [frames] { return frames->next(); }, clear_depth, sink, &setup);
  std::optional<sim::Timeline> timeline;  // only when asked: units then report their busy spans
  if (o.timeline || o.vcd) {
    sim::TimelineOptions to;
    to.json = o.timeline, to.vcd = o.vcd;
    timeline.emplace(std::move(to));
    timeline->attach_units();
  }
  const auto t0 = std::chrono::steady_clock::now();
  sc_core::sc_start();
  if (timeline) s.timeline_events = timeline->close().events, s.timeline_dropped = timeline->summary().dropped;
  sim::rethrow_thread_failure();  // a damaged trace read mid-run, as an InputError
  s.host_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  s.stats = registry.values();
  if (o.config.cull.parsed_mode() != cull::CullMode::Trace) {
    s.cull = sink.cull.to_json();
    const long long bytes = gpu.cull() ? gpu.cull()->structure_bytes() : 0;
    s.cull["structure_memory_bytes"] = bytes;  // N-buffer levels, tile Hi-Z or pyramid
    s.cull["nbuffer_memory_bytes"] = gpu.cull() && gpu.cull()->nbuffer_unit() ? nlohmann::ordered_json(bytes) : nullptr;
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
    run["frames"] = sink.per_frame_;
    std::ofstream(*o.out / "run.json") << run.dump(2) << "\n";
  }
  return s;
}

}  // namespace nbsim::pipeline

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
#include "model/relief/walk.h"
#include "model/sim/timeline.h"
#include "io/json_spill.h"
#include "traces/format/reader.h"
#include "io/output_folder.h"

namespace nbsim::pipeline {

namespace {

// The cull stage's per-frame values (run.json "frames"): differences of its statistics between two
// frame ends, which are exact because the next frame's tests wait for the frame to leave the
// pipeline (model/cull/unit.h).
constexpr std::array<const char*, 11> kCullFrameCounts = {
    "bounds_tests",    "candidates",        "culled",            "candidates_not_visible",     "false_culls",
    "undrawable",      "primitive_tests",   "primitives_culled", "primitive_lookups",          "primitive_fragments_culled",
    "primitive_false_culls"};
// The particles program's counters in run.json's per-frame values (differences at frame ends).
constexpr std::array<const char*, 11> kParticlesFrameCounts = {
    "particles", "culled", "kept_too_large", "lookups", "particle_fragments", "build_texels", "decision_mismatches",
    "popping", "false_culls", "exactly_hidden", "hidden_kept"};
// The shadows program's counters in run.json's per-frame values (differences at frame ends).
constexpr std::array<const char*, 19> kShadowsFrameCounts = {
    "casters",     "culled",          "gl_culled",       "outside",    "crossing_near",       "kept_by_slab", "reference_fill",
    "lookups",     "build_texels",    "litmap_reprojections", "receiver_splats", "volume_draws", "fill", "gl_fill",
    "stencil_tests", "mask_pixels", "mask_diff",       "mask_diff_infinite", "decision_mismatches"};

// The ldi program's counters in run.json's per-frame values (differences at frame ends).
constexpr std::array<const char*, 16> kLdiFrameCounts = {
    "peel_passes", "peel_fragments", "gl_peel_fragments", "peel_samples", "gl_peel_samples", "peel_pass_mismatches", "layers",
    "gl_layers", "layer_texel_mismatches", "crop_mismatch", "compressed_mismatches", "test_points", "parity_mismatches_layers",
    "parity_mismatches_ranges", "misclassified_layers", "misclassified_ranges"};

// The relief program's counters in run.json's per-frame values, per method (differences at frame ends).
constexpr std::array<const char*, 9> kReliefFrameCounts = {"fragments", "gl_fragments", "pixel_mismatches", "walk_mismatches",
                                                            "lookups", "steps", "errors", "reference_hits", "cycles"};

// A statistic of a group's values (0 when the group has none of that name).
std::uint64_t stat(const nlohmann::ordered_json& group, const char* name) {
  const auto it = group.find(name);
  return it == group.end() ? 0 : static_cast<std::uint64_t>(it->get<double>());
}

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
      // A draw the program made itself (its own query boxes, particle draws it decided otherwise):
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
    for (std::size_t i = 0; i < depth.texels.size(); ++i) {
      const double e = std::fabs(static_cast<double>(depth.texels[i]) - static_cast<double>(gl->texels[i]));
      s_.depth_max_abs_error = std::max(s_.depth_max_abs_error, e);
      if (e <= o_.depth_tolerance) ++frame_.depth_matching;
    }
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
    if (const stats::Group* g = registry_.find("gpu.cull")) {
      const nlohmann::ordered_json now = g->values();
      const auto delta = [&](const char* name) { return stat(now, name) - stat(last_cull_, name); };
      pf["query_depth_tests"] = delta("query_depth_tests");
      pf["update_texels"] = delta("update_texels");
      pf["total_depth_tests"] = delta("query_depth_tests") + delta("update_texels") + (frame_.depth_tests - delta("box_depth_tests"));
      for (const char* name : kCullFrameCounts) pf[name] = delta(name);
      last_cull_ = now;
    }
    if (const stats::Group* g = registry_.find("gpu.particles")) {
      const nlohmann::ordered_json now = g->values();
      const auto delta = [&](const char* name) { return stat(now, name) - stat(last_particles_, name); };
      pf["query_depth_tests"] = delta("lookups");
      pf["total_depth_tests"] = delta("lookups") + delta("particle_fragments") + delta("build_texels");
      for (const char* name : kParticlesFrameCounts) pf[name] = delta(name);
      last_particles_ = now;
    }
    if (const stats::Group* g = registry_.find("gpu.shadows")) {
      const nlohmann::ordered_json now = g->values();
      for (const char* name : kShadowsFrameCounts) pf[name] = stat(now, name) - stat(last_shadows_, name);
      last_shadows_ = now;
    }
    if (const stats::Group* g = registry_.find("gpu.ldi")) {
      const nlohmann::ordered_json now = g->values();
      for (const char* name : kLdiFrameCounts) pf[name] = stat(now, name) - stat(last_ldi_, name);
      last_ldi_ = now;
    }
    if (const stats::Group* g = registry_.find("gpu.relief")) {
      const nlohmann::ordered_json now = g->values();
      nlohmann::ordered_json methods = nlohmann::ordered_json::object();
      for (relief::Method m : relief::kAllMethods) {
        const std::string prefix = std::string(relief::to_string(m)) + "_";
        if (stat(now, (prefix + "draws").c_str()) == stat(last_relief_, (prefix + "draws").c_str())) continue;
        nlohmann::ordered_json v;
        for (const char* name : kReliefFrameCounts) v[name] = stat(now, (prefix + name).c_str()) - stat(last_relief_, (prefix + name).c_str());
        methods[std::string(relief::to_string(m))] = v;
      }
      pf["relief"] = methods;
      last_relief_ = now;
    }
    if (registry_.find("gpu.shadows"))
      shadows_frames_.push_back({w.frame->begin.frame, pf.value("fill", std::uint64_t{0}), pf.value("reference_fill", std::uint64_t{0}),
                                 pf.value("culled", std::uint64_t{0}), pf.value("gl_culled", std::uint64_t{0}),
                                 pf.value("mask_diff", std::uint64_t{0}), pf.value("mask_diff_infinite", std::uint64_t{0}),
                                 cycle - last_cycle_});
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
  // The shadows summary's "per_frame" values (shadows traces only): 64 bytes a frame, the one
  // per-frame record a replay keeps in memory, because ReplaySummary (`nbsim compare --json`)
  // returns them (320 KiB at 5,000 frames).
  struct ShadowsFrame {
    std::uint32_t frame = 0;
    std::uint64_t fill = 0, reference_fill = 0, culled = 0, gl_culled = 0, mask_diff = 0, mask_diff_infinite = 0, cycles = 0;
  };
  std::vector<ShadowsFrame> shadows_frames_;

 private:
  struct FrameTotals {
    std::uint64_t draws = 0, fragments_model = 0, fragments_gl = 0, passed_model = 0, passed_gl = 0, depth_tests = 0;
    std::uint64_t depth_matching = 0, depth_pixels = 0;
    std::uint64_t stencil_matching = 0, stencil_pixels = 0;
  };
  ReplaySummary& s_;
  const ReplayOptions& o_;
  const stats::Registry& registry_;
  nlohmann::ordered_json last_cull_ = nlohmann::ordered_json::object();  // gpu.cull at the last frame end
  nlohmann::ordered_json last_particles_ = nlohmann::ordered_json::object();  // gpu.particles at the last frame end
  nlohmann::ordered_json last_shadows_ = nlohmann::ordered_json::object();    // gpu.shadows at the last frame end
  nlohmann::ordered_json last_ldi_ = nlohmann::ordered_json::object();        // gpu.ldi at the last frame end
  nlohmann::ordered_json last_relief_ = nlohmann::ordered_json::object();     // gpu.relief at the last frame end
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

// The cull stage's run totals (summary "cull", the columns of Table 2 and of explore's results),
// derived from its statistics and the depth unit's when the run is done.
nlohmann::ordered_json cull_summary(const nlohmann::ordered_json& cull, const nlohmann::ordered_json& depth,
                                    const cull::CullUnitConfig& config, std::uint64_t cycles,
                                    std::uint64_t visible_draws_passed_below_gl) {
  const std::uint64_t frames = stat(cull, "frames");
  const auto per_frame = [frames](std::uint64_t v) { return frames ? static_cast<double>(v) / static_cast<double>(frames) : 0.0; };
  const std::uint64_t query = stat(cull, "query_depth_tests"), update = stat(cull, "update_texels");
  const std::uint64_t drawn = stat(depth, "depth_tests") - stat(cull, "box_depth_tests");  // occluders and visible objects
  const std::uint64_t total = query + update + drawn;
  nlohmann::ordered_json j;
  j["mode"] = config.mode;
  j["frames"] = frames;
  j["query_depth_tests"] = query;
  j["query_depth_tests_per_frame"] = per_frame(query);
  j["box_depth_tests"] = stat(cull, "box_depth_tests");
  j["lookups"] = stat(cull, "lookups");
  j["max_lookups_per_test"] = stat(cull, "max_lookups");
  j["update_texels"] = update;
  j["update_texels_per_frame"] = per_frame(update);
  j["clear_texels_per_frame"] = per_frame(stat(cull, "clear_texels"));
  j["drawn_depth_tests"] = drawn;
  j["drawn_depth_tests_per_frame"] = per_frame(drawn);
  j["total_depth_tests"] = total;
  j["total_depth_tests_per_frame"] = per_frame(total);
  j["cycles"] = cycles;
  j["cycles_per_frame"] = per_frame(cycles);
  for (const char* name : {"in_frustum", "occluders", "candidates", "bounds_tests", "node_tests", "crossing_near", "found_visible",
                           "culled", "undrawable", "frames_with_truth", "candidates_not_visible", "false_culls"})
    j[name] = stat(cull, name);
  j["culling_efficiency"] = cull["culling_efficiency"];
  j["granularity"] = config.granularity;
  for (const char* name : {"primitive_tests", "primitives_culled", "primitive_lookups", "primitive_fragments_culled"}) {
    j[name] = stat(cull, name);
    j[std::string(name) + "_per_frame"] = per_frame(stat(cull, name));
  }
  j["primitive_false_culls"] = stat(cull, "primitive_false_culls");
  j["visible_draws_passed_below_gl"] = visible_draws_passed_below_gl;
  return j;
}

// The particles program's run totals (summary "particles"), from its statistics and its N-buffer's
// when the run is done. Depth tests as docs/architecture.md ("Definitions") counts them: the
// queries' texels read, the particle draws' fragments, and the partial build's texels; the scene's
// own depth tests apart.
nlohmann::ordered_json particles_summary(const nlohmann::ordered_json& p, std::string_view mode, std::uint64_t cycles) {
  const std::uint64_t frames = stat(p, "frames");
  const auto per_frame = [frames](std::uint64_t v) { return frames ? static_cast<double>(v) / static_cast<double>(frames) : 0.0; };
  const std::uint64_t query = stat(p, "lookups"), raster = stat(p, "particle_fragments"), build = stat(p, "build_texels");
  const std::uint64_t total = query + raster + build;
  nlohmann::ordered_json j;
  j["mode"] = mode;
  j["frames"] = frames;
  for (const char* name : {"particles", "tested", "culled", "kept_too_large", "offscreen", "gl_culled"}) {
    j[name] = stat(p, name);
    j[std::string(name) + "_per_frame"] = per_frame(stat(p, name));
  }
  j["query_depth_tests"] = query;
  j["query_depth_tests_per_frame"] = per_frame(query);
  j["gl_lookups"] = stat(p, "gl_lookups");
  j["raster_depth_tests"] = raster;
  j["raster_depth_tests_per_frame"] = per_frame(raster);
  j["raster_passed"] = stat(p, "particle_passed");
  j["build_texels"] = build;
  j["build_texels_per_frame"] = per_frame(build);
  j["total_depth_tests"] = total;
  j["total_depth_tests_per_frame"] = per_frame(total);
  j["scene_depth_tests_per_frame"] = per_frame(stat(p, "scene_depth_tests"));
  j["cycles"] = cycles;
  j["cycles_per_frame"] = per_frame(cycles);
  for (const char* name : {"decision_mismatches", "lookup_mismatches", "popping", "false_culls", "exactly_hidden",
                           "visible_reference", "dropped", "redrawn", "own_draws"})
    j[name] = stat(p, name);
  // Culled less than the exact sprite test would (the cost of a conservative test): drawn sprites
  // with no passing pixel that the model kept.
  j["culled_below_exact"] = stat(p, "hidden_kept");
  // As fractions of the sprites the exact test culls (exactly_hidden): the share it culled
  // (culling_efficiency, 1 when no sprite was hidden) and the share it kept (culled_below_exact_fraction).
  const std::uint64_t hidden = stat(p, "exactly_hidden"), kept = stat(p, "hidden_kept");
  j["culling_efficiency"] = hidden ? static_cast<double>(hidden - kept) / static_cast<double>(hidden) : 1.0;
  j["culled_below_exact_fraction"] = hidden ? static_cast<double>(kept) / static_cast<double>(hidden) : 0.0;
  return j;
}

// The shadows program's run totals (summary "shadows"), from its statistics and both N-buffers'
// when the run is done; the per-frame values (fill, culled casters, cycles) are run.json's frames.
nlohmann::ordered_json shadows_summary(const nlohmann::ordered_json& p, std::uint64_t cycles) {
  const std::uint64_t frames = stat(p, "frames");
  const auto per_frame = [frames](std::uint64_t v) { return frames ? static_cast<double>(v) / static_cast<double>(frames) : 0.0; };
  nlohmann::ordered_json j;
  j["frames"] = frames;
  for (const char* name : {"casters", "measured", "culled", "gl_culled", "outside", "crossing_near", "kept_by_slab", "lookups",
                           "build_texels", "litmap_draws", "litmap_reprojections", "receiver_splats", "volume_draws", "fill", "gl_fill",
                           "reference_fill", "stencil_tests", "mask_pixels", "scene_depth_tests"}) {
    j[name] = stat(p, name);
    j[std::string(name) + "_per_frame"] = per_frame(stat(p, name));
  }
  // The fill against GL's infinite reference of the same frames (null when the trace predates
  // SHDC's reference_fill on some frame).
  const std::uint64_t reference = stat(p, "reference_fill");
  j["fill_ratio_to_infinite"] = stat(p, "reference_frames") == frames && reference > 0
                                    ? nlohmann::ordered_json(static_cast<double>(stat(p, "fill")) / static_cast<double>(reference))
                                    : nlohmann::ordered_json(nullptr);
  j["cycles"] = cycles;
  j["cycles_per_frame"] = per_frame(cycles);
  for (const char* name : {"decision_mismatches", "zmin_mismatches", "zmax_mismatches", "not_conservative", "unsafe_culls",
                           "culls_lost", "lookup_mismatches", "mask_diff", "mask_diff_infinite", "gl_mask_diff", "gl_mask_pixels"})
    j[name] = stat(p, name);
  return j;
}

// The ldi program's run totals (summary "ldi"), from its statistics; the per-frame values are
// run.json's frames. Rates are null when nothing was classified; cycles are the program's own
// (peel and parity tests), cycles_total the run's.
nlohmann::ordered_json ldi_summary(const nlohmann::ordered_json& p, const nlohmann::ordered_json& memory, std::uint64_t cycles) {
  nlohmann::ordered_json j;
  for (const char* name : {"frames", "peel_passes", "peel_fragments", "gl_peel_fragments", "peel_samples", "gl_peel_samples",
                           "peel_reads", "peel_discarded", "peel_pass_mismatches", "layers", "gl_layers", "layer_count_mismatches",
                           "layer_texel_mismatches", "crop_mismatch", "compressed_mismatches", "m_crop", "m_comp", "test_points",
                           "parity_mismatches_layers", "parity_mismatches_ranges", "fetch_mismatches_layers",
                           "fetch_mismatches_ranges", "fetches_layers", "fetches_ranges", "gl_fetches_layers", "gl_fetches_ranges",
                           "misclassified_layers", "misclassified_ranges", "classified_points", "near_surface_points"})
    j[name] = stat(p, name);
  const std::uint64_t classified = stat(p, "classified_points");
  const auto rate = [classified](std::uint64_t v) {
    return classified ? nlohmann::ordered_json(static_cast<double>(v) / static_cast<double>(classified)) : nlohmann::ordered_json(nullptr);
  };
  j["misclassification_rate_layers"] = rate(stat(p, "misclassified_layers"));
  j["misclassification_rate_ranges"] = rate(stat(p, "misclassified_ranges"));
  const std::uint64_t m_crop = stat(p, "m_crop");
  j["c_ratio"] = m_crop ? nlohmann::ordered_json(static_cast<double>(stat(p, "m_comp")) / static_cast<double>(m_crop))
                        : nlohmann::ordered_json(nullptr);
  nlohmann::ordered_json kinds = nlohmann::ordered_json::object();
  for (const char* kind : {"random", "crop_boundary", "near_surface", "midway"}) {
    const std::string k(kind);
    kinds[k] = {{"points", stat(p, ("points_" + k).c_str())},
                {"classified", stat(p, ("classified_" + k).c_str())},
                {"misclassified_layers", stat(p, ("misclassified_layers_" + k).c_str())},
                {"misclassified_ranges", stat(p, ("misclassified_ranges_" + k).c_str())}};
  }
  j["by_kind"] = kinds;
  j["peel_cycles"] = stat(p, "peel_cycles");
  j["vpt_cycles"] = stat(p, "vpt_cycles");
  j["cycles"] = stat(p, "peel_cycles") + stat(p, "vpt_cycles");
  j["cycles_total"] = cycles;
  j["memory_bytes"] = stat(memory, "bytes_ldi");
  j["peel_bytes"] = stat(p, "peel_bytes");
  j["vpt_bytes"] = stat(p, "vpt_bytes");
  return j;
}

// The relief program's run totals (summary "relief"), from its statistics: per method its counts,
// lookups and steps per fragment, cycles, and hit error against the exact reference.
nlohmann::ordered_json relief_summary(const nlohmann::ordered_json& p, const nlohmann::ordered_json& memory, std::uint64_t cycles) {
  nlohmann::ordered_json j;
  for (const char* name : {"frames", "scene_draws", "scene_depth_tests", "box_draws", "cache_hits", "cache_misses", "memory_bytes",
                           "memory_stall_cycles", "cycles"})
    j[name] = stat(p, name);
  j["cycles_total"] = cycles;
  j["channel_bytes"] = stat(memory, "bytes_relief");
  nlohmann::ordered_json methods = nlohmann::ordered_json::object();
  for (relief::Method m : relief::kAllMethods) {
    const std::string prefix = std::string(relief::to_string(m)) + "_";
    const auto v = [&](const char* name) { return stat(p, (prefix + name).c_str()); };
    if (v("draws") == 0) continue;
    nlohmann::ordered_json e;
    for (const char* name : {"draws", "rasterized", "fragments", "gl_fragments", "samples", "gl_samples", "pixel_mismatches", "walk_mismatches", "lookups",
                             "gl_lookups", "steps", "bisections", "hits", "capped", "reference_hits", "wrong_hit", "wrong_miss",
                             "far_hit", "errors", "cycles", "cache_misses"})
      e[name] = v(name);
    const double fragments = static_cast<double>(v("fragments"));
    const auto per = [fragments](std::uint64_t x) {
      return fragments > 0 ? nlohmann::ordered_json(static_cast<double>(x) / fragments) : nlohmann::ordered_json(nullptr);
    };
    e["lookups_per_fragment"] = per(v("lookups"));
    e["steps_per_fragment"] = per(v("steps"));
    e["error_rate"] = per(v("errors"));
    const std::uint64_t both = v("hits") - std::min(v("hits"), v("wrong_hit"));
    e["mean_hit_distance"] = both ? nlohmann::ordered_json(static_cast<double>(v("distance_microtexels")) * 1e-6 / static_cast<double>(both))
                                  : nlohmann::ordered_json(nullptr);
    e["cycles_per_frame"] = stat(p, "frames") ? nlohmann::ordered_json(static_cast<double>(v("cycles")) / static_cast<double>(stat(p, "frames")))
                                              : nlohmann::ordered_json(nullptr);
    methods[std::string(relief::to_string(m))] = e;
  }
  j["methods"] = methods;
  // Totals over the methods (the results row's metrics).
  std::uint64_t fragments = 0, lookups = 0, errors = 0, walk_mismatches = 0, pixel_mismatches = 0;
  for (const auto& [name, e] : methods.items()) {
    fragments += e["fragments"].get<std::uint64_t>(), lookups += e["lookups"].get<std::uint64_t>();
    errors += e["errors"].get<std::uint64_t>(), walk_mismatches += e["walk_mismatches"].get<std::uint64_t>();
    pixel_mismatches += e["pixel_mismatches"].get<std::uint64_t>();
  }
  j["fragments"] = fragments;
  j["lookups"] = lookups;
  j["lookups_per_fragment"] = fragments ? nlohmann::ordered_json(static_cast<double>(lookups) / static_cast<double>(fragments)) : nlohmann::ordered_json(nullptr);
  j["errors"] = errors;
  j["error_rate"] = fragments ? nlohmann::ordered_json(static_cast<double>(errors) / static_cast<double>(fragments)) : nlohmann::ordered_json(nullptr);
  j["walk_mismatches"] = walk_mismatches;
  j["pixel_mismatches"] = pixel_mismatches;
  return j;
}

double rel(std::uint64_t a, std::uint64_t b) {
  if (b == 0) return a == 0 ? 0.0 : 1.0;
  return std::fabs(static_cast<double>(a) - static_cast<double>(b)) / static_cast<double>(b);
}

}  // namespace

double ReplaySummary::fragment_error() const { return rel(fragments_model, fragments_gl); }
double ReplaySummary::passed_error() const { return rel(passed_model, passed_gl); }

const nlohmann::ordered_json& ReplaySummary::program_summary() const {
  for (const nlohmann::ordered_json* s : {&particles, &shadows, &ldi, &relief})
    if (!s->is_null()) return *s;
  return particles;  // null
}

bool ReplaySummary::within_thresholds() const {
  const bool draws_ok = draws == 0 || static_cast<double>(draws_exact) >= 0.99 * static_cast<double>(draws);
  const bool depth_ok = depth_pixels == 0 || static_cast<double>(depth_pixels_matching) >= 0.9999 * static_cast<double>(depth_pixels);
  const bool stencil_ok = stencil_pixels_matching == stencil_pixels;
  // An ldi trace's peel is the program's own replay of GL's peel draws: its fragments and samples
  // against GL's counters under the same thresholds.
  const auto counter = [this](const char* name) { return ldi.value(name, std::uint64_t{0}); };
  const bool ldi_ok = ldi.is_null() || (rel(counter("peel_fragments"), counter("gl_peel_fragments")) <= 1e-4 &&
                                        rel(counter("peel_samples"), counter("gl_peel_samples")) <= 1e-4);
  // A relief trace: every method's fragments, samples and walks equal GL's.
  bool relief_ok = true;
  if (!relief.is_null())
    for (const auto& [name, m] : relief["methods"].items())
      relief_ok = relief_ok && m.value("pixel_mismatches", 0) == 0 && m.value("walk_mismatches", 0) == 0 &&
                  m.value("fragments", 0) == m.value("gl_fragments", 0) && m.value("samples", 0) == m.value("gl_samples", 0);
  return fragment_error() <= 1e-4 && passed_error() <= 1e-4 && draws_ok && depth_ok && stencil_ok && ldi_ok && relief_ok;
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
  if (!cull.is_null()) j["cull"] = cull;
  if (!particles.is_null()) j["particles"] = particles;
  if (!shadows.is_null()) j["shadows"] = shadows;
  if (!ldi.is_null()) j["ldi"] = ldi;
  if (!relief.is_null()) j["relief"] = relief;
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
  Gpu gpu("gpu", registry, o.config, w, h, [frames] { return frames->next(); }, clear_depth, sink, head, setup,
          o.out ? &*o.out : nullptr);
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
  if (s.stats.contains("gpu.cull")) {
    s.cull = cull_summary(s.stats["gpu.cull"], s.stats["gpu.depth"], o.config.cull, sink.last_frame_cycle(),
                          sink.visible_draws_passed_below_gl);
    const auto& structures = gpu.program().structures;
    const query::Structure* structure = structures.empty() ? nullptr : structures.front().get();
    const long long bytes = structure ? structure->storage_bytes() : 0;
    s.cull["structure_memory_bytes"] = bytes;  // N-buffer levels, tile Hi-Z or pyramid
    s.cull["nbuffer_memory_bytes"] =
        structure && structure->structure_kind() == query::Kind::NBuffer ? nlohmann::ordered_json(bytes) : nullptr;
  }

  if (s.stats.contains("gpu.particles")) {
    std::string capture_mode;
    for (const auto& [k, v] : tr.properties())
      if (k == "particle_mode") capture_mode = v;
    const std::string& mode = o.config.particles.mode == "trace" ? capture_mode : o.config.particles.mode;
    s.particles = particles_summary(s.stats["gpu.particles"], mode, sink.last_frame_cycle());
    s.particles["capture_mode"] = capture_mode;
    const auto& structures = gpu.program().structures;
    s.particles["nbuffer_memory_bytes"] = structures.empty() ? 0 : structures.front()->storage_bytes();
  }

  if (s.stats.contains("gpu.shadows")) {
    s.shadows = shadows_summary(s.stats["gpu.shadows"], sink.last_frame_cycle());
    for (const char* key : {"shadow_mode", "scene", "litmap_size", "seed"})
      for (const auto& [k, v] : tr.properties())
        if (k == key) s.shadows[key] = v;
    long long bytes = 0;
    for (const auto& structure : gpu.program().structures) bytes += structure->storage_bytes();
    s.shadows["nbuffer_memory_bytes"] = bytes;  // both units' levels
    nlohmann::ordered_json per_frame = nlohmann::ordered_json::array();
    for (const auto& pf : sink.shadows_frames_)
      per_frame.push_back({{"frame", pf.frame}, {"fill", pf.fill}, {"reference_fill", pf.reference_fill}, {"culled", pf.culled},
                           {"gl_culled", pf.gl_culled}, {"mask_diff", pf.mask_diff}, {"mask_diff_infinite", pf.mask_diff_infinite},
                           {"cycles", pf.cycles}});
    s.shadows["per_frame"] = per_frame;
  }

  if (s.stats.contains("gpu.ldi")) {
    s.ldi = ldi_summary(s.stats["gpu.ldi"], s.stats.contains("gpu.memory") ? s.stats["gpu.memory"] : nlohmann::ordered_json::object(),
                        sink.last_frame_cycle());
    for (const char* key : {"shape", "seed"})
      for (const auto& [k, v] : tr.properties())
        if (k == key) s.ldi[key] = v;
  }

  if (s.stats.contains("gpu.relief")) {
    s.relief = relief_summary(s.stats["gpu.relief"], s.stats.contains("gpu.memory") ? s.stats["gpu.memory"] : nlohmann::ordered_json::object(),
                              sink.last_frame_cycle());
    for (const char* key : {"relief_field", "relief_field_size", "relief_box_height", "relief_angles"})
      for (const auto& [k, v] : tr.properties())
        if (k == key) s.relief[key] = v;
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

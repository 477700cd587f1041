// The occlusion_culling technique's frame program, the cull stage, and its results; its row of pipeline/sim/programs.h.
#include "pipeline/sim/programs.h"

#include <fmt/format.h>

#include <array>
#include <fstream>

#include "model/common/error.h"
#include "model/cull/unit.h"
#include "pipeline/sim/gpu.h"

namespace nbsim::pipeline {

namespace {

// Occlusion culling (the N-buffer paper, 3.1/4.2): cull.mode picks the query; "trace" replays.
Program build(const ProgramContext& c) {
  Program p;
  c.config.cull.parsed_granularity();  // refuses cull.granularity=primitive with nothing to test against
  if (c.config.cull.parsed_mode() == cull::CullMode::Trace) return p;
  // The mode's query structure: the N-buffer unit, or the Hi-Z baselines.
  if (const std::optional<query::Kind> kind = c.config.cull.structure_kind())
    p.structures.push_back(c.structure(*kind == query::Kind::NBuffer ? "nbuffer" : "hiz", *kind, c.view.op));
  // The cull stage's view of the trace: the viewport and depth convention, the projection's near
  // plane and clip control, the bounds tests' margin, and the depth unit's interpolation.
  cull::CullSetup setup;
  setup.width_px = c.view.width_px;
  setup.height_px = c.view.height_px;
  setup.op = c.view.op;
  setup.depth_func = c.view.depth_func;
  setup.near_m = c.header.near_m;
  setup.nearest_margin = c.header.nearest_margin;
  setup.zero_to_one = c.header.clip_control == trace::ClipControl::ZeroToOne;
  setup.scene = c.view.scene;
  setup.fused_interpolation = c.config.depth.fused_interpolation;
  auto unit = std::make_unique<cull::CullUnit>("cull", c.registry, c.config.cull, setup, c.depth_buffer,
                                               p.structures.empty() ? nullptr : p.structures.front().get());
  if (c.out) {  // every bounds test with its decision, cost and ground truth
    auto log = std::make_unique<std::ofstream>(*c.out / "culls.csv");
    if (!*log) throw InputError(fmt::format("cannot write into '{}'", c.out->string()));
    unit->set_test_log(log.get());
    p.logs.push_back(std::move(log));
  }
  p.frames = unit.get();
  p.depth_listener = unit.get();
  if (unit->granularity() == cull::Granularity::Primitive) p.primitive_tester = unit.get();
  p.unit = std::move(unit);
  return p;
}

// The cull stage's per-frame values (run.json "frames"): differences of its statistics between two
// frame ends, which are exact because the next frame's tests wait for the frame to leave the
// pipeline (model/cull/unit.h).
constexpr std::array<const char*, 11> kCullFrameCounts = {
    "bounds_tests",    "candidates",        "culled",            "candidates_not_visible",     "false_culls",
    "undrawable",      "primitive_tests",   "primitives_culled", "primitive_lookups",          "primitive_fragments_culled",
    "primitive_false_culls"};

void frame_values(const nlohmann::ordered_json& now, const nlohmann::ordered_json& last, nlohmann::ordered_json& pf) {
  const auto delta = [&](const char* name) { return stat(now, name) - stat(last, name); };
  const std::uint64_t depth_tests = pf.value("depth_tests", std::uint64_t{0});
  pf["query_depth_tests"] = delta("query_depth_tests");
  pf["update_texels"] = delta("update_texels");
  pf["total_depth_tests"] = delta("query_depth_tests") + delta("update_texels") + (depth_tests - delta("box_depth_tests"));
  for (const char* name : kCullFrameCounts) pf[name] = delta(name);
}

// The cull stage's run totals (summary "cull", the columns of Table 2 and of explore's results),
// derived from its statistics and the depth unit's when the run is done.
nlohmann::ordered_json totals(const nlohmann::ordered_json& cull, const nlohmann::ordered_json& depth,
                              const cull::CullUnitConfig& config, std::uint64_t cycles, std::uint64_t visible_draws_passed_below_gl) {
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

// The summary: the totals and the query structure's storage (N-buffer levels, tile Hi-Z or pyramid).
nlohmann::ordered_json summary(const SummaryInputs& in) {
  const nlohmann::ordered_json depth = in.stats.contains("gpu.depth") ? in.stats["gpu.depth"] : nlohmann::ordered_json::object();
  nlohmann::ordered_json j = totals(in.group, depth, in.config.cull, in.cycles, in.visible_draws_passed_below_gl);
  const query::Structure* structure = in.program.structures.empty() ? nullptr : in.program.structures.front().get();
  const long long bytes = structure ? structure->storage_bytes() : 0;
  j["structure_memory_bytes"] = bytes;
  j["nbuffer_memory_bytes"] = structure && structure->structure_kind() == query::Kind::NBuffer ? nlohmann::ordered_json(bytes) : nullptr;
  return j;
}

}  // namespace

ProgramRow occlusion_program() {
  return {"occlusion_culling",
          "occlusion culling of a scene's objects (cull.mode: trace replays the recorded draws; none, oq, oq_hier, nb, "
          "nb_hier, hiz_tile, hiz_pyramid cull every candidate again)",
          build,
          {"gpu.cull", "cull", frame_values, {}, summary},
          {},  // its config group is the cull unit's ("cull."), which GpuConfig holds itself
          {{"nbuffer", InstanceKind::NBuffer, "the N-buffer unit (cull.mode nb, nb_hier)"},
           {"hiz", InstanceKind::HiZ, "the Hi-Z baselines (cull.mode hiz_tile, hiz_pyramid)"}},
          true};
}

}  // namespace nbsim::pipeline

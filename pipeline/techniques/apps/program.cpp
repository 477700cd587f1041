// The apps technique's frame program and its results; its row of pipeline/sim/programs.h.
#include "pipeline/sim/programs.h"

#include <fmt/format.h>

#include <array>
#include <fstream>
#include <string>

#include "model/apps/unit.h"
#include "model/common/error.h"
#include "pipeline/sim/gpu.h"

namespace nbsim::pipeline {

namespace {

// A recorded program's frames: every draw replayed or flagged, compared with GL's samples passed.
// cull.mode culls its draw calls (model/apps/replay.h): oq at full resolution, nb and the hiz modes
// with the "nbuffer" or "hiz" instance; trace and none replay every draw. The hierarchical modes
// need a BVH over objects, which a program's draw calls do not have.
Program build(const ProgramContext& c) {
  const cull::CullMode mode = c.config.cull.parsed_mode();
  const cull::Granularity granularity = c.config.cull.parsed_granularity();
  if (cull::hierarchical(mode))
    throw InputError(fmt::format("cull.mode={} traverses a scene's BVH, and an apps trace's objects are its draw calls, which have none "
                                 "(use oq, nb, hiz_tile or hiz_pyramid)",
                                 c.config.cull.mode));
  Program p;
  apps::AppsCull cull;
  if (mode != cull::CullMode::Trace && mode != cull::CullMode::None) {
    cull.on = true;
    if (const std::optional<query::Kind> kind = c.config.cull.structure_kind()) {
      p.structures.push_back(c.structure(*kind == query::Kind::NBuffer ? "nbuffer" : "hiz", *kind, c.view.op));
      cull.structure = p.structures.back().get();
    }
    cull.width = c.view.width_px, cull.height = c.view.height_px, cull.op = c.view.op;
    cull.primitives = granularity == cull::Granularity::Primitive;
    cull.fused_interpolation = c.config.depth.fused_interpolation;
  }
  std::ostream* log = nullptr;
  if (c.out) {
    auto file = std::make_unique<std::ofstream>(*c.out / "app_draws.csv");
    if (!*file) throw InputError(fmt::format("cannot write into '{}'", c.out->string()));
    log = file.get();
    p.logs.push_back(std::move(file));
  }
  auto unit = std::make_unique<apps::AppsUnit>("apps", c.registry, c.config.group<apps::AppsUnitConfig>("apps"), cull, log);
  p.frames = unit.get();
  p.depth_listener = unit.get();
  p.unit = std::move(unit);
  return p;
}

constexpr std::array<const char*, 18> kFrameCounts = {"draws",       "replayed",      "compared",    "matched",     "mismatched",
                                                      "after_stale", "depth_changes", "depth_tests", "samples",     "gl_samples",
                                                      "depth_mismatches", "cycles", "tested", "culled", "false_culls",
                                                      "query_depth_tests", "update_texels", "gl_hidden"};

void frame_values(const nlohmann::ordered_json& now, const nlohmann::ordered_json& last, nlohmann::ordered_json& pf) {
  nlohmann::ordered_json v;
  for (const char* name : kFrameCounts) v[name] = stat(now, name) - stat(last, name);
  pf["apps"] = v;
}

nlohmann::ordered_json summary(const SummaryInputs& in) {
  const nlohmann::ordered_json& g = in.group;
  nlohmann::ordered_json j;
  for (const char* name : {"frames", "draws", "replayed", "compared", "matched", "mismatched", "after_stale", "depth_changes", "clears",
                           "triangles", "fragments", "depth_tests", "samples", "gl_samples", "gl_samples_compared", "frames_depth_compared",
                           "depth_pixels", "depth_mismatches", "unhandled_frames", "may_discard_replayed", "may_discard_equal", "cycles"})
    j[name] = stat(g, name);
  const double draws = static_cast<double>(stat(g, "draws"));
  nlohmann::ordered_json flagged = nlohmann::ordered_json::object();
  std::uint64_t flagged_total = 0;
  for (int r = 1; r < apps::kReasons; ++r) {
    const std::string name(apps::to_string(static_cast<apps::Reason>(r)));
    const std::uint64_t v = stat(g, ("flagged_" + name).c_str());
    flagged_total += v;
    if (v) flagged[name] = v;
  }
  j["flagged"] = flagged_total;
  j["flagged_by_reason"] = flagged;
  j["flagged_share"] = draws > 0 ? nlohmann::ordered_json(static_cast<double>(flagged_total) / draws) : nlohmann::ordered_json(nullptr);
  const double compared = static_cast<double>(stat(g, "compared"));
  j["match_rate"] = compared > 0 ? nlohmann::ordered_json(static_cast<double>(stat(g, "matched")) / compared) : nlohmann::ordered_json(nullptr);
  j["mismatch_rate"] = compared > 0 ? static_cast<double>(stat(g, "mismatched")) / compared : 0.0;
  for (const char* key : {"apitrace", "app_frames"}) copy_property(in.header, key, j);
  // Culling the draw calls (cull.mode): Table 2's columns on the program's frames. Depth tests:
  // the queries' (texels read or boxes' fragments), the drawn draws' (the replayed ones; culled
  // draws cost none) and the structure's upkeep (texels recomputed).
  nlohmann::ordered_json c;
  c["mode"] = in.config.cull.mode;
  c["granularity"] = in.config.cull.granularity;
  for (const char* name : {"gl_hidden", "tested", "tested_hidden", "culled", "false_culls", "queries", "query_depth_tests", "update_texels",
                           "clear_texels", "primitive_tests", "primitives_culled", "primitive_lookups"})
    c[name] = stat(g, name);
  nlohmann::ordered_json untested = nlohmann::ordered_json::object();
  for (int u = 1; u < apps::kUntested; ++u) {
    const std::string name(apps::to_string(static_cast<apps::Untested>(u)));
    if (const std::uint64_t v = stat(g, ("untested_" + name).c_str())) untested[name] = v;
  }
  c["untested_by_reason"] = untested;
  const std::uint64_t total = stat(g, "query_depth_tests") + stat(g, "update_texels") + stat(g, "depth_tests");
  c["drawn_depth_tests"] = stat(g, "depth_tests");
  c["total_depth_tests"] = total;
  const std::uint64_t frames = stat(g, "frames");
  const auto per_frame = [frames](std::uint64_t v) { return frames ? static_cast<double>(v) / static_cast<double>(frames) : 0.0; };
  c["frames"] = frames;
  c["draws_per_frame"] = per_frame(stat(g, "draws"));
  c["culled_per_frame"] = per_frame(stat(g, "culled"));
  c["query_depth_tests_per_frame"] = per_frame(stat(g, "query_depth_tests"));
  c["update_texels_per_frame"] = per_frame(stat(g, "update_texels"));
  c["drawn_depth_tests_per_frame"] = per_frame(stat(g, "depth_tests"));
  c["total_depth_tests_per_frame"] = per_frame(total);
  c["cycles_per_frame"] = per_frame(in.cycles);
  const std::uint64_t hidden = stat(g, "tested_hidden");
  c["culling_efficiency"] = hidden ? nlohmann::ordered_json(static_cast<double>(stat(g, "culled")) / static_cast<double>(hidden)) : nlohmann::ordered_json(nullptr);
  c["run_cycles"] = in.cycles;
  const query::Structure* structure = in.program.structures.empty() ? nullptr : in.program.structures.front().get();
  c["structure_memory_bytes"] = structure ? structure->storage_bytes() : 0;
  j["cull"] = c;
  return j;
}

// Every compared draw's samples passed and every compared final depth equal GL's, and no draw GL
// drew samples of was culled.
bool exact(const nlohmann::ordered_json& s) {
  const std::uint64_t false_culls = s.contains("cull") ? s["cull"].value("false_culls", std::uint64_t{0}) : 0;
  return s.value("mismatched", 0) == 0 && s.value("depth_mismatches", 0) == 0 && false_culls == 0;
}

std::string describe(const nlohmann::ordered_json& s) {
  std::string reasons;
  for (const auto& [name, v] : s["flagged_by_reason"].items()) reasons += fmt::format("{}{} {}", reasons.empty() ? "" : ", ", name, v.get<std::uint64_t>());
  return fmt::format("  apps draws {}: replayed {} (compared {}: matched {}, differing {}; after a stale change {}; may discard, "
                     "checked and equal {} of {}), flagged {}{}\n"
                     "  apps final depth: {} frames compared, {} pixels differing\n",
                     s["draws"].get<std::uint64_t>(), s["replayed"].get<std::uint64_t>(), s["compared"].get<std::uint64_t>(),
                     s["matched"].get<std::uint64_t>(), s["mismatched"].get<std::uint64_t>(), s["after_stale"].get<std::uint64_t>(),
                     s["may_discard_equal"].get<std::uint64_t>(), s["may_discard_replayed"].get<std::uint64_t>(), s["flagged"].get<std::uint64_t>(), reasons.empty() ? "" : " (" + reasons + ")",
                     s["frames_depth_compared"].get<std::uint64_t>(), s["depth_mismatches"].get<std::uint64_t>()) +
         (s.contains("cull") && s["cull"]["mode"] != "trace" && s["cull"]["mode"] != "none"
              ? fmt::format("  apps culling ({}): {} draws tested ({} hidden in GL), {} culled, {} false culls; depth tests: queries {}, "
                            "upkeep {}, total {}\n",
                            s["cull"]["mode"].get<std::string>(), s["cull"]["tested"].get<std::uint64_t>(),
                            s["cull"]["tested_hidden"].get<std::uint64_t>(), s["cull"]["culled"].get<std::uint64_t>(),
                            s["cull"]["false_culls"].get<std::uint64_t>(), s["cull"]["query_depth_tests"].get<std::uint64_t>(),
                            s["cull"]["update_texels"].get<std::uint64_t>(), s["cull"]["total_depth_tests"].get<std::uint64_t>())
              : std::string());
}

}  // namespace

ProgramRow apps_program() {
  return {"apps",
          "a recorded program's frames (nbsim capture apitrace): every draw call replayed through the raster path into its render "
          "target and its samples passed compared with GL's, or flagged by the reason the model cannot redo it",
          build,
          {"gpu.apps", "", frame_values, {}, summary, exact, describe},
          config_group<apps::AppsUnitConfig>("apps"),
          {{"nbuffer", InstanceKind::NBuffer, "cull.mode=nb: the N-buffer unit the draw calls are tested against"},
           {"hiz", InstanceKind::HiZ, "cull.mode=hiz_tile, hiz_pyramid: the Hi-Z the draw calls are tested against"}},
          true};
}

}  // namespace nbsim::pipeline

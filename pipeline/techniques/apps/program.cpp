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
Program build(const ProgramContext& c) {
  c.require_no_cull_mode("an apps trace replays a program's own draws (culling its draw calls is not built yet)");
  Program p;
  std::ostream* log = nullptr;
  if (c.out) {
    auto file = std::make_unique<std::ofstream>(*c.out / "app_draws.csv");
    if (!*file) throw InputError(fmt::format("cannot write into '{}'", c.out->string()));
    log = file.get();
    p.logs.push_back(std::move(file));
  }
  auto unit = std::make_unique<apps::AppsUnit>("apps", c.registry, c.config.group<apps::AppsUnitConfig>("apps"), log);
  p.frames = unit.get();
  p.depth_listener = unit.get();
  p.unit = std::move(unit);
  return p;
}

constexpr std::array<const char*, 12> kFrameCounts = {"draws",   "replayed",  "compared",          "matched",        "mismatched",
                                                      "after_stale", "depth_changes", "depth_tests", "samples", "gl_samples",
                                                      "depth_mismatches", "cycles"};

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
  return j;
}

// Every compared draw's samples passed and every compared final depth equal GL's.
bool exact(const nlohmann::ordered_json& s) { return s.value("mismatched", 0) == 0 && s.value("depth_mismatches", 0) == 0; }

std::string describe(const nlohmann::ordered_json& s) {
  std::string reasons;
  for (const auto& [name, v] : s["flagged_by_reason"].items()) reasons += fmt::format("{}{} {}", reasons.empty() ? "" : ", ", name, v.get<std::uint64_t>());
  return fmt::format("  apps draws {}: replayed {} (compared {}: matched {}, differing {}; after a stale change {}; may discard, "
                     "checked and equal {} of {}), flagged {}{}\n"
                     "  apps final depth: {} frames compared, {} pixels differing\n",
                     s["draws"].get<std::uint64_t>(), s["replayed"].get<std::uint64_t>(), s["compared"].get<std::uint64_t>(),
                     s["matched"].get<std::uint64_t>(), s["mismatched"].get<std::uint64_t>(), s["after_stale"].get<std::uint64_t>(),
                     s["may_discard_equal"].get<std::uint64_t>(), s["may_discard_replayed"].get<std::uint64_t>(), s["flagged"].get<std::uint64_t>(), reasons.empty() ? "" : " (" + reasons + ")",
                     s["frames_depth_compared"].get<std::uint64_t>(), s["depth_mismatches"].get<std::uint64_t>());
}

}  // namespace

ProgramRow apps_program() {
  return {"apps",
          "a recorded program's frames (nbsim capture apitrace): every draw call replayed through the raster path into its render "
          "target and its samples passed compared with GL's, or flagged by the reason the model cannot redo it",
          build,
          {"gpu.apps", "", frame_values, {}, summary, exact, describe},
          config_group<apps::AppsUnitConfig>("apps"),
          {},
          false};
}

}  // namespace nbsim::pipeline

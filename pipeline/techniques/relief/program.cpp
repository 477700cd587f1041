// The relief technique's frame program and its results (per-frame values, summary); its row of pipeline/sim/programs.h.
#include "pipeline/sim/programs.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <string>

#include "model/relief/unit.h"
#include "model/relief/walk.h"
#include "pipeline/sim/gpu.h"

namespace nbsim::pipeline {

namespace {

// Relief textures (Baboud & Decoret) and the N-buffer walk: every relief_box draw rasterized with the
// early depth test, each fragment's walk run with the draw's method and compared with GL's, and
// scored against the exact reference.
Program build(const ProgramContext& c) {
  c.require_no_cull_mode("a relief trace walks its own rays");
  const double box_height = c.header.real("relief_box_height");  // above 0: checked when the trace was opened
  // What the boxes write (a trace from before the key: its default, nothing); a valid choice: checked when opened.
  const std::string* depth_key = c.header.property("relief_box_depth");
  const relief::BoxDepth box_depth = depth_key ? relief::parse_box_depth(*depth_key).value_or(relief::BoxDepth::None) : relief::BoxDepth::None;
  Program p;
  // The N-buffer walk covers as the capture did (its GL walks are compared one by one).
  auto unit = std::make_unique<relief::ReliefUnit>("relief", c.registry, c.config.group<relief::ReliefUnitConfig>("relief"), c.memory, c.view.width_px, c.view.height_px,
                                                   box_height, c.config.depth.fused_interpolation, c.capture_covering(), box_depth);
  p.frames = unit.get();
  p.unit = std::move(unit);
  return p;
}

// The relief program's counters in run.json's per-frame values, per method (differences at frame ends).
constexpr std::array<const char*, 13> kReliefFrameCounts = {"fragments", "gl_fragments", "pixel_mismatches", "walk_mismatches",
                                                             "lookups", "steps", "errors", "reference_hits", "cycles", "rasterized",
                                                             "depth_written", "depth_mismatches", "scene_hidden"};

// The counts a replay with relief.score false leaves at 0: null in its results, not a perfect score.
constexpr std::array<const char*, 5> kScoreCounts = {"reference_hits", "wrong_hit", "wrong_miss", "far_hit", "errors"};

void frame_values(const nlohmann::ordered_json& now, const nlohmann::ordered_json& last, nlohmann::ordered_json& pf) {
  const bool unscored = stat(now, "unscored_draws") != stat(last, "unscored_draws");
  nlohmann::ordered_json methods = nlohmann::ordered_json::object();
  for (relief::Method m : relief::kAllMethods) {
    const std::string prefix = std::string(relief::to_string(m)) + "_";
    if (stat(now, (prefix + "draws").c_str()) == stat(last, (prefix + "draws").c_str())) continue;
    nlohmann::ordered_json v;
    for (const char* name : kReliefFrameCounts) v[name] = stat(now, (prefix + name).c_str()) - stat(last, (prefix + name).c_str());
    if (unscored)
      for (const char* name : kScoreCounts)
        if (v.contains(name)) v[name] = nullptr;
    v["storage_bytes"] = stat(now, (prefix + "storage_bytes").c_str());  // the largest field's so far, not a difference
    methods[std::string(relief::to_string(m))] = v;
  }
  pf["relief"] = methods;
}

// The relief program's run totals (summary "relief"), from its statistics: per method its counts,
// lookups and steps per fragment, cycles, and hit error against the exact reference.
nlohmann::ordered_json totals(const nlohmann::ordered_json& p, const nlohmann::ordered_json& memory, std::uint64_t cycles) {
  nlohmann::ordered_json j;
  for (const char* name : {"frames", "scene_draws", "scene_depth_tests", "scene_mismatches", "box_draws", "cache_hits", "cache_misses", "memory_bytes",
                           "memory_stall_cycles", "cycles"})
    j[name] = stat(p, name);
  j["cycles_total"] = cycles;
  // The safety radii the robust searches read (the trace's: strict, or the paper's with its epsilon).
  const double radius_texels = static_cast<double>(stat(p, "radius_texels"));
  j["radius_mean"] = radius_texels > 0 ? nlohmann::ordered_json(static_cast<double>(stat(p, "radius_sum")) / radius_texels) : nlohmann::ordered_json(nullptr);
  j["radius_zero_fraction"] =
      radius_texels > 0 ? nlohmann::ordered_json(static_cast<double>(stat(p, "radius_zero")) / radius_texels) : nlohmann::ordered_json(nullptr);
  j["channel_bytes"] = stat(memory, "bytes_relief");
  const bool unscored = stat(p, "unscored_draws") > 0;  // relief.score false: no hit errors
  nlohmann::ordered_json methods = nlohmann::ordered_json::object();
  for (relief::Method m : relief::kAllMethods) {
    const std::string prefix = std::string(relief::to_string(m)) + "_";
    const auto v = [&](const char* name) { return stat(p, (prefix + name).c_str()); };
    if (v("draws") == 0) continue;
    nlohmann::ordered_json e;
    for (const char* name : {"draws", "rasterized", "fragments", "gl_fragments", "samples", "gl_samples", "pixel_mismatches", "walk_mismatches", "lookups",
                             "gl_lookups", "steps", "bisections", "hits", "capped", "reference_hits", "wrong_hit", "wrong_miss",
                             "far_hit", "errors", "cycles", "cache_misses", "storage_bytes", "depth_written", "depth_mismatches",
                             "scene_after_draws", "scene_after_samples", "scene_hidden"})
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
    if (m == relief::Method::NBuffer) {  // the levels the walks read, on demand, against a full build a frame
      for (const char* name : {"levels_eager_texels", "levels_on_demand_texels", "levels_on_demand_mismatches"}) e[name] = v(name);
      e["levels_on_demand_share"] = v("levels_eager_texels") ? nlohmann::ordered_json(static_cast<double>(v("levels_on_demand_texels")) /
                                                                                        static_cast<double>(v("levels_eager_texels")))
                                                             : nlohmann::ordered_json(nullptr);
    }
    if (unscored) {
      for (const char* name : kScoreCounts) e[name] = nullptr;
      e["error_rate"] = nullptr;
      e["mean_hit_distance"] = nullptr;
    }
    e["cycles_per_frame"] = stat(p, "frames") ? nlohmann::ordered_json(static_cast<double>(v("cycles")) / static_cast<double>(stat(p, "frames")))
                                              : nlohmann::ordered_json(nullptr);
    methods[std::string(relief::to_string(m))] = e;
  }
  j["methods"] = methods;
  // Totals over the methods (the results row's metrics).
  std::uint64_t fragments = 0, lookups = 0, errors = 0, walk_mismatches = 0, pixel_mismatches = 0, depth_mismatches = 0;
  for (const auto& [name, e] : methods.items()) {
    fragments += e["fragments"].get<std::uint64_t>(), lookups += e["lookups"].get<std::uint64_t>();
    errors += e["errors"].is_number() ? e["errors"].get<std::uint64_t>() : 0, walk_mismatches += e["walk_mismatches"].get<std::uint64_t>();
    pixel_mismatches += e["pixel_mismatches"].get<std::uint64_t>(), depth_mismatches += e["depth_mismatches"].get<std::uint64_t>();
  }
  j["fragments"] = fragments;
  j["lookups"] = lookups;
  j["lookups_per_fragment"] = fragments ? nlohmann::ordered_json(static_cast<double>(lookups) / static_cast<double>(fragments)) : nlohmann::ordered_json(nullptr);
  j["errors"] = unscored ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(errors);
  j["error_rate"] = unscored ? nlohmann::ordered_json(nullptr) : fragments ? nlohmann::ordered_json(static_cast<double>(errors) / static_cast<double>(fragments)) : nlohmann::ordered_json(nullptr);
  j["walk_mismatches"] = walk_mismatches;
  j["pixel_mismatches"] = pixel_mismatches;
  j["depth_mismatches"] = depth_mismatches;
  return j;
}

nlohmann::ordered_json summary(const SummaryInputs& in) {
  nlohmann::ordered_json j = totals(in.group, in.stats.contains("gpu.memory") ? in.stats["gpu.memory"] : nlohmann::ordered_json::object(), in.cycles);
  for (const char* key : {"relief_field", "relief_field_size", "relief_box_height", "relief_angles", "relief_radius", "relief_radius_epsilon",
                          "relief_radius_combine", "relief_box_depth", "relief_placement"})
    copy_property(in.header, key, j);
  // Storage a texel of the heightfield: what each method's textures cost (4 bytes a value).
  const std::string* size = in.header.property("relief_field_size");
  const double n = size ? std::strtod(size->c_str(), nullptr) : 0.0;
  for (auto& [name, e] : j["methods"].items())
    e["storage_bytes_per_texel"] = n > 0 ? nlohmann::ordered_json(e["storage_bytes"].get<double>() / (n * n)) : nlohmann::ordered_json(nullptr);
  return j;
}

// Every method's fragments, samples, walks and depth equal GL's, and every scene draw's samples.
bool exact(const nlohmann::ordered_json& s) {
  if (s.value("scene_mismatches", 0) != 0) return false;
  for (const auto& [name, m] : s["methods"].items())
    if (m.value("pixel_mismatches", 0) != 0 || m.value("walk_mismatches", 0) != 0 || m.value("levels_on_demand_mismatches", 0) != 0 || m.value("fragments", 0) != m.value("gl_fragments", 0) ||
        m.value("samples", 0) != m.value("gl_samples", 0) || m.value("depth_mismatches", 0) != 0)
      return false;
  return true;
}

std::string describe(const nlohmann::ordered_json& s) {
  std::string out;
  for (const auto& [name, m] : s["methods"].items())
    out += fmt::format("  relief {:<13} fragments model {} GL {}, hits model {} GL {}, walks differing {}, pixels differing {}, "
                       "{:.2f} lookups/fragment, hit errors {}\n",
                       name, m["fragments"].get<std::uint64_t>(), m["gl_fragments"].get<std::uint64_t>(), m["samples"].get<std::uint64_t>(),
                       m["gl_samples"].get<std::uint64_t>(), m["walk_mismatches"].get<std::uint64_t>(),
                       m["pixel_mismatches"].get<std::uint64_t>(), m["lookups_per_fragment"].is_number() ? m["lookups_per_fragment"].get<double>() : 0.0,
                       m["errors"].is_number() ? fmt::format("{}", m["errors"].get<std::uint64_t>()) : std::string("not scored"));
  return out;
}

}  // namespace

ProgramRow relief_program() {
  return {"relief",
          "relief textures: every relief_box draw rasterized with the early depth test, each fragment's ray walk (binary, "
          "exact, robust, robust_clamp or nbuffer, as the draw's RLFF says) run through the ray-walk unit and its texel cache, "
          "compared with GL's per fragment and scored against the exact reference",
          build,
          {"gpu.relief", "", frame_values, {}, summary, exact, describe},
          config_group<relief::ReliefUnitConfig>("relief"),
          {},
          false};
}

}  // namespace nbsim::pipeline

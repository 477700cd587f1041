// The ldi technique's frame program and its results (per-frame values, summary); its row of pipeline/sim/programs.h.
#include "pipeline/sim/programs.h"

#include <fmt/format.h>

#include <array>
#include <string>

#include "model/ldi/unit.h"
#include "pipeline/sim/gpu.h"

namespace nbsim::pipeline {

namespace {

// Layered depth images (Trapp & Doellner): the peel replayed at the LDI's size (LDIL) with its own
// depth buffer and the strict compare against the previous layer, the model's LDI cropped and
// compressed and compared with GL's, and the parity test at GL's test points (LDIT).
Program build(const ProgramContext& c) {
  c.require_no_cull_mode("an ldi trace peels and tests its own shape");
  Program p;
  auto unit = std::make_unique<ldi::LdiUnit>("ldi", c.registry, c.config.group<ldi::LdiUnitConfig>("ldi"), c.memory, c.config.depth.fused_interpolation);
  p.frames = unit.get();
  p.unit = std::move(unit);
  return p;
}

// The ldi program's counters in run.json's per-frame values (differences at frame ends).
constexpr std::array<const char*, 33> kLdiFrameCounts = {
    "peel_passes", "peel_fragments", "gl_peel_fragments", "peel_samples", "gl_peel_samples", "peel_pass_mismatches", "layers",
    "gl_layers", "layer_texel_mismatches", "crop_mismatch", "compressed_mismatches", "test_points", "parity_mismatches_layers",
    "parity_mismatches_ranges", "misclassified_layers", "misclassified_ranges", "parity_mismatches_all", "fetches_all",
    // Clipping and lens frames (model/ldi/clip.h): per frame, the misclassification against the exact reference among them.
    "clip_draws", "clip_fragments", "clip_discarded", "clip_depth_tests", "clip_samples", "clip_fetches", "clip_fetches_layers",
    "clip_fetches_all", "clip_fetches_ranges", "clip_classified", "clip_misclassified", "clip_draw_mismatches", "clip_depth_mismatches",
    "clip_cycles", "clip_bytes"};

void frame_values(const nlohmann::ordered_json& now, const nlohmann::ordered_json& last, nlohmann::ordered_json& pf) {
  for (const char* name : kLdiFrameCounts) pf[name] = stat(now, name) - stat(last, name);
}

// The ldi program's run totals (summary "ldi"), from its statistics; the per-frame values are
// run.json's frames. Rates are null when nothing was classified; cycles are the program's own
// (peel and parity tests), cycles_total the run's.
nlohmann::ordered_json totals(const nlohmann::ordered_json& p, const nlohmann::ordered_json& memory, std::uint64_t cycles) {
  nlohmann::ordered_json j;
  for (const char* name : {"frames", "peel_passes", "peel_fragments", "gl_peel_fragments", "peel_samples", "gl_peel_samples",
                           "peel_reads", "peel_discarded", "peel_pass_mismatches", "layers", "gl_layers", "layer_count_mismatches",
                           "layer_texel_mismatches", "crop_mismatch", "compressed_mismatches", "m_crop", "m_comp", "test_points",
                           "parity_mismatches_layers", "parity_mismatches_ranges", "fetch_mismatches_layers",
                           "fetch_mismatches_ranges", "fetches_layers", "fetches_ranges", "gl_fetches_layers", "gl_fetches_ranges",
                           "misclassified_layers", "misclassified_ranges", "classified_points", "near_surface_points", "all_points",
                           "parity_mismatches_all", "fetch_mismatches_all", "fetches_all", "gl_fetches_all", "misclassified_all"})
    j[name] = stat(p, name);
  // Fetches a test point of each reader: the early exit's, the compressed one's and the paper's (every layer).
  const auto per_point = [](std::uint64_t fetches, std::uint64_t points) {
    return points ? nlohmann::ordered_json(static_cast<double>(fetches) / static_cast<double>(points)) : nlohmann::ordered_json(nullptr);
  };
  j["fetches_per_point_layers"] = per_point(stat(p, "fetches_layers"), stat(p, "test_points"));
  j["fetches_per_point_ranges"] = per_point(stat(p, "fetches_ranges"), stat(p, "test_points"));
  j["fetches_per_point_all"] = per_point(stat(p, "fetches_all"), stat(p, "all_points"));
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
  // Clipping and lens frames.
  for (const char* name : {"clip_frames", "clip_draws", "clip_fragments", "gl_clip_fragments", "clip_samples", "gl_clip_samples",
                           "clip_discarded", "gl_clip_discarded", "clip_fetches", "gl_clip_fetches", "clip_depth_tests", "clip_volume_tests",
                           "clip_draw_mismatches", "clip_decision_mismatches", "clip_depth_mismatches", "clip_volumes",
                           "clip_volume_mismatches", "clip_classified", "clip_near_surface", "clip_misclassified", "clip_fetches_layers",
                           "clip_fetches_all", "clip_fetches_ranges", "clip_cache_hits", "clip_cache_misses", "clip_cycles", "clip_bytes"})
    j[name] = stat(p, name);
  const std::uint64_t clip_tests = stat(p, "clip_fragments");
  const auto per_test = [clip_tests](std::uint64_t v) {
    return clip_tests ? nlohmann::ordered_json(static_cast<double>(v) / static_cast<double>(clip_tests)) : nlohmann::ordered_json(nullptr);
  };
  j["clip_discard_rate"] = per_test(stat(p, "clip_discarded"));
  j["clip_fetches_per_test_layers"] = per_test(stat(p, "clip_fetches_layers"));
  j["clip_fetches_per_test_all"] = per_test(stat(p, "clip_fetches_all"));
  j["clip_fetches_per_test_ranges"] = per_test(stat(p, "clip_fetches_ranges"));
  const std::uint64_t clip_classified = stat(p, "clip_classified");
  j["clip_misclassification_rate"] = clip_classified ? nlohmann::ordered_json(static_cast<double>(stat(p, "clip_misclassified")) /
                                                                              static_cast<double>(clip_classified))
                                                     : nlohmann::ordered_json(nullptr);
  const std::uint64_t clip_frames = stat(p, "clip_frames");
  j["clip_cycles_per_frame"] = clip_frames ? nlohmann::ordered_json(static_cast<double>(stat(p, "clip_cycles")) / static_cast<double>(clip_frames))
                                           : nlohmann::ordered_json(nullptr);
  j["peel_cycles"] = stat(p, "peel_cycles");
  j["vpt_cycles"] = stat(p, "vpt_cycles");
  j["cycles"] = stat(p, "peel_cycles") + stat(p, "vpt_cycles") + stat(p, "clip_cycles");
  j["cycles_total"] = cycles;
  j["memory_bytes"] = stat(memory, "bytes_ldi");
  j["peel_bytes"] = stat(p, "peel_bytes");
  j["vpt_bytes"] = stat(p, "vpt_bytes");
  return j;
}

nlohmann::ordered_json summary(const SummaryInputs& in) {
  nlohmann::ordered_json j = totals(in.group, in.stats.contains("gpu.memory") ? in.stats["gpu.memory"] : nlohmann::ordered_json::object(), in.cycles);
  for (const char* key : {"shape", "ldi_seed", "ldi_application", "ldi_reader", "ldi_volumes"}) copy_property(in.header, key, j);
  return j;
}

// The peel is the program's own replay of GL's peel draws: its fragments and samples against GL's
// counters under the draws' thresholds.
bool exact(const nlohmann::ordered_json& s) {
  const auto counter = [&s](const char* name) { return s.value(name, std::uint64_t{0}); };
  return relative_error(counter("peel_fragments"), counter("gl_peel_fragments")) <= kCounterErrorLimit &&
         relative_error(counter("peel_samples"), counter("gl_peel_samples")) <= kCounterErrorLimit &&
         relative_error(counter("clip_fragments"), counter("gl_clip_fragments")) <= kCounterErrorLimit &&
         relative_error(counter("clip_samples"), counter("gl_clip_samples")) <= kCounterErrorLimit &&
         counter("clip_draw_mismatches") == 0 && counter("clip_depth_mismatches") == 0 && counter("clip_volume_mismatches") == 0;
}

std::string describe(const nlohmann::ordered_json& l) {
  std::string s;
  if (l.value("clip_frames", std::uint64_t{0}) > 0) {
    const auto u = [&l](const char* name) { return l[name].get<std::uint64_t>(); };
    s += fmt::format("  ldi volume test    {} draws, fragments model {} GL {}, discarded model {} GL {}, samples model {} GL {}\n", u("clip_draws"),
                     u("clip_fragments"), u("gl_clip_fragments"), u("clip_discarded"), u("gl_clip_discarded"), u("clip_samples"),
                     u("gl_clip_samples"));
    s += fmt::format("  ldi volume test    {} draws and {} final depth buffers unlike GL's; {} of {} classified fragments misclassified "
                     "({} near a surface)\n",
                     u("clip_draw_mismatches"), u("clip_depth_mismatches"), u("clip_misclassified"), u("clip_classified"), u("clip_near_surface"));
    s += fmt::format("  ldi readers        fetches a test: layers {:.3f}, all (the paper's) {:.3f}, ranges {:.3f}; {:.0f} cycles a frame\n",
                     l["clip_fetches_per_test_layers"].get<double>(), l["clip_fetches_per_test_all"].get<double>(),
                     l["clip_fetches_per_test_ranges"].get<double>(), l["clip_cycles_per_frame"].get<double>());
    return s;
  }
  s += fmt::format("  ldi peel           {} passes, fragments model {} GL {}, samples model {} GL {}, {} passes differ\n",
                   l["peel_passes"].get<std::uint64_t>(), l["peel_fragments"].get<std::uint64_t>(),
                   l["gl_peel_fragments"].get<std::uint64_t>(), l["peel_samples"].get<std::uint64_t>(),
                   l["gl_peel_samples"].get<std::uint64_t>(), l["peel_pass_mismatches"].get<std::uint64_t>());
  s += fmt::format("  ldi layers         {} texel values differ, {} crop frames differ, {} compressed values differ\n",
                   l["layer_texel_mismatches"].get<std::uint64_t>(), l["crop_mismatch"].get<std::uint64_t>(),
                   l["compressed_mismatches"].get<std::uint64_t>());
  s += fmt::format("  ldi parity tests   {} points: answers differ {} / {}, misclassified {} / {} of {} (layers / ranges)\n",
                   l["test_points"].get<std::uint64_t>(), l["parity_mismatches_layers"].get<std::uint64_t>(),
                   l["parity_mismatches_ranges"].get<std::uint64_t>(), l["misclassified_layers"].get<std::uint64_t>(),
                   l["misclassified_ranges"].get<std::uint64_t>(), l["classified_points"].get<std::uint64_t>());
  if (l.value("all_points", std::uint64_t{0}) > 0)
    s += fmt::format("  ldi paper's reader {} points (every layer read): answers differ {}, fetch counts differ {}, misclassified {}\n",
                     l["all_points"].get<std::uint64_t>(), l["parity_mismatches_all"].get<std::uint64_t>(),
                     l["fetch_mismatches_all"].get<std::uint64_t>(), l["misclassified_all"].get<std::uint64_t>());
  return s;
}

}  // namespace

ProgramRow ldi_program() {
  return {"ldi",
          "layered depth images and the volumetric parity test: GL's peel passes replayed at the LDI's size with the strict "
          "compare against the previous layer, the model's LDI, crop and compressed texture compared with GL's, and the parity "
          "test (uncompressed and compressed) at GL's test points against GL's answers and the exact reference",
          build,
          {"gpu.ldi", "", frame_values, {}, summary, exact, describe},
          config_group<ldi::LdiUnitConfig>("ldi"),
          {},
          false};
}

}  // namespace nbsim::pipeline

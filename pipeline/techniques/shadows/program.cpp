// The shadows technique's frame program and its results (per-frame values, summary); its row of pipeline/sim/programs.h.
#include "pipeline/sim/programs.h"

#include <algorithm>
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "model/shadows/caster.h"
#include "model/shadows/unit.h"
#include "pipeline/sim/gpu.h"

namespace nbsim::pipeline {

namespace {

// Shadow volumes with litmaps (the N-buffer paper, 3.3/4.4): the trace's shadow_mode drew the
// volumes; the min and max N-buffer instances "litmap_min" and "litmap_max" are built over the
// litmaps (litmap_size square) and queried per caster, and the model's stencil gives the mask.
Program build(const ProgramContext& c) {
  c.require_no_cull_mode("a shadows trace culls its casters with the litmaps");
  shadows::ShadowsSetup s;
  s.width_px = c.view.width_px;
  s.height_px = c.view.height_px;
  // The header's shadows keys were checked against their declarations when the trace was opened
  // (traces/format/shadows/shadows_chunk.cpp).
  s.mode = *shadows::parse_mode(c.header.text("shadow_mode"));
  s.trace_litmap_size = static_cast<int>(c.header.whole("litmap_size"));
  const auto& config = c.config.group<shadows::ShadowsUnitConfig>("shadows");
  s.litmap_size = config.litmap_size > 0 ? config.litmap_size : s.trace_litmap_size;
  const shadows::ClampMargin tolerance = *shadows::parse_clamp_margin(c.header.text("reproject_tolerance"));
  s.reproject.tolerance_rel = static_cast<float>(tolerance.rel);
  s.reproject.tolerance_m = static_cast<float>(tolerance.metres);
  s.reproject.near_m = static_cast<float>(c.header.real("near"));
  s.reproject.far_m = static_cast<float>(c.header.real("far"));
  s.margin = *shadows::parse_clamp_margin(c.header.text("clamp_margin"));
  s.edge_rule = c.header.text("clamp_rule") == "edge";
  s.reference_path.width_px = c.view.width_px;
  s.reference_path.height_px = c.view.height_px;
  s.reference_path.batch_triangles = c.config.geometry.batch_triangles;
  s.reference_path.fused_viewport = c.config.geometry.fused_viewport;
  s.reference_path.fused_interpolation = c.config.depth.fused_interpolation;
  if (const std::string* f = c.header.property("depth_format"))
    if (const auto format = raster::parse_depth_format(*f)) s.reference_path.depth_format = *format;
  Program p;
  const auto nbuffer = [&](const char* instance, FarOp op) {
    return std::make_unique<query::NBufferStructure>(instance, c.registry, c.nbuffer_config(instance), s.litmap_size,
                                                     s.litmap_size, op, &c.memory);
  };
  auto min_nb = nbuffer("litmap_min", FarOp::Min);
  auto max_nb = nbuffer("litmap_max", FarOp::Max);
  auto unit = std::make_unique<shadows::ShadowsUnit>("shadows", c.registry, config, s, c.depth_buffer, c.stencil_buffer, *min_nb, *max_nb);
  p.structures.push_back(std::move(min_nb));
  p.structures.push_back(std::move(max_nb));
  p.frames = unit.get();
  p.depth_listener = unit.get();
  p.unit = std::move(unit);
  return p;
}

// The shadows program's counters in run.json's per-frame values (differences at frame ends).
constexpr std::array<const char*, 24> kShadowsFrameCounts = {"model_volumes", "stencil_checksum",
    "casters",     "culled",          "gl_culled",       "outside",    "crossing_near",       "kept_by_slab", "reference_fill",
    "lookups",     "build_texels",    "litmap_reprojections", "receiver_splats", "litmap_texel_diff", "litmap_fragment_diff", "volume_draws", "fill", "gl_fill",
    "stencil_tests", "mask_pixels", "mask_diff",       "mask_diff_infinite", "decision_mismatches", "mask_errors"};

// The per-frame values the summary keeps (the shadows table's per-frame fill and culls).
constexpr std::array<const char*, 6> kPerFrame = {"fill", "reference_fill", "culled", "gl_culled", "mask_diff", "mask_diff_infinite"};

void frame_values(const nlohmann::ordered_json& now, const nlohmann::ordered_json& last, nlohmann::ordered_json& pf) {
  for (const char* name : kShadowsFrameCounts) pf[name] = stat(now, name) - stat(last, name);
}

// The shadows program's run totals (summary "shadows"), from its statistics and both N-buffers'
// when the run is done; the per-frame values (fill, culled casters, cycles) are run.json's frames.
nlohmann::ordered_json totals(const nlohmann::ordered_json& p, std::uint64_t cycles) {
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
                           "culls_lost", "lookup_mismatches", "mask_diff", "mask_diff_infinite", "gl_mask_diff", "gl_mask_pixels",
                           "model_volumes", "rect_mismatches", "own_mask_diff", "model_litmap_frames", "litmap_texel_diff",
                           "litmap_fragment_diff", "litmap_discarded", "mask_errors"})
    j[name] = stat(p, name);
  return j;
}

// The summary: the totals, the header's mode, scene, litmap size and seed, and both N-buffers' storage.
nlohmann::ordered_json summary(const SummaryInputs& in) {
  nlohmann::ordered_json j = totals(in.group, in.cycles);
  for (const char* key : {"shadow_mode", "clamp_rule", "scene", "path", "litmap_size", "seed"}) copy_property(in.header, key, j);
  long long bytes = 0;
  for (const auto& structure : in.program.structures) bytes += structure->storage_bytes();
  j["nbuffer_memory_bytes"] = bytes;  // both units' levels
  // Where the fill goes: per caster class and reason kept, per frame, largest fill first.
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  if (const auto* unit = dynamic_cast<const shadows::ShadowsUnit*>(in.program.unit.get())) {
    j["replayed_litmap_size"] = unit->litmap_size();  // the header's litmap_size, or config shadows.litmap_size
    const double frames = std::max<double>(1.0, static_cast<double>(stat(in.group, "frames")));
    std::vector<std::pair<const std::pair<std::string, std::string>*, const shadows::FillShare*>> shares;
    for (const auto& [key, share] : unit->breakdown()) shares.emplace_back(&key, &share);
    std::stable_sort(shares.begin(), shares.end(), [](const auto& a, const auto& b) { return a.second->fill > b.second->fill; });
    for (const auto& [key, share] : shares) {
      nlohmann::ordered_json r;
      r["class"] = key->first;
      r["kept"] = key->second;
      r["casters_per_frame"] = static_cast<double>(share->casters) / frames;
      r["volumes_per_frame"] = static_cast<double>(share->volumes) / frames;
      r["fill_per_frame"] = static_cast<double>(share->fill) / frames;
      r["gl_fill_per_frame"] = static_cast<double>(share->gl_fill) / frames;
      r["fill_infinite_per_frame"] = static_cast<double>(share->fill_infinite) / frames;
      rows.push_back(std::move(r));
    }
  }
  j["fill_breakdown"] = std::move(rows);
  return j;
}

}  // namespace

ProgramRow shadows_program() {
  return {"shadows",
          "shadow volumes culled and clamped with min/max litmaps (the trace's shadow_mode): GL's scene and volume draws "
          "rasterized with the stencil test, a min and a max N-buffer built over GL's litmaps and queried per caster, the "
          "decisions and the shadow mask compared with GL's",
          build,
          {"gpu.shadows", "", frame_values, kPerFrame, summary},
          config_group<shadows::ShadowsUnitConfig>("shadows"),
          {{"litmap_min", InstanceKind::NBuffer,
            "the min N-buffer over the min litmap (litmap_size square), queried for each caster's z_min"},
           {"litmap_max", InstanceKind::NBuffer,
            "the max N-buffer over the max litmap (litmap_size square), queried for each caster's z_max"}},
          false};
}

}  // namespace nbsim::pipeline

// The particles technique's frame program and its results (per-frame values, summary); its row of pipeline/sim/programs.h.
#include "pipeline/sim/programs.h"

#include <fmt/format.h>

#include <string>

#include "model/common/error.h"
#include "model/particles/sprite.h"
#include "model/particles/unit.h"
#include "pipeline/sim/gpu.h"

namespace nbsim::pipeline {

namespace {

const particles::ParticlesUnitConfig& config(const GpuConfig& gpu) { return gpu.group<particles::ParticlesUnitConfig>("particles"); }

// Point-sprite particles (the N-buffer paper, 3.2/4.3): the trace's particle_mode is the test; the
// N-buffer instance "nbuffer" (mode nb) is built up to the capture's top level (levels_built - 1)
// unless nbuffer.level_cap sets another; mode hiz reads the "hiz" instance's format and timing.
Program build(const ProgramContext& c) {
  c.require_no_cull_mode("a particles trace culls with its own particle_mode");
  particles::ParticlesSetup s;
  s.width_px = c.view.width_px;
  s.height_px = c.view.height_px;
  s.op = c.view.op;
  s.depth_func = c.view.depth_func;
  // The header's particle keys were checked against their declarations when the trace was opened
  // (traces/format/particles/particles_chunk.cpp): the mode is a known one, the levels 0 .. 31.
  s.mode = *particles::parse_mode(c.header.text("particle_mode"));
  s.top_level = static_cast<int>(c.header.whole("levels_built")) - 1;
  s.margin = static_cast<float>(c.header.real("cull_margin"));
  if (config(c.config).mode != "trace") {
    // Another test than the capture's: the levels it builds follow from the capture's sprite sizes
    // and level cap, as the capture computes them for that mode.
    const auto other = particles::parse_mode(config(c.config).mode);
    if (!other) throw InputError(fmt::format("particles.mode '{}' is not one of trace, none, center, nb, hiz", config(c.config).mode));
    const std::string& sprite = c.header.text("sprite");
    const int largest = sprite == "atten" ? static_cast<int>(particles::kMaxAttenuatedPx) : static_cast<int>(c.header.whole("sprite"));
    const int level_cap = static_cast<int>(c.header.whole("level_cap"));
    if (*other != s.mode) s.top_level = particles::top_level_needed(*other, largest, level_cap);
    s.mode = *other;
  }
  Program p;
  const HiZUnitConfig* hiz = nullptr;
  if (s.mode == particles::Mode::NBuffer) {
    nbuffer::NBufferUnitConfig nb = c.nbuffer_config("nbuffer");
    if (nb.level_cap < 0) nb.level_cap = s.top_level;  // the partial build the capture made
    nb.direct_squares = true;  // a power-of-two sprite is one lookup (the paper's direct covering, 3.2)
    s.top_level = nb.level_cap;
    p.structures.push_back(std::make_unique<query::NBufferStructure>("nbuffer", c.registry, nb, c.view.width_px,
                                                                     c.view.height_px, c.view.op, &c.memory));
  } else if (s.mode == particles::Mode::HiZ) {
    hiz = &c.config.hiz.at("hiz");
  }
  auto unit = std::make_unique<particles::ParticlesUnit>("particles", c.registry, config(c.config), s, c.depth_buffer,
                                                         p.structures.empty() ? nullptr : p.structures.front().get(), hiz);
  p.frames = unit.get();
  p.depth_listener = unit.get();
  p.unit = std::move(unit);
  return p;
}

// The particles program's counters in run.json's per-frame values (differences at frame ends).
constexpr std::array<const char*, 11> kParticlesFrameCounts = {
    "particles", "culled", "kept_too_large", "lookups", "particle_fragments", "build_texels", "decision_mismatches",
    "popping", "false_culls", "exactly_hidden", "hidden_kept"};

void frame_values(const nlohmann::ordered_json& now, const nlohmann::ordered_json& last, nlohmann::ordered_json& pf) {
  const auto delta = [&](const char* name) { return stat(now, name) - stat(last, name); };
  pf["query_depth_tests"] = delta("lookups");
  pf["total_depth_tests"] = delta("lookups") + delta("particle_fragments") + delta("build_texels");
  for (const char* name : kParticlesFrameCounts) pf[name] = delta(name);
}

// The particles program's run totals (summary "particles"), from its statistics and its N-buffer's
// when the run is done. Depth tests as docs/architecture.md ("Definitions") counts them: the
// queries' texels read, the particle draws' fragments, and the partial build's texels; the scene's
// own depth tests apart.
nlohmann::ordered_json totals(const nlohmann::ordered_json& p, std::string_view mode, std::uint64_t cycles) {
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

// The summary: the totals under the mode the model ran (the capture's unless particles.mode says
// another), the capture's mode, and the N-buffer's storage (0 in the modes without one).
nlohmann::ordered_json summary(const SummaryInputs& in) {
  const std::string* captured = in.header.property("particle_mode");
  const std::string capture_mode = captured ? *captured : "";
  const std::string& chosen = config(in.config).mode;
  const std::string& mode = chosen == "trace" ? capture_mode : chosen;
  nlohmann::ordered_json j = totals(in.group, mode, in.cycles);
  j["capture_mode"] = capture_mode;
  j["nbuffer_memory_bytes"] = in.program.structures.empty() ? 0 : in.program.structures.front()->storage_bytes();
  return j;
}

}  // namespace

ProgramRow particles_program() {
  return {"particles",
          "point-sprite particles culled in the vertex stage (the trace's particle_mode: none, center, nb, hiz), each "
          "decision made again by the model and compared with GL's; GL's particle draws rasterized",
          build,
          {"gpu.particles", "", frame_values, {}, summary},
          config_group<particles::ParticlesUnitConfig>("particles"),
          {{"nbuffer", InstanceKind::NBuffer, "the max N-buffer (particle_mode nb, level_cap -1: the capture's levels)"},
           {"hiz", InstanceKind::HiZ, "the Hi-Z pyramid's format and timing (particle_mode hiz)"}},
          false};
}

}  // namespace nbsim::pipeline

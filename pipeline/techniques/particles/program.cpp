// The particles technique's frame program; see program.h.
#include "pipeline/techniques/particles/program.h"

#include <fmt/format.h>

#include "model/common/error.h"
#include "model/particles/sprite.h"
#include "model/particles/unit.h"
#include "pipeline/sim/gpu.h"

namespace nbsim::pipeline {

namespace {

// Point-sprite particles (the N-buffer paper, 3.2/4.3): the trace's particle_mode is the test; the
// N-buffer instance "nbuffer" (mode nb) is built up to the capture's top level (levels_built - 1)
// unless nbuffer.level_cap sets another; mode hiz reads the "hiz" instance's format and timing.
Program build(const ProgramContext& c) {
  c.require_no_cull_mode("a particles trace culls with its own particle_mode");
  particles::ParticlesSetup s;
  s.width_px = c.setup.width_px;
  s.height_px = c.setup.height_px;
  s.op = c.setup.op;
  s.depth_func = c.setup.depth_func;
  // The header's particle keys were checked against their declarations when the trace was opened
  // (traces/format/particles/particles_chunk.cpp): the mode is a known one, the levels 0 .. 31.
  s.mode = *particles::parse_mode(c.header.text("particle_mode"));
  s.top_level = static_cast<int>(c.header.whole("levels_built")) - 1;
  s.margin = static_cast<float>(c.header.real("cull_margin"));
  if (c.config.particles.mode != "trace") {
    // Another test than the capture's: the levels it builds follow from the capture's sprite sizes
    // and level cap, as the capture computes them for that mode.
    const auto other = particles::parse_mode(c.config.particles.mode);
    if (!other) throw InputError(fmt::format("particles.mode '{}' is not one of trace, none, center, nb, hiz", c.config.particles.mode));
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
    p.structures.push_back(std::make_unique<query::NBufferStructure>("nbuffer", c.registry, nb, c.setup.width_px,
                                                                     c.setup.height_px, c.setup.op, &c.memory));
  } else if (s.mode == particles::Mode::HiZ) {
    hiz = &c.config.hiz.at("hiz");
  }
  auto unit = std::make_unique<particles::ParticlesUnit>("particles", c.registry, c.config.particles, s, c.depth_buffer,
                                                         p.structures.empty() ? nullptr : p.structures.front().get(), hiz);
  p.frames = unit.get();
  p.depth_listener = unit.get();
  p.unit = std::move(unit);
  return p;
}

}  // namespace

ProgramRow particles_program() {
  return {"particles",
          "point-sprite particles culled in the vertex stage (the trace's particle_mode: none, center, nb, hiz), each "
          "decision made again by the model and compared with GL's; GL's particle draws rasterized",
          build};
}

}  // namespace nbsim::pipeline

// The shadows technique's frame program; see program.h.
#include "pipeline/techniques/shadows/program.h"

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
  s.width_px = c.setup.width_px;
  s.height_px = c.setup.height_px;
  // The header's shadows keys were checked against their declarations when the trace was opened
  // (traces/format/shadows/shadows_chunk.cpp).
  s.mode = *shadows::parse_mode(c.header.text("shadow_mode"));
  s.litmap_size = static_cast<int>(c.header.whole("litmap_size"));
  s.margin = *shadows::parse_clamp_margin(c.header.text("clamp_margin"));
  Program p;
  const auto nbuffer = [&](const char* instance, FarOp op) {
    return std::make_unique<query::NBufferStructure>(instance, c.registry, c.nbuffer_config(instance), s.litmap_size,
                                                     s.litmap_size, op, &c.memory);
  };
  auto min_nb = nbuffer("litmap_min", FarOp::Min);
  auto max_nb = nbuffer("litmap_max", FarOp::Max);
  auto unit = std::make_unique<shadows::ShadowsUnit>("shadows", c.registry, c.config.shadows, s, c.stencil_buffer, *min_nb, *max_nb);
  p.structures.push_back(std::move(min_nb));
  p.structures.push_back(std::move(max_nb));
  p.frames = unit.get();
  p.depth_listener = unit.get();
  p.unit = std::move(unit);
  return p;
}

}  // namespace

ProgramRow shadows_program() {
  return {"shadows",
          "shadow volumes culled and clamped with min/max litmaps (the trace's shadow_mode): GL's scene and volume draws "
          "rasterized with the stencil test, a min and a max N-buffer built over GL's litmaps and queried per caster, the "
          "decisions and the shadow mask compared with GL's",
          build};
}

}  // namespace nbsim::pipeline

// The relief technique's frame program; see program.h.
#include "pipeline/techniques/relief/program.h"

#include "model/relief/unit.h"
#include "pipeline/sim/gpu.h"

namespace nbsim::pipeline {

namespace {

// Relief textures (Baboud & Decoret) and the N-buffer walk: every relief_box draw rasterized with the
// early depth test, each fragment's walk run with the draw's method and compared with GL's, and
// scored against the exact reference.
Program build(const ProgramContext& c) {
  c.require_no_cull_mode("a relief trace walks its own rays");
  const double box_height = c.header.real("relief_box_height");  // above 0: checked when the trace was opened
  Program p;
  // The N-buffer walk covers as the capture did (its GL walks are compared one by one).
  auto unit = std::make_unique<relief::ReliefUnit>("relief", c.registry, c.config.relief, c.memory, c.setup.width_px, c.setup.height_px,
                                                   box_height, c.config.depth.fused_interpolation, c.capture_covering());
  p.frames = unit.get();
  p.unit = std::move(unit);
  return p;
}

}  // namespace

ProgramRow relief_program() {
  return {"relief",
          "relief textures: every relief_box draw rasterized with the early depth test, each fragment's ray walk (binary, "
          "exact, robust, robust_clamp or nbuffer, as the draw's RLFF says) run through the ray-walk unit and its texel cache, "
          "compared with GL's per fragment and scored against the exact reference",
          build};
}

}  // namespace nbsim::pipeline

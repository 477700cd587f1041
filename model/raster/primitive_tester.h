// The raster unit's hook for per-primitive culling (cull.granularity=primitive): between triangle
// setup and the tile walk, the raster unit hands a draw's accepted triangles to a PrimitiveTester
// (the cull stage, model/cull/unit.h), which queries its depth structure and marks the hidden
// ones; the raster unit then walks only the others. Without a tester nothing changes.
#pragma once

#include <span>
#include <vector>

#include "model/cp/work.h"
#include "model/geometry/primitive.h"
#include "model/raster/setup.h"

namespace nbsim::raster {

// One triangle that setup accepted: the window-space triangle and setup's result for it.
struct SetupPrimitive {
  const geometry::WindowTriangle* window = nullptr;
  SetupTriangle setup;
};

class PrimitiveTester {
 public:
  virtual ~PrimitiveTester() = default;
  // Whether the draw's triangles are to be tested (once per draw, from the raster unit's thread).
  virtual bool tests_primitives(const cp::Work& work) const = 0;
  // Sets hidden[i] (sized like `prims`, zeroed) for each triangle found hidden. Blocking: the
  // raster unit's thread waits for the query unit's cycles.
  virtual void test_primitives(const cp::Work& work, std::span<const SetupPrimitive> prims, std::vector<char>& hidden) = 0;
};

}  // namespace nbsim::raster

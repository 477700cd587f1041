// The check of per-primitive culling (cull.granularity=primitive), off the clock: a triangle the
// cull stage dropped is rasterized (llvmpipe's rules, model/raster/rasterizer.h) against the depth
// buffer as it was after the frame's occluders. A fragment that passes there is a possible false
// cull: the depth buffer only moves nearer after the occluders (the drawn candidates test and
// write with the same func), so a fragment that fails there fails when the triangle would have been
// drawn, and the count is an upper bound on real false culls. Plain C++, no SystemC.
#pragma once

#include <cstdint>

#include "model/common/depth.h"
#include "model/raster/depth_test.h"
#include "model/raster/rasterizer.h"

namespace nbsim::cull {

class FalseCullCheck {
 public:
  FalseCullCheck(int width_px, int height_px);

  // The depth buffer after this frame's occluders: what the dropped triangles are checked against.
  void set_occluder_depth(const DepthImage& depth) { occluder_depth_ = depth; }

  struct Result {
    std::uint64_t fragments = 0;  // fragments the triangle rasterizes (the depth tests it would have cost)
    bool passes = false;          // at least one of them passes against the occluders' depth
  };
  // `fused`: the depth unit's interpolation (depth.fused_interpolation).
  Result check(const raster::SetupTriangle& t, raster::DepthFunc func, bool fused) const;

 private:
  raster::Rasterizer raster_;
  DepthImage occluder_depth_;
};

}  // namespace nbsim::cull

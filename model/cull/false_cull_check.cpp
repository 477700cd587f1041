// The check of per-primitive culling; see false_cull_check.h.
#include "model/cull/false_cull_check.h"

namespace nbsim::cull {

FalseCullCheck::FalseCullCheck(int width_px, int height_px) : raster_(width_px, height_px) {}

FalseCullCheck::Result FalseCullCheck::check(const raster::SetupTriangle& t, raster::DepthFunc func, bool fused) const {
  Result r;
  raster::TileCounters ignored;
  raster_.rasterize(t, ignored, [&](int x, int y, std::uint16_t mask) {
    for (int b = 0; b < 16; ++b) {
      if (!(mask & (1u << b))) continue;
      const int px = x + (b & 3), py = y + (b >> 2);
      ++r.fragments;
      r.passes = r.passes || raster::depth_passes(func, t.depth.at(px, py, fused), occluder_depth_.at(px, py));
    }
  });
  return r;
}

}  // namespace nbsim::cull

// Point setup: a point sprite from the geometry stage (model/geometry/primitive.h WindowPoint) to
// the square the rasterizer traverses (four fixed-point planes and a bounding box, the same
// SetupTriangle the tile walk of model/raster/rasterizer.h takes) and its constant depth plane, as
// llvmpipe does it for GL core contexts (point sprites, one sample).
//
// What is matched (Mesa 22.3, src/gallium/drivers/llvmpipe; the geometry stage's side, centre
// clipping, is in model/geometry/geometry.h):
// - lp_setup_point.c try_setup_point, the "points as quads" branch: GL core has point sprites
//   always on, so the state tracker sets point_quad_rasterization (st_atom_rasterizer.c) and
//   lp_setup.c sets legacy_points = !point_quad_rasterization && !multisample = false. The size
//   is the vertex's gl_PointSize (point_size_per_vertex, GL_PROGRAM_POINT_SIZE), cut to
//   LP_MAX_POINT_WIDTH = 255 (lp_limits.h; also PIPE_CAPF_MAX_POINT_SIZE, so GL reports 1..255)
//   when larger; nothing else clamps it.
// - subpixel_snap(a) = util_iround(256 a). On x86-64 util_iround (u_math.h) is not the x87
//   fistp branch (that is 32-bit x86 only) but (int)(f + 0.5f) for f >= 0 and (int)(f - 0.5f)
//   otherwise: round half AWAY from zero, the sum rounded in float (exact below 2^22 px). That
//   differs from the triangle snap (setup.h: cvtps2dq, half to even) on exact 1/512 ties.
// - width w = max(256, subpixel_snap(size)): sizes below one pixel (zero and negative ones too)
//   draw one pixel. x0 = subpixel_snap(x - 0.5f) - w / 2 (C integer division: w odd rounds the
//   half down), x1 = x0 + w; likewise y. pixel_offset is 0.5 (half_pixel_center, one sample).
// - Planes (fixed point, pixel (i, j) has its centre at (256 i, 256 j)): left c = -x0 + 1,
//   dcdx = -256; right c = x1, dcdx = 256; bottom c = -y0 + 1, dcdy = 256; top c = y1,
//   dcdy = -256; "+ 1" is the fill rule (bottom_edge_rule = 0 for FBOs adjusts the bottom plane,
//   adj = 0). So pixel (i, j) is covered exactly when x0 <= 256 i < x1 and y0 <= 256 j < y1: a
//   square edge through a pixel centre owns it on the left and bottom, not on the right and top.
// - The bounding box (x0 >> 8 .. ((x1 + 255) >> 8) - 1, likewise y) is intersected with the
//   draw region (the render target); a point whose box misses it is dropped after being counted
//   (c_primitives, the clipper's output). The planes are clamped to the intersected box
//   (c = -max(x0, 256 bx0) + 1, ...), so no scissor planes are added. The square is then binned
//   like a four-plane triangle (lp_setup_bin_triangle: TRI_4_16 or the tile walk).
// - Depth: setup_point_fragcoord_coef gives z the constant coefficient a0 = window z,
//   dadx = dady = 0, so every fragment has the vertex's window z (then clamped to [0, 1] as for
//   triangles); it goes through the same early depth test.
#pragma once

#include <cstdint>

#include "model/geometry/primitive.h"
#include "model/raster/setup.h"

namespace nbsim::raster {

// Fixed by the design being matched (lp_limits.h LP_MAX_POINT_WIDTH).
constexpr float kMaxPointSizePx = 255.0f;

// llvmpipe's subpixel_snap for points (round half away from zero, see above). Values beyond
// 2^31 / 256 px are not snapped as llvmpipe does (it overflows there); the geometry stage's
// centre clipping keeps point centres within the viewport.
std::int32_t snap_point_coordinate(float window_coordinate) noexcept;

// The point's square width in 1/256 pixels after llvmpipe's clamps: 256 .. 65280.
std::int32_t point_width_fixed(float size) noexcept;

class PointSetup {
 public:
  // Throws InputError for a render target outside 1x1 .. 16384x16384.
  explicit PointSetup(const SetupConfig& config);

  // Sets up one point; `out` is filled only when the result is Accepted (four planes, front
  // facing, a constant depth plane). Offscreen: the square misses the render target.
  // Unsupported: a non-finite or out-of-range window position (a w = 0 vertex at the origin,
  // which has no outcode bit), which llvmpipe cannot snap either and for which GL draws nothing
  // (PointGlCompareTest.ZeroWPointCountedButNotDrawn). Counts into `counters.points` and the
  // shared result counters.
  SetupResult setup(const geometry::WindowPoint& point, SetupTriangle& out, SetupCounters& counters) const;

  const SetupConfig& config() const noexcept { return config_; }

 private:
  SetupConfig config_;
};

}  // namespace nbsim::raster

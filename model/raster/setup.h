// Triangle setup: window-space triangles from the geometry stage (model/geometry/primitive.h) to
// what the rasterizer traverses (fixed-point edge planes and a bounding box, model/raster/
// rasterizer.h) and what the depth test interpolates (a depth plane), as llvmpipe does it.
//
// What is matched (Mesa 22.3, src/gallium/drivers/llvmpipe):
// - lp_setup_tri.c calc_fixed_position: x_fixed = round-half-even((x - 0.5) * 256) with 8
//   subpixel bits, so pixel (i, j) has its centre at fixed (256 i, 256 j). The area sign of the
//   snapped triangle decides facing and culling (triangle_cw / triangle_ccw / triangle_both): a
//   triangle of negative area is drawn with vertices 0 and 1 swapped.
// - lp_setup_tri.c do_triangle_ccw: edge i runs from vertex i to i + 1; dcdx = y_i - y_i+1,
//   dcdy = x_i - x_i+1, c = dcdx x_i - dcdy y_i, plus one on left edges and on horizontal edges
//   with dcdy > 0 (the top-left rule of a y-down raster, which for GL's y-up FBOs is
//   bottom-left; st_atom_rasterizer.c sets bottom_edge_rule = 0 for FBOs; with
//   SetupConfig::bottom_edge_rule, horizontal edges with dcdy < 0 instead). A pixel is covered
//   when c - dcdx x + dcdy y > 0 for every plane (lp_rast_tri_tmp.h tests c - 1 >= 0).
// - The bounding box (x0 = min >> 8, x1 = (max - 1) >> 8, likewise y), the draw-region reject and
//   the scissor planes added when the box passes the render target's right or top border
//   (lp_setup.c lp_setup_add_scissor_planes).
// - lp_state_setup.c: the depth plane from the float window positions, in float:
//   ooa = 1 / (dx01 dy20 - dy01 dx20), dzdx = dz01 dy20 ooa - dz20 dy01 ooa,
//   dzdy = dz20 dx01 ooa - dz01 dx20 ooa, a0 = z0 - (dzdx (x0 - 0.5) + dzdy (y0 - 0.5)), each
//   product and sum rounded separately (the JIT uses plain fmul/fsub there).
// - lp_bld_interp.c: z at pixel (x, y) = fmuladd(dzdy, y, fmuladd(dzdx, x, a0)) (fused on FMA
//   hosts), then clamped to [0, 1] (lp_state_fs.c lp_build_depth_clamp).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "model/geometry/primitive.h"

namespace nbsim::raster {

// Fixed by the design being matched (llvmpipe's FIXED_ORDER and TILE_SIZE).
constexpr int kSubpixelBits = 8;
constexpr int kSubpixelOne = 1 << kSubpixelBits;
constexpr int kTileBits = 6;
constexpr int kTilePx = 1 << kTileBits;

// One half-plane in llvmpipe's form. At pixel (x, y): E = c - dcdx * x + dcdy * y (dcdx and dcdy
// are already scaled by 256); the pixel is inside when E > 0. eo is the largest increase of E
// over one pixel step (for trivial reject).
struct EdgePlane {
  std::int64_t c = 0;
  std::int32_t dcdx = 0;
  std::int32_t dcdy = 0;
  std::int64_t eo = 0;  // llvmpipe keeps it unsigned 32-bit; it can pass 2^31

  constexpr std::int64_t at(int x, int y) const noexcept {
    return c - static_cast<std::int64_t>(dcdx) * x + static_cast<std::int64_t>(dcdy) * y;
  }
  // The smallest change of E over one pixel step in x and y (<= 0); llvmpipe's ei.
  constexpr std::int64_t ei() const noexcept {
    return static_cast<std::int64_t>(dcdy) - static_cast<std::int64_t>(dcdx) - eo;
  }
};

// An inclusive pixel rectangle.
struct PixelBox {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
  constexpr bool empty() const noexcept { return x1 < x0 || y1 < y0; }
};

// The depth plane of a triangle, with llvmpipe's evaluation at pixel (x, y).
struct DepthPlane {
  float a0 = 0.0f;
  float dzdx = 0.0f;
  float dzdy = 0.0f;
  // z before the [0, 1] clamp: fmuladd(dzdy, y, fmuladd(dzdx, x, a0)), with one rounding each
  // (fused) or two (unfused, for hosts without FMA).
  // (Inline: the depth test calls it per fragment. Every target compiles with -ffp-contract=off,
  // so the unfused sum keeps its two roundings wherever it is inlined.)
  float raw_at(int x, int y, bool fused = true) const noexcept {
    const float fx = static_cast<float>(x), fy = static_cast<float>(y);
    if (fused) return std::fma(dzdy, fy, std::fma(dzdx, fx, a0));
    const float ax = dzdx * fx;
    const float a = a0 + ax;
    const float ay = dzdy * fy;
    return a + ay;
  }
  // The depth the fragment is tested and written with: plus the (zero) polygon offset llvmpipe
  // adds, then lp_build_clamp(z, 0, 1).
  float at(int x, int y, bool fused = true) const noexcept {
    const float z = raw_at(x, y, fused) + 0.0f;
    return std::min(std::max(z, 0.0f), 1.0f);
  }
};

constexpr int kMaxPlanes = 7;  // three edges and at most four scissor planes

struct SetupTriangle {
  std::array<EdgePlane, kMaxPlanes> planes{};
  int num_planes = 0;
  PixelBox bbox;     // llvmpipe's box with x0, y0 clamped at 0; x1, y1 may pass the target
  PixelBox trimmed;  // bbox within the render target
  DepthPlane depth;
  bool front_facing = true;
};

enum class SetupResult : std::uint8_t {
  Accepted = 0,
  ZeroArea = 1,   // the snapped triangle has no area
  Culled = 2,     // the face is culled (by the snapped area's sign)
  Offscreen = 3,  // the bounding box misses the render target
  Unsupported = 4,  // a non-finite coordinate, or vertices 32768 px or more apart: llvmpipe's
                    // 32-bit plane arithmetic overflows there, the clipper never produces it
};

// Per-draw counters of setup (added to, never reset by the stage).
struct SetupCounters {
  std::uint64_t triangles = 0;  // entering setup
  std::uint64_t points = 0;     // point sprites entering point setup (point_setup.h); the result
                                // counters below count points and triangles alike
  std::uint64_t zero_area = 0;
  std::uint64_t culled = 0;
  std::uint64_t offscreen = 0;
  std::uint64_t unsupported = 0;
  std::uint64_t accepted = 0;
  SetupCounters& operator+=(const SetupCounters& o);
};

struct SetupConfig {
  int width_px = 0;  // render target, 1 .. 16384
  int height_px = 0;
  // llvmpipe's bottom_edge_rule (st_atom_rasterizer.c sets it for a window-system framebuffer,
  // which Gallium draws upside down; 0 for FBOs): a horizontal edge with dcdy < 0 is the included
  // one instead of dcdy > 0, and the bounding box's rows round one subpixel up
  // (lp_setup_tri.c do_triangle_ccw).
  bool bottom_edge_rule = false;
};

// The fixed-point position llvmpipe snaps a window coordinate to.
std::int32_t snap_to_subpixel(float window_coordinate) noexcept;

class TriangleSetup {
 public:
  // Throws InputError for a render target outside 1x1 .. 16384x16384.
  explicit TriangleSetup(const SetupConfig& config);

  // Sets up one triangle; `out` is filled only when the result is Accepted.
  SetupResult setup(const geometry::WindowTriangle& triangle, const geometry::FaceState& face, SetupTriangle& out,
                    SetupCounters& counters) const;

  const SetupConfig& config() const noexcept { return config_; }

 private:
  SetupConfig config_;
};

}  // namespace nbsim::raster

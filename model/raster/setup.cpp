// Triangle setup as llvmpipe does it: snapping, facing and culling, edge planes with the fill
// rule, bounding box and scissor planes, depth plane. See setup.h for the Mesa sources matched.
// The float expressions must stay separately rounded (see the pragma below); the fused
// interpolation calls std::fma explicitly.
#include "model/raster/setup.h"

// Keep the compiler from fusing a * b + c into one FMA even when a build targets FMA hardware
// (-march): Mesa's C and JIT code round these products separately.
// GCC: -ffp-contract=off on every target (cmake/NbsimWarnings.cmake), not a `#pragma GCC optimize`,
// which would keep GCC from inlining std::min, std::max and friends into this file's functions.
#if defined(__clang__)
#pragma clang fp contract(off)
#endif

#include <algorithm>
#include <cmath>
#include <string>

#include "model/common/error.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace nbsim::raster {

namespace {

constexpr int kMaxTargetPx = 16384;
// Input limits (fixed by llvmpipe's arithmetic): an edge's fixed-point extent times 256 must fit in
// 32 bits, so vertices must be less than 2^23 / 256 = 32768 px apart; coordinates beyond 2^22 px
// cannot be snapped exactly at all.
constexpr std::int64_t kMaxEdgeFixed = std::int64_t{1} << 23;
constexpr float kMaxCoordinatePx = 4194304.0f;

struct Fixed {
  std::array<std::int32_t, 3> x{}, y{};
};

// Sign of the snapped area dx01 * dy20 - dx20 * dy01 (lp_setup_tri.c calc_fixed_position).
int area_sign(const Fixed& f) {
  const std::int64_t dx01 = static_cast<std::int64_t>(f.x[0]) - f.x[1];
  const std::int64_t dy01 = static_cast<std::int64_t>(f.y[0]) - f.y[1];
  const std::int64_t dx20 = static_cast<std::int64_t>(f.x[2]) - f.x[0];
  const std::int64_t dy20 = static_cast<std::int64_t>(f.y[2]) - f.y[0];
  // llvmpipe takes the int32 differences and multiplies them in 64 bits.
  const std::int64_t area =
      static_cast<std::int64_t>(static_cast<std::int32_t>(dx01)) * static_cast<std::int32_t>(dy20) -
      static_cast<std::int64_t>(static_cast<std::int32_t>(dx20)) * static_cast<std::int32_t>(dy01);
  return area == 0 ? 0 : (area < 0 ? -1 : 1);
}

DepthPlane depth_plane(const geometry::WindowVertex& v0, const geometry::WindowVertex& v1,
                       const geometry::WindowVertex& v2) {
  // lp_state_setup.c init_args / calc_coef4, operation for operation.
  const float x0_center = v0.x - 0.5f;
  const float y0_center = v0.y - 0.5f;
  const float dx01 = v0.x - v1.x, dy01 = v0.y - v1.y, dz01 = v0.z - v1.z;
  const float dx20 = v2.x - v0.x, dy20 = v2.y - v0.y, dz20 = v2.z - v0.z;
  const float e = dx01 * dy20;
  const float f = dy01 * dx20;
  const float ooa = 1.0f / (e - f);
  const float dx20_ooa = dx20 * ooa, dy20_ooa = dy20 * ooa;
  const float dx01_ooa = dx01 * ooa, dy01_ooa = dy01 * ooa;
  const float dz01_dy20 = dz01 * dy20_ooa;
  const float dz20_dy01 = dz20 * dy01_ooa;
  const float dzdx = dz01_dy20 - dz20_dy01;
  const float dz01_dx20 = dz01 * dx20_ooa;
  const float dz20_dx01 = dz20 * dx01_ooa;
  const float dzdy = dz20_dx01 - dz01_dx20;
  const float dzdx_x0 = dzdx * x0_center;
  const float dzdy_y0 = dzdy * y0_center;
  const float at_v0 = dzdx_x0 + dzdy_y0;
  return DepthPlane{v0.z - at_v0, dzdx, dzdy};
}

}  // namespace


SetupCounters& SetupCounters::operator+=(const SetupCounters& o) {
  triangles += o.triangles;
  points += o.points;
  zero_area += o.zero_area;
  unsupported += o.unsupported;
  culled += o.culled;
  offscreen += o.offscreen;
  accepted += o.accepted;
  return *this;
}

std::int32_t snap_to_subpixel(float window_coordinate) noexcept {
  const float scaled = (window_coordinate - 0.5f) * static_cast<float>(kSubpixelOne);
#if defined(__SSE2__)
  // cvtps2dq: round half to even, 0x80000000 for NaN and out-of-range values, as llvmpipe gets.
  return _mm_cvtsi128_si32(_mm_cvtps_epi32(_mm_set_ss(scaled)));
#else
  if (!(scaled >= -2147483648.0f && scaled < 2147483648.0f)) return INT32_MIN;
  return static_cast<std::int32_t>(std::nearbyint(scaled));
#endif
}

TriangleSetup::TriangleSetup(const SetupConfig& config) : config_(config) {
  if (config.width_px < 1 || config.width_px > kMaxTargetPx || config.height_px < 1 || config.height_px > kMaxTargetPx)
    throw InputError("setup: render target " + std::to_string(config.width_px) + "x" +
                     std::to_string(config.height_px) + " is outside 1x1 .. 16384x16384");
}

SetupResult TriangleSetup::setup(const geometry::WindowTriangle& triangle, const geometry::FaceState& face,
                                 SetupTriangle& out, SetupCounters& counters) const {
  counters.triangles += 1;
  for (const geometry::WindowVertex& v : triangle.v) {
    if (!(std::fabs(v.x) < kMaxCoordinatePx && std::fabs(v.y) < kMaxCoordinatePx)) {
      counters.unsupported += 1;
      return SetupResult::Unsupported;
    }
  }
  Fixed f;
  for (int i = 0; i < 3; ++i) {
    f.x[static_cast<std::size_t>(i)] = snap_to_subpixel(triangle.v[static_cast<std::size_t>(i)].x);
    f.y[static_cast<std::size_t>(i)] = snap_to_subpixel(triangle.v[static_cast<std::size_t>(i)].y);
  }
  for (std::size_t i = 0; i < 3; ++i) {
    const std::size_t j = (i + 1) % 3;
    if (std::abs(static_cast<std::int64_t>(f.x[i]) - f.x[j]) >= kMaxEdgeFixed ||
        std::abs(static_cast<std::int64_t>(f.y[i]) - f.y[j]) >= kMaxEdgeFixed) {
      counters.unsupported += 1;
      return SetupResult::Unsupported;
    }
  }
  const int sign = area_sign(f);
  if (sign == 0) {
    counters.zero_area += 1;
    return SetupResult::ZeroArea;
  }

  // llvmpipe's "ccw" (positive snapped area) is clockwise for y up. Gallium's front_ccw is GL's
  // inverted for an FBO, so a positive area is front-facing exactly when GL's front face is CW.
  const bool positive_is_front = !face.front_ccw;
  const bool front = sign > 0 ? positive_is_front : !positive_is_front;
  const unsigned face_bit = front ? 2u : 1u;  // CullFace: Back = 1, Front = 2
  if ((static_cast<unsigned>(face.cull) & face_bit) != 0) {
    counters.culled += 1;
    return SetupResult::Culled;
  }

  // A negative area is drawn as (v1, v0, v2) (rotate_fixed_position_01, last-vertex provoking).
  std::array<int, 3> order = {0, 1, 2};
  if (sign < 0) order = {1, 0, 2};
  std::array<std::int32_t, 3> x{}, y{};
  for (std::size_t i = 0; i < 3; ++i) {
    x[i] = f.x[static_cast<std::size_t>(order[i])];
    y[i] = f.y[static_cast<std::size_t>(order[i])];
  }

  // Bounding box, inclusive (with bottom_edge_rule its rows round one subpixel up).
  const int adj = config_.bottom_edge_rule ? 1 : 0;
  PixelBox box;
  box.x0 = std::min({x[0], x[1], x[2]}) >> kSubpixelBits;
  box.x1 = (std::max({x[0], x[1], x[2]}) - 1) >> kSubpixelBits;
  box.y0 = (std::min({y[0], y[1], y[2]}) + adj) >> kSubpixelBits;
  box.y1 = (std::max({y[0], y[1], y[2]}) - 1 + adj) >> kSubpixelBits;
  const PixelBox region{0, 0, config_.width_px - 1, config_.height_px - 1};
  if (box.x0 > region.x1 || box.x1 < region.x0 || box.y0 > region.y1 || box.y1 < region.y0) {
    counters.offscreen += 1;
    return SetupResult::Offscreen;
  }
  box.x0 = std::max(box.x0, 0);
  box.y0 = std::max(box.y0, 0);
  out.bbox = box;
  out.trimmed = {std::max(box.x0, region.x0), std::max(box.y0, region.y0), std::min(box.x1, region.x1),
                 std::min(box.y1, region.y1)};

  for (std::size_t i = 0; i < 3; ++i) {
    const std::size_t j = (i + 1) % 3;
    EdgePlane& p = out.planes[i];
    const std::int32_t dcdx = y[i] - y[j];  // |dcdx|, |dcdy| < 2^23: checked above
    const std::int32_t dcdy = x[i] - x[j];
    p.c = static_cast<std::int64_t>(dcdx) * x[i] - static_cast<std::int64_t>(dcdy) * y[i];
    if (dcdx < 0 || (dcdx == 0 && (config_.bottom_edge_rule ? dcdy < 0 : dcdy >= 0))) p.c += 1;  // fill rule (see setup.h)
    p.dcdx = dcdx * kSubpixelOne;
    p.dcdy = dcdy * kSubpixelOne;
    p.eo = (p.dcdx < 0 ? -static_cast<std::int64_t>(p.dcdx) : 0) + (p.dcdy > 0 ? p.dcdy : 0);
  }
  int n = 3;
  // Scissor planes where the box passes the draw region (the left and bottom borders are at 0,
  // where the box was clamped, so only the right and top ones can be needed).
  if (box.x1 > region.x1) {
    out.planes[static_cast<std::size_t>(n++)] =
        EdgePlane{static_cast<std::int64_t>(region.x1) * kSubpixelOne + 127, kSubpixelOne, 0, 0};
  }
  if (box.y1 > region.y1) {
    out.planes[static_cast<std::size_t>(n++)] =
        EdgePlane{static_cast<std::int64_t>(region.y1) * kSubpixelOne + 127, 0, -kSubpixelOne, 0};
  }
  out.num_planes = n;

  const auto& v = triangle.v;
  out.depth = depth_plane(v[static_cast<std::size_t>(order[0])], v[static_cast<std::size_t>(order[1])],
                          v[static_cast<std::size_t>(order[2])]);
  out.front_facing = front;
  counters.accepted += 1;
  return SetupResult::Accepted;
}

}  // namespace nbsim::raster

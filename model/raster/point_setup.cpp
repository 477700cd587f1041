// Point setup as llvmpipe does it for point sprites: size clamp, snapping (round half away from
// zero), the square's four planes with the fill rule, the box against the render target, and the
// constant depth plane. See point_setup.h for the Mesa sources matched.
#include "model/raster/point_setup.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "model/common/error.h"

namespace nbsim::raster {

namespace {

constexpr int kMaxTargetPx = 16384;
// Window coordinates whose snap stays far from int32 overflow (the square adds at most 255 px).
constexpr float kMaxPointCoordinatePx = 4194304.0f;  // 2^22 px

}  // namespace

std::int32_t snap_point_coordinate(float window_coordinate) noexcept {
  const float f = window_coordinate * static_cast<float>(kSubpixelOne);
  // util_iround's portable branch: the sum is a float, then truncated toward zero.
  return f >= 0.0f ? static_cast<std::int32_t>(f + 0.5f) : static_cast<std::int32_t>(f - 0.5f);
}

std::int32_t point_width_fixed(float size) noexcept {
  if (size > kMaxPointSizePx) size = kMaxPointSizePx;  // NaN is refused before (geometry stage)
  return std::max<std::int32_t>(kSubpixelOne, snap_point_coordinate(size));
}

PointSetup::PointSetup(const SetupConfig& config) : config_(config) {
  if (config.width_px < 1 || config.width_px > kMaxTargetPx || config.height_px < 1 || config.height_px > kMaxTargetPx)
    throw InputError("point setup: render target " + std::to_string(config.width_px) + "x" +
                     std::to_string(config.height_px) + " is outside 1x1 .. 16384x16384");
}

SetupResult PointSetup::setup(const geometry::WindowPoint& point, SetupTriangle& out, SetupCounters& counters) const {
  counters.points += 1;
  const geometry::WindowVertex& v = point.v;
  if (!(std::fabs(v.x) < kMaxPointCoordinatePx && std::fabs(v.y) < kMaxPointCoordinatePx && std::isfinite(v.z))) {
    counters.unsupported += 1;
    return SetupResult::Unsupported;
  }
  const std::int32_t w = point_width_fixed(point.size);
  // pixel_offset 0.5 is subtracted in float before the snap, as llvmpipe does.
  const std::int32_t x0 = snap_point_coordinate(v.x - 0.5f) - w / 2;
  const std::int32_t y0 = snap_point_coordinate(v.y - 0.5f) - w / 2;
  const std::int32_t x1 = x0 + w, y1 = y0 + w;

  PixelBox box;
  box.x0 = x0 >> kSubpixelBits;
  box.x1 = ((x1 + (kSubpixelOne - 1)) >> kSubpixelBits) - 1;
  box.y0 = y0 >> kSubpixelBits;
  box.y1 = ((y1 + (kSubpixelOne - 1)) >> kSubpixelBits) - 1;
  const PixelBox region{0, 0, config_.width_px - 1, config_.height_px - 1};
  if (box.x0 > region.x1 || box.x1 < region.x0 || box.y0 > region.y1 || box.y1 < region.y0) {
    counters.offscreen += 1;
    return SetupResult::Offscreen;
  }
  box = {std::max(box.x0, region.x0), std::max(box.y0, region.y0), std::min(box.x1, region.x1),
         std::min(box.y1, region.y1)};
  out.bbox = box;
  out.trimmed = box;

  // E = c - dcdx x + dcdy y > 0 inside (setup.h EdgePlane); eo as llvmpipe sets it.
  const auto fixed = [](int px) { return static_cast<std::int64_t>(px) * kSubpixelOne; };
  out.planes[0] = EdgePlane{-std::max<std::int64_t>(x0, fixed(box.x0)) + 1, -kSubpixelOne, 0, kSubpixelOne};
  out.planes[1] = EdgePlane{std::min<std::int64_t>(x1, fixed(box.x1 + 1)), kSubpixelOne, 0, 0};
  out.planes[2] = EdgePlane{-std::max<std::int64_t>(y0, fixed(box.y0)) + 1, 0, kSubpixelOne, kSubpixelOne};
  out.planes[3] = EdgePlane{std::min<std::int64_t>(y1, fixed(box.y1 + 1)), 0, -kSubpixelOne, 0};
  out.num_planes = 4;
  out.depth = DepthPlane{v.z, 0.0f, 0.0f};
  out.front_facing = true;
  counters.accepted += 1;
  return SetupResult::Accepted;
}

}  // namespace nbsim::raster

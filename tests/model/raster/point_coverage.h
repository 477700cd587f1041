// Test helpers for point sprites: the model's per-pixel fragments and passed samples of one point
// draw (geometry -> point setup -> rasterizer -> early depth test, pixel by pixel), and a
// reference that states llvmpipe's point rule independently in double arithmetic: the square of
// side max(1, min(size, 255)) px, snapped to 1/256 px with ties away from zero, owns the pixel
// centres on its left and bottom edges and not those on its right and top edges.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "model/common/depth.h"
#include "model/geometry/geometry.h"
#include "model/raster/depth_test.h"
#include "model/raster/point_setup.h"
#include "model/raster/rasterizer.h"

namespace nbsim::raster::testing {

// Per-pixel results of one point draw through the model (y up, row-major).
struct PointDrawResult {
  std::vector<std::uint32_t> fragments, passed;
  geometry::GeometryCounters geometry;
  SetupCounters setup;
  DepthCounters depth;
  int outside = 0;  // reported pixels outside the target (must stay 0)
};

// Runs one point draw through the cores on `depth` (tested and written), one pixel at a time so
// that each pixel's passed samples are known.
inline PointDrawResult model_point_draw(std::span<const geometry::ClipPosition> clip, std::span<const float> sizes,
                                        const geometry::GeometryState& gstate, const DepthState& dstate,
                                        DepthImage& depth) {
  const int w = depth.width, h = depth.height;
  PointDrawResult r;
  r.fragments.assign(static_cast<std::size_t>(w * h), 0);
  r.passed.assign(static_cast<std::size_t>(w * h), 0);
  const geometry::GeometryStage geo({w, h, 85, true});
  std::vector<geometry::WindowPoint> points;
  geo.process_points(clip, sizes, gstate, points, r.geometry);
  const PointSetup setup(SetupConfig{w, h});
  const Rasterizer raster(w, h);
  EarlyDepthTest test(depth);
  TileCounters tiles;
  SetupTriangle s;
  for (const geometry::WindowPoint& p : points) {
    if (setup.setup(p, s, r.setup) != SetupResult::Accepted) continue;
    raster.rasterize(s, tiles, [&](int x, int y, std::uint16_t mask) {
      for (int i = 0; i < 16; ++i) {
        if (!(mask & (1u << i))) continue;
        const int px = x + (i & 3), py = y + (i >> 2);
        if (px < 0 || py < 0 || px >= w || py >= h) {
          ++r.outside;
          continue;
        }
        const std::uint64_t before = r.depth.passed;
        test.test_block(s.depth, x, y, static_cast<std::uint16_t>(1u << i), dstate, r.depth);
        const std::size_t at = static_cast<std::size_t>(py * w + px);
        r.fragments[at] += 1;
        r.passed[at] += static_cast<std::uint32_t>(r.depth.passed - before);
      }
    });
  }
  return r;
}

// Reference: does the point at window (x, y) with gl_PointSize `size` cover pixel (px, py)?
inline bool reference_point_covers(float x, float y, float size, int px, int py) {
  const auto snap = [](double v) { return static_cast<std::int64_t>(std::round(v * 256.0)); };  // half away
  const double s = std::isnan(size) ? 1.0 : std::min(static_cast<double>(size), 255.0);
  const std::int64_t width = std::max<std::int64_t>(256, snap(s));
  const std::int64_t left = snap(static_cast<double>(x - 0.5f)) - width / 2;
  const std::int64_t bottom = snap(static_cast<double>(y - 0.5f)) - width / 2;
  const std::int64_t cx = static_cast<std::int64_t>(px) * 256, cy = static_cast<std::int64_t>(py) * 256;
  return left <= cx && cx < left + width && bottom <= cy && cy < bottom + width;
}

}  // namespace nbsim::raster::testing

// Test helpers of the raster suites: window-space triangles through setup and the traversal into a
// per-pixel coverage count, and a brute-force reference that states llvmpipe's coverage rule
// independently: snap to 1/256 pixel (round half to even) relative to pixel centres; a centre is
// covered when it lies strictly inside every edge, or exactly on an edge whose inward normal points
// to +x, or to +y for a horizontal edge (the bottom-left rule of a y-up target).
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "model/geometry/primitive.h"
#include "model/raster/rasterizer.h"
#include "model/raster/setup.h"

namespace nbsim::raster::testing {

using geometry::CullFace;
using geometry::FaceState;
using geometry::WindowTriangle;
using geometry::WindowVertex;

inline WindowTriangle tri(float x0, float y0, float x1, float y1, float x2, float y2, float z = 0.5f) {
  return WindowTriangle{{WindowVertex{x0, y0, z, 1.0f}, WindowVertex{x1, y1, z, 1.0f}, WindowVertex{x2, y2, z, 1.0f}}};
}

constexpr FaceState kNoCull{CullFace::None, true};

// Per-pixel coverage counts of window-space triangles through setup and the traversal.
struct Coverage {
  int width = 0, height = 0;
  std::vector<int> count;
  TileCounters tiles;
  SetupCounters setup;
  int outside = 0;  // reports outside the target (must stay 0)
  int at(int x, int y) const { return count[static_cast<std::size_t>(y * width + x)]; }
  long total() const {
    long t = 0;
    for (int c : count) t += c;
    return t;
  }
};

inline Coverage cover(const std::vector<WindowTriangle>& tris, int w, int h, FaceState face = kNoCull) {
  Coverage c;
  c.width = w;
  c.height = h;
  c.count.assign(static_cast<std::size_t>(w * h), 0);
  const TriangleSetup setup(SetupConfig{w, h});
  const Rasterizer raster(w, h);
  SetupTriangle s;
  for (const WindowTriangle& t : tris) {
    if (setup.setup(t, face, s, c.setup) != SetupResult::Accepted) continue;
    raster.rasterize(s, c.tiles, [&](int x, int y, std::uint16_t mask) {
      for (int i = 0; i < 16; ++i) {
        if (!(mask & (1u << i))) continue;
        const int px = x + (i & 3), py = y + (i >> 2);
        if (px < 0 || py < 0 || px >= w || py >= h) {
          ++c.outside;
          continue;
        }
        ++c.count[static_cast<std::size_t>(py * w + px)];
      }
    });
  }
  return c;
}

inline std::int64_t ref_snap(float v) {
  return static_cast<std::int64_t>(std::nearbyint(static_cast<double>((v - 0.5f) * 256.0f)));
}

inline bool reference_covers(const WindowTriangle& t, int px, int py) {
  std::int64_t X[3], Y[3];
  for (int i = 0; i < 3; ++i) {
    X[i] = ref_snap(t.v[static_cast<std::size_t>(i)].x);
    Y[i] = ref_snap(t.v[static_cast<std::size_t>(i)].y);
  }
  const std::int64_t Px = static_cast<std::int64_t>(px) * 256, Py = static_cast<std::int64_t>(py) * 256;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    const std::int64_t dx = X[j] - X[i], dy = Y[j] - Y[i];
    const std::int64_t side_c = dx * (Y[k] - Y[i]) - dy * (X[k] - X[i]);
    if (side_c == 0) return false;  // no area
    const std::int64_t side_p = dx * (Py - Y[i]) - dy * (Px - X[i]);
    if (side_p != 0) {
      if ((side_p > 0) != (side_c > 0)) return false;
      continue;
    }
    // On the edge: owned when the inward normal points to +x, or to +y on a horizontal edge.
    std::int64_t nx = -dy, ny = dx;  // left normal of the edge
    if (side_c < 0) nx = -nx, ny = -ny;
    if (!(nx > 0 || (nx == 0 && ny > 0))) return false;
  }
  return true;
}

}  // namespace nbsim::raster::testing

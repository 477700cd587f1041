// The exact crossing reference; see crossings.h.
#include "model/mesh/crossings.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "model/common/error.h"

namespace nbsim::mesh {
namespace {

__extension__ typedef __int128 Wide;

// Bits of the snapped view-plane grid: corners within 2^40 grid steps of the origin, so edge
// function products stay below 2^84 (fixed by the 128-bit arithmetic, with room to spare).
constexpr int kGridBits = 40;

double dot(const Vec3d& a, const Vec3d& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3d cross(const Vec3d& a, const Vec3d& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
bool finite(const Vec3d& a) { return std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]); }
Vec3d widen(const Vec3f& p) { return {p[0], p[1], p[2]}; }

// The edge function of the edge a -> b at q: positive when q is to its left (y up). Exact.
Wide edge(std::int64_t ax, std::int64_t ay, std::int64_t bx, std::int64_t by, std::int64_t qx, std::int64_t qy) {
  return Wide(bx - ax) * Wide(qy - ay) - Wide(by - ay) * Wide(qx - ax);
}

// The tie rule: the sign an exactly-zero edge function takes, i.e. its sign after moving q by
// (+e, +e^2): inside (+1) when the edge a -> b runs downward, or exactly horizontal rightward.
// llvmpipe's rule as measured on GL (LdiPeelTest.BoxEdgesOnTexelCentresFollowTheTieRule: a box
// whose edges lie on texel centres): its top-left rule works in y-down window coordinates whose row
// 0 is an FBO's bottom row, which is a bottom-left rule in the view plane's y-up coordinates.
int tie_sign(std::int64_t dx, std::int64_t dy) { return (dy < 0 || (dy == 0 && dx > 0)) ? 1 : -1; }

}  // namespace

OrthoFrame OrthoFrame::look_along(const Vec3d& direction, const Vec3d& up_hint) {
  const double n = std::sqrt(dot(direction, direction));
  if (!finite(direction) || !(n > 0.0) || !std::isfinite(n))
    throw InputError(fmt::format("view direction ({}, {}, {}) is zero or not finite", direction[0], direction[1],
                                 direction[2]));
  OrthoFrame f;
  f.direction = {direction[0] / n, direction[1] / n, direction[2] / n};
  Vec3d r = cross(f.direction, up_hint);
  const double rn = std::sqrt(dot(r, r));
  if (!(rn > 1e-12) || !finite(up_hint))
    throw InputError(fmt::format("view direction ({}, {}, {}) is parallel to the up hint ({}, {}, {})",
                                 direction[0], direction[1], direction[2], up_hint[0], up_hint[1], up_hint[2]));
  f.right = {r[0] / rn, r[1] / rn, r[2] / rn};
  f.up = cross(f.right, f.direction);
  return f;
}

CrossingReference::CrossingReference(const TriMesh& m, const OrthoFrame& frame) : frame_(frame) {
  if (!finite(frame.direction) || !finite(frame.right) || !finite(frame.up))
    throw InputError("crossing reference: the view frame is not finite");
  double extent = 0.0;
  for (const Vec3f& p : m.vertices) {
    const Vec3d d = widen(p);
    if (!finite(d)) throw InputError("crossing reference: the mesh has a non-finite vertex");
    extent = std::max({extent, std::abs(dot(d, frame.right)), std::abs(dot(d, frame.up))});
  }
  for (const Tri& t : m.triangles)
    for (std::uint32_t i : t)
      if (i >= m.vertices.size()) throw InputError("crossing reference: the mesh has an out-of-range vertex index");
  // A power of two, so snapping is one exact multiplication and a rounding.
  scale_ = extent > 0.0 ? std::ldexp(1.0, kGridBits - (std::ilogb(extent) + 1)) : 1.0;

  lo_x_ = lo_y_ = INT64_MAX;
  hi_x_ = hi_y_ = INT64_MIN;
  tris_.reserve(m.triangles.size());
  for (const Tri& t : m.triangles) {
    Projected p{};
    for (int k = 0; k < 3; ++k) {
      const Vec3d d = widen(m.vertices[t[k]]);
      snap(d, p.x[k], p.y[k]);
      p.depth[k] = dot(d, frame.direction);
    }
    if (edge(p.x[0], p.y[0], p.x[1], p.y[1], p.x[2], p.y[2]) == 0) continue;  // edge-on: counts 0
    for (int k = 0; k < 3; ++k) {
      lo_x_ = std::min(lo_x_, p.x[k]), hi_x_ = std::max(hi_x_, p.x[k]);
      lo_y_ = std::min(lo_y_, p.y[k]), hi_y_ = std::max(hi_y_, p.y[k]);
    }
    tris_.push_back(p);
  }
  if (tris_.empty()) return;

  // A uniform grid of about sqrt(triangles) cells a side over the projected bounds; each triangle
  // is listed in every cell its bounding rectangle touches (corners included).
  const auto side = static_cast<std::int64_t>(std::clamp(std::sqrt(double(tris_.size())), 1.0, 1024.0));
  cell_ = std::max<std::int64_t>(1, (std::max(hi_x_ - lo_x_, hi_y_ - lo_y_) + side) / side);
  cells_x_ = (hi_x_ - lo_x_) / cell_ + 1;
  cells_y_ = (hi_y_ - lo_y_) / cell_ + 1;
  std::vector<std::uint32_t> counts(static_cast<std::size_t>(cells_x_ * cells_y_) + 1, 0);
  auto for_cells = [&](const Projected& p, auto&& fn) {
    const std::int64_t x0 = (std::min({p.x[0], p.x[1], p.x[2]}) - lo_x_) / cell_;
    const std::int64_t x1 = (std::max({p.x[0], p.x[1], p.x[2]}) - lo_x_) / cell_;
    const std::int64_t y0 = (std::min({p.y[0], p.y[1], p.y[2]}) - lo_y_) / cell_;
    const std::int64_t y1 = (std::max({p.y[0], p.y[1], p.y[2]}) - lo_y_) / cell_;
    for (std::int64_t cy = y0; cy <= y1; ++cy)
      for (std::int64_t cx = x0; cx <= x1; ++cx) fn(static_cast<std::size_t>(cy * cells_x_ + cx));
  };
  for (const Projected& p : tris_) for_cells(p, [&](std::size_t c) { ++counts[c + 1]; });
  for (std::size_t c = 1; c < counts.size(); ++c) counts[c] += counts[c - 1];
  cell_start_ = counts;
  cell_tris_.resize(counts.back());
  for (std::size_t i = 0; i < tris_.size(); ++i)
    for_cells(tris_[i], [&](std::size_t c) { cell_tris_[counts[c]++] = static_cast<std::uint32_t>(i); });
}

bool CrossingReference::snap(const Vec3d& p, std::int64_t& x, std::int64_t& y) const {
  const double sx = dot(p, frame_.right) * scale_, sy = dot(p, frame_.up) * scale_;
  // Beyond 2^62 the line is far outside every corner (which lie within 2^40): no crossings.
  constexpr double kLimit = 4.6e18;
  if (!(std::abs(sx) < kLimit && std::abs(sy) < kLimit)) return false;
  x = static_cast<std::int64_t>(std::nearbyint(sx));
  y = static_cast<std::int64_t>(std::nearbyint(sy));
  return true;
}

std::vector<double> CrossingReference::crossing_depths(const Vec3d& point) const {
  if (!finite(point)) throw InputError("crossing reference: the query point is not finite");
  std::vector<double> depths;
  std::int64_t qx = 0, qy = 0;
  if (tris_.empty() || !snap(point, qx, qy)) return depths;
  if (qx < lo_x_ || qx > hi_x_ || qy < lo_y_ || qy > hi_y_) return depths;
  const auto c = static_cast<std::size_t>(((qy - lo_y_) / cell_) * cells_x_ + (qx - lo_x_) / cell_);
  for (std::uint32_t k = cell_start_[c]; k < cell_start_[c + 1]; ++k) {
    const Projected& p = tris_[cell_tris_[k]];
    Wide w[3];
    int sign[3];
    for (int i = 0; i < 3; ++i) {
      // w[i]: the edge opposite corner i, walked in the triangle's order.
      const int a = (i + 1) % 3, b = (i + 2) % 3;
      w[i] = edge(p.x[a], p.y[a], p.x[b], p.y[b], qx, qy);
      sign[i] = w[i] > 0 ? 1 : w[i] < 0 ? -1 : tie_sign(p.x[b] - p.x[a], p.y[b] - p.y[a]);
    }
    if (sign[0] != sign[1] || sign[1] != sign[2]) continue;
    const long double sum = static_cast<long double>(w[0] + w[1] + w[2]);
    long double t = 0.0L;
    for (int i = 0; i < 3; ++i) t += static_cast<long double>(w[i]) / sum * p.depth[i];
    depths.push_back(static_cast<double>(t));
  }
  std::sort(depths.begin(), depths.end());
  return depths;
}

CrossingCount CrossingReference::count(const Vec3d& point) const {
  const std::vector<double> depths = crossing_depths(point);
  const double d = dot(point, frame_.direction);
  CrossingCount c;
  for (double t : depths) {
    if (t < d) ++c.in_front;
    else if (t > d) ++c.beyond;
    else ++c.at_point;
    c.nearest_distance = std::min(c.nearest_distance, std::abs(t - d));
  }
  return c;
}

}  // namespace nbsim::mesh

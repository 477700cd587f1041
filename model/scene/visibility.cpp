// Visibility on the frame's scene; see visibility.h.
#include "model/scene/visibility.h"

#include <algorithm>
#include <cmath>

namespace nbsim::scene {

namespace {

std::array<double, 3> corner(const Aabb& b, int i) {
  return {static_cast<double>(i & 1 ? b.hi[0] : b.lo[0]), static_cast<double>(i & 2 ? b.hi[1] : b.lo[1]),
          static_cast<double>(i & 4 ? b.hi[2] : b.lo[2])};
}

}  // namespace

FrameView FrameView::make(const FrameBegin& f, int width_px, int height_px, double near_m, double nearest_margin,
                          bool zero_to_one, bool reversed) {
  FrameView v;
  // proj * view column by column, as glm's mat4 product does it in float (no fused operations:
  // the renderer's host code is built for baseline x86-64): col c = sum_k proj.col(k) * view[c][k].
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      const auto at = [](const std::array<float, 16>& m, int col, int row) { return m[static_cast<std::size_t>(col * 4 + row)]; };
      const float p0 = at(f.proj, 0, r) * at(f.view, c, 0);
      const float p1 = at(f.proj, 1, r) * at(f.view, c, 1);
      const float p2 = at(f.proj, 2, r) * at(f.view, c, 2);
      const float p3 = at(f.proj, 3, r) * at(f.view, c, 3);
      v.view_proj[static_cast<std::size_t>(c * 4 + r)] = ((p0 + p1) + p2) + p3;
    }
  }
  for (std::size_t i = 0; i < 16; ++i) v.view_proj_d[i] = static_cast<double>(v.view_proj[i]);
  v.width_px = width_px;
  v.height_px = height_px;
  v.near_m = near_m;
  v.nearest_margin = nearest_margin;
  v.zero_to_one = zero_to_one;
  v.reversed = reversed;
  return v;
}

BoundsTest bounds_test(const Aabb& b, const FrameView& v) {
  BoundsTest t;
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  double nearest = v.reversed ? -INFINITY : INFINITY;
  const auto& m = v.view_proj_d;
  for (int i = 0; i < 8; ++i) {
    const auto p = corner(b, i);
    std::array<double, 4> c{};
    for (std::size_t r = 0; r < 4; ++r) c[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
    // A NaN or infinite corner or matrix (a damaged trace) has no place on screen: treated as
    // crossing the near plane, so the bounds are never culled and nothing non-finite reaches the
    // integer rectangle below.
    if (!std::all_of(c.begin(), c.end(), [](double x) { return std::isfinite(x); }) || c[3] < v.near_m * 0.999) {
      t.crosses_near = true;
      continue;
    }
    const double x = (c[0] / c[3] * 0.5 + 0.5) * v.width_px, y = (c[1] / c[3] * 0.5 + 0.5) * v.height_px;
    const double z = v.zero_to_one ? c[2] / c[3] : c[2] / c[3] * 0.5 + 0.5;
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    nearest = v.reversed ? std::max(nearest, z) : std::min(nearest, z);
  }
  if (t.crosses_near) {  // never culled: the whole viewport at the nearest possible depth
    t.x = 0, t.y = 0, t.w = v.width_px, t.h = v.height_px;
    t.nearest_depth = v.reversed ? 1.0f : 0.0f;
    return t;
  }
  // Clamped in double first: a corner far outside the viewport (or x / w overflowing to infinity)
  // must not be converted to int out of its range.
  const auto pixel = [](double x, int hi) { return static_cast<int>(std::clamp(x, 0.0, static_cast<double>(hi))); };
  const int ix0 = pixel(std::floor(x0), v.width_px), iy0 = pixel(std::floor(y0), v.height_px);
  const int ix1 = pixel(std::ceil(x1), v.width_px), iy1 = pixel(std::ceil(y1), v.height_px);
  t.x = ix0, t.y = iy0, t.w = std::max(0, ix1 - ix0), t.h = std::max(0, iy1 - iy0);
  const double margin = v.reversed ? nearest + v.nearest_margin : nearest - v.nearest_margin;
  t.nearest_depth = static_cast<float>(std::clamp(margin, 0.0, 1.0));
  return t;
}

void box_clip_positions(const Aabb& b, const FrameView& v, std::vector<std::array<float, 4>>& out) {
  std::array<std::array<float, 4>, 8> corners{};
  const auto& m = v.view_proj;
  for (int i = 0; i < 8; ++i) {
    const float px = i & 1 ? b.hi[0] : b.lo[0], py = i & 2 ? b.hi[1] : b.lo[1], pz = i & 4 ? b.hi[2] : b.lo[2];
    for (std::size_t r = 0; r < 4; ++r) {
      // mat4 * vec4(p, 1) as a sum of columns, in float, in column order.
      const float s = ((m[r] * px + m[4 + r] * py) + m[8 + r] * pz) + m[12 + r];
      corners[static_cast<std::size_t>(i)][r] = s;
    }
  }
  out.clear();
  for (std::uint8_t i : kBoxIndices) out.push_back(corners[i]);
}

bool outside_frustum(const Aabb& b, const FrameView& v) {
  const auto& m = v.view_proj_d;
  const auto row = [&](int r) { return std::array<double, 4>{m[static_cast<std::size_t>(r)], m[static_cast<std::size_t>(4 + r)],
                                                             m[static_cast<std::size_t>(8 + r)], m[static_cast<std::size_t>(12 + r)]}; };
  const auto r0 = row(0), r1 = row(1), r2 = row(2), r3 = row(3);
  std::array<std::array<double, 4>, 6> planes{};
  for (std::size_t k = 0; k < 4; ++k) {
    planes[0][k] = r3[k] + r0[k];
    planes[1][k] = r3[k] - r0[k];
    planes[2][k] = r3[k] + r1[k];
    planes[3][k] = r3[k] - r1[k];
    planes[4][k] = v.zero_to_one ? r2[k] : r3[k] + r2[k];
    planes[5][k] = r3[k] - r2[k];
  }
  for (const auto& p : planes) {
    const double x = p[0] >= 0 ? b.hi[0] : b.lo[0], y = p[1] >= 0 ? b.hi[1] : b.lo[1], z = p[2] >= 0 ? b.hi[2] : b.lo[2];
    if (p[0] * x + p[1] * y + p[2] * z + p[3] < 0) return true;
  }
  return false;
}

std::vector<std::uint32_t> frustum_objects(const SceneObjects& s, const FrameView& v) {
  std::vector<std::uint32_t> out;
  if (s.node_bounds.empty()) {  // no BVH: test every object
    for (std::size_t o = 0; o < s.objects.size(); ++o)
      if (!outside_frustum(s.objects[o], v)) out.push_back(static_cast<std::uint32_t>(o));
    return out;
  }
  std::vector<std::int32_t> stack{0};
  while (!stack.empty()) {
    const auto n = static_cast<std::size_t>(stack.back());
    stack.pop_back();
    if (outside_frustum(s.node_bounds[n], v)) continue;
    if (s.node_left[n] < 0) {
      for (std::uint32_t i = s.node_first[n]; i < s.node_first[n] + s.node_count[n]; ++i)
        if (!outside_frustum(s.objects[s.leaf_objects[i]], v)) out.push_back(s.leaf_objects[i]);
    } else {
      stack.push_back(s.node_left[n]);
      stack.push_back(s.node_right[n]);
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<char> find_visible(const SceneObjects& s, const FrameView& v, const std::vector<std::uint32_t>& in_frustum,
                               const std::vector<char>& is_occluder, bool hier, const BatchTester& tester) {
  std::vector<char> visible(s.objects.size(), 0);
  std::vector<TestItem> items;
  std::vector<BoundsTest> tests;
  if (!hier || s.node_bounds.empty()) {
    for (auto o : in_frustum)
      if (!is_occluder[o]) items.push_back({static_cast<std::int32_t>(o), -1});
    for (const TestItem& it : items) tests.push_back(bounds_test(s.objects[static_cast<std::size_t>(it.object)], v));
    if (!items.empty()) tester(items, tests);
    for (std::size_t i = 0; i < items.size(); ++i) visible[static_cast<std::size_t>(items[i].object)] = tests[i].visible;
    return visible;
  }
  std::vector<TestItem> batch{{-1, 0}}, next;
  while (!batch.empty()) {
    next.clear();
    items.clear();
    tests.clear();
    for (const TestItem& it : batch) {
      const Aabb& b = it.node >= 0 ? s.node_bounds[static_cast<std::size_t>(it.node)] : s.objects[static_cast<std::size_t>(it.object)];
      if (outside_frustum(b, v)) continue;
      if (it.node < 0 && is_occluder[static_cast<std::size_t>(it.object)]) continue;
      items.push_back(it);
      tests.push_back(bounds_test(b, v));
    }
    if (!items.empty()) tester(items, tests);
    for (std::size_t i = 0; i < items.size(); ++i) {
      if (!tests[i].visible) continue;
      const TestItem it = items[i];
      if (it.node < 0) {
        visible[static_cast<std::size_t>(it.object)] = 1;
        continue;
      }
      const auto n = static_cast<std::size_t>(it.node);
      if (s.node_left[n] >= 0) {
        next.push_back({-1, s.node_left[n]});
        next.push_back({-1, s.node_right[n]});
      } else {
        for (std::uint32_t k = s.node_first[n]; k < s.node_first[n] + s.node_count[n]; ++k)
          next.push_back({static_cast<std::int32_t>(s.leaf_objects[k]), -1});
      }
    }
    std::swap(batch, next);
  }
  return visible;
}

double distance_to(const Aabb& b, const glm::dvec3& p) {
  double sum = 0.0;
  for (std::size_t k = 0; k < 3; ++k) {
    const double out = std::max({0.0, static_cast<double>(b.lo[k]) - p[static_cast<int>(k)], p[static_cast<int>(k)] - static_cast<double>(b.hi[k])});
    sum += out * out;
  }
  return std::sqrt(sum);
}

}  // namespace nbsim::scene

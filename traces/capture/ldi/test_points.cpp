// Test points and their exact reference; see test_points.h.
#include "traces/capture/ldi/test_points.h"

#include <cmath>
#include <random>

#include "traces/format/ldi/ldi_chunk.h"

namespace nbsim::capture {
namespace {

float step_ulps(float z, int ulps) {
  for (; ulps > 0; --ulps) z = std::nextafter(z, 2.0f);
  for (; ulps < 0; ++ulps) z = std::nextafter(z, -1.0f);
  return z;
}

}  // namespace

LdiTestPoints make_test_points(const ldi::Ldi& l, const Rect& crop, int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed ^ 0x1D1u);
  const int w = l.width(), h = l.height();
  std::vector<std::int32_t> with_layers, with_two;  // texel numbers
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (l.count(x, y) >= 1) with_layers.push_back(y * w + x);
      if (l.count(x, y) >= 2) with_two.push_back(y * w + x);
    }
  auto uniform_int = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };  // inclusive
  auto uniform_z = [&] { return std::uniform_real_distribution<float>(0.0f, 1.0f)(rng); };
  auto pick = [&](const std::vector<std::int32_t>& texels) { return texels[static_cast<std::size_t>(uniform_int(0, static_cast<int>(texels.size()) - 1))]; };

  LdiTestPoints p;
  for (int i = 0; i < count; ++i) {
    const auto kind = static_cast<trace::LdiPointKind>(i % trace::kLdiPointKinds);
    int x = uniform_int(0, w - 1), y = uniform_int(0, h - 1);
    float z = uniform_z();
    switch (kind) {
      case trace::LdiPointKind::Random: break;
      case trace::LdiPointKind::CropBoundary:
        if (!crop.empty()) {
          // One of the four sides, at distance 0 (on the border texel) or 1 (just outside).
          const int side = uniform_int(0, 3), out = uniform_int(0, 1);
          x = uniform_int(crop.x - 1, crop.x1());
          y = uniform_int(crop.y - 1, crop.y1());
          if (side == 0) x = crop.x - out;
          if (side == 1) x = crop.x1() - 1 + out;
          if (side == 2) y = crop.y - out;
          if (side == 3) y = crop.y1() - 1 + out;
        }
        break;
      case trace::LdiPointKind::NearSurface:
        if (!with_layers.empty()) {
          const int t = pick(with_layers);
          x = t % w, y = t / w;
          const float layer = l.depth(x, y, uniform_int(0, l.count(x, y) - 1));
          z = step_ulps(layer, uniform_int(-3, 3));
          if (!(z >= 0.0f && z <= 1.0f)) z = layer;
        }
        break;
      case trace::LdiPointKind::Midway:
        if (!with_two.empty()) {
          const int t = pick(with_two);
          x = t % w, y = t / w;
          const int k = uniform_int(0, l.count(x, y) - 2);
          z = 0.5f * (l.depth(x, y, k) + l.depth(x, y, k + 1));
        }
        break;
    }
    p.kind.push_back(static_cast<std::uint32_t>(kind));
    p.x.push_back(x);
    p.y.push_back(y);
    p.z.push_back(z);
  }
  return p;
}

std::vector<std::int32_t> reference_crossings(const mesh::CrossingReference& ref, const OrthoMapping& map,
                                              const LdiTestPoints& p, double epsilon) {
  std::vector<std::int32_t> out(p.x.size());
  const mesh::Vec3d& d = map.frame.direction;
  for (std::size_t i = 0; i < p.x.size(); ++i) {
    mesh::Vec3d q = map.texel_line_point(p.x[i], p.y[i]);  // at depth t0
    const double along = double(p.z[i]) * (map.t1 - map.t0);
    for (int a = 0; a < 3; ++a) q[a] += along * d[a];
    const mesh::CrossingCount c = ref.count(q);
    out[i] = c.nearest_distance <= epsilon ? trace::kLdiNearSurface : static_cast<std::int32_t>(c.beyond);
  }
  return out;
}

}  // namespace nbsim::capture

// Test support for the relief field tests: a seeded generator (splitmix64, the same numbers with
// every standard library), random heightfields, the box clip of a ray and the dense-sampling
// brute force of the height above the surface along a ray (heightfield.h's conventions).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <utility>

#include "model/relief/heightfield.h"

namespace nbsim::relief::test_support {

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  int below(int n) { return static_cast<int>(next() % static_cast<std::uint64_t>(n)); }

 private:
  std::uint64_t state_;
};

// N x N heights: mostly uniform in [0, 1], a few exactly 0 or 1 (plateaus, the border's level).
inline Heightfield random_field(int n, Rng& rng) {
  Heightfield f;
  f.size = n;
  f.heights.resize(static_cast<std::size_t>(n) * n);
  for (float& h : f.heights) {
    const int kind = rng.below(8);
    h = kind == 0 ? 0.0f : kind == 1 ? 1.0f : static_cast<float>(rng.uniform());
  }
  return f;
}

// The ray's parameter interval inside the box [0, N]^2 x [0, 1] (slabs), from t >= 0.
inline std::optional<std::pair<double, double>> box_interval(int n, const std::array<double, 3>& o, const std::array<double, 3>& d) {
  double t0 = 0.0, t1 = 1e30;
  const std::array<double, 3> hi = {static_cast<double>(n), static_cast<double>(n), 1.0};
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) {
      if (o[a] < 0.0 || o[a] > hi[a]) return std::nullopt;
      continue;
    }
    double ta = (0.0 - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 > t1) return std::nullopt;
  return std::make_pair(t0, t1);
}

// The height of the ray above the surface at t.
inline double above(const Heightfield& f, const std::array<double, 3>& o, const std::array<double, 3>& d, double t) {
  return o[2] + t * d[2] - surface_height(f, o[0] + t * d[0], o[1] + t * d[1]);
}

}  // namespace nbsim::relief::test_support

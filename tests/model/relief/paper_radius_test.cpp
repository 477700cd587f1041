// ReliefPaperRadiusTest: the paper's safety radius (paper_radius.h) by brute force: with the
// minimum over directions and epsilon 0, no unblocked ray from a texel's square passes under the
// surface and out again within the radius; the paper's maximum over directions lets such rays
// through; a larger epsilon never lowers a radius, and a ray that passes under by more than epsilon
// comes out only beyond it; planes keep the cap; bad options are refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "model/relief/heightfield.h"
#include "model/relief/paper_radius.h"
#include "tests/model/relief/relief_brute_force.h"

namespace {

using namespace nbsim::relief;
using nbsim::relief::test_support::random_field;
using nbsim::relief::test_support::Rng;

// A ray over a texel's square: start (x, y), horizontal direction (dx, dy), height z0 + slope * s at
// horizontal distance s (negative behind the start).
struct Ray {
  double x, y, dx, dy, z0, slope;
  double g(const Heightfield& f, double s) const { return surface_height(f, x + s * dx, y + s * dy); }
  double above(const Heightfield& f, double s) const { return z0 + slope * s - g(f, s); }
};

// True when the ray is above the surface everywhere behind its start, back to the field's square.
bool unblocked(const Heightfield& f, const Ray& r) {
  const double n = f.size;
  double behind = 1e30;
  if (r.dx > 0.0) behind = std::min(behind, r.x / r.dx);
  if (r.dx < 0.0) behind = std::min(behind, (n - r.x) / -r.dx);
  if (r.dy > 0.0) behind = std::min(behind, r.y / r.dy);
  if (r.dy < 0.0) behind = std::min(behind, (n - r.y) / -r.dy);
  for (int k = 0; k <= 2000; ++k)
    if (r.above(f, -behind * k / 2000.0) <= 0.0) return false;
  return true;
}

// True when the ray passes under the surface by more than `depth` and is above it again within
// horizontal distance `distance` (densely sampled).
bool under_and_out(const Heightfield& f, const Ray& r, double distance, double depth) {
  bool deep = false;
  for (int k = 1; k <= 2000; ++k) {
    const double a = r.above(f, distance * k / 2000.0);
    if (a < -depth - 1e-9) deep = true;
    else if (deep && a > 1e-9) return true;
  }
  return false;
}

// A random unblocked ray from texel (i, j)'s square aimed just under a random point ahead, or none.
std::optional<Ray> random_unblocked_ray(const Heightfield& f, int i, int j, double distance, Rng& rng) {
  const double a = rng.uniform(0.0, 2.0 * std::numbers::pi);
  Ray r{i + rng.uniform(), j + rng.uniform(), std::cos(a), std::sin(a), 0.0, 0.0};
  const double lift[] = {1e-6, 1e-3, 1e-2, 0.1};
  r.z0 = r.g(f, 0.0) + lift[rng.below(4)];
  const double aim = rng.uniform(0.05, std::max(0.1, distance));
  r.slope = (r.g(f, aim) - 0.02 * rng.uniform() - r.z0) / aim;
  if (!unblocked(f, r)) return std::nullopt;
  return r;
}

std::vector<std::pair<std::string, Heightfield>> fields() {
  Rng rng(5);
  return {{"random 8x8", random_field(8, rng)},
          {"fbm 16x16", make_heightfield("fbm", 16, 4, 2)},
          {"spikes 12x12", make_heightfield("spikes", 12, 3, 4)},
          {"walls 12x12", make_heightfield("walls", 12, 4, 0)},
          {"step 12x12", make_heightfield("step", 12, 0, 0)}};
}

// Counts the unblocked rays that pass under and out within the radius, over `rays` rays a texel.
struct Tally {
  int rays = 0, failures = 0;
};
Tally brute_force(const Heightfield& f, const SafetyRadius& r, double epsilon, int rays, Rng& rng) {
  Tally t;
  const int n = f.size;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double radius = r.radius[static_cast<std::size_t>(j) * n + i];
      if (radius == 0.0) continue;
      for (int k = 0; k < rays; ++k)
        if (const auto ray = random_unblocked_ray(f, i, j, radius, rng)) {
          ++t.rays;
          t.failures += under_and_out(f, *ray, radius, epsilon) ? 1 : 0;
        }
    }
  return t;
}

// The minimum over directions at epsilon 0 and epsilon 0.02 bounds the unblocked rays it was made
// for: none of about a thousand and two thousand random rays passes under and out within the
// radius (the directions and profiles are sampled: measured, not proven).
TEST(ReliefPaperRadiusTest, MinimumBoundsUnblockedRays) {
  Rng rng(11);
  for (const double epsilon : {0.0, 0.02}) {
    Tally all;
    for (const auto& [name, f] : fields()) {
      PaperRadiusOptions o;
      o.combine = RadiusCombine::Min;
      o.epsilon = epsilon;
      o.directions = 32;
      const Tally t = brute_force(f, paper_safety_radius(f, 8, o), epsilon, 12, rng);
      all.rays += t.rays, all.failures += t.failures;
    }
    std::printf("min, epsilon %g: %d of %d\n", epsilon, all.failures, all.rays);
    EXPECT_GT(all.rays, 1000) << "epsilon " << epsilon;
    EXPECT_EQ(all.failures, 0) << "epsilon " << epsilon << ": " << all.failures << " of " << all.rays
                               << " unblocked rays passed under and out within the radius";
  }
}

// The paper's wording, the maximum over directions, lets unblocked rays pass under and out (the
// walk reads one radius for every direction).
TEST(ReliefPaperRadiusTest, MaximumLetsRaysThrough) {
  Rng rng(12);
  Tally all;
  for (const auto& [name, f] : fields()) {
    PaperRadiusOptions o;
    o.combine = RadiusCombine::Max;
    const Tally t = brute_force(f, paper_safety_radius(f, 8, o), 0.0, 12, rng);
    all.rays += t.rays, all.failures += t.failures;
  }
  std::printf("max: %d of %d\n", all.failures, all.rays);
  EXPECT_GT(all.failures * 100, all.rays) << all.failures << " of " << all.rays;
}

// A larger epsilon never lowers a radius; the maximum is never below the minimum; a plane (the
// field and its border at 0) keeps the cap everywhere.
TEST(ReliefPaperRadiusTest, MonotoneInEpsilonAndPlanesKeepTheCap) {
  for (const auto& [name, f] : fields()) {
    PaperRadiusOptions lo, hi, mx;
    lo.combine = hi.combine = RadiusCombine::Min;
    hi.epsilon = 0.05;
    mx.combine = RadiusCombine::Max;
    const SafetyRadius a = paper_safety_radius(f, 8, lo), b = paper_safety_radius(f, 8, hi), c = paper_safety_radius(f, 8, mx);
    for (std::size_t k = 0; k < a.radius.size(); ++k) {
      ASSERT_LE(a.radius[k], b.radius[k]) << name << " texel " << k;
      ASSERT_LE(a.radius[k], c.radius[k]) << name << " texel " << k;
    }
  }
  const Heightfield flat{16, std::vector<float>(256, 0.0f)};
  for (const float v : paper_safety_radius(flat, 8, PaperRadiusOptions{}).radius) ASSERT_EQ(v, 8.0f);
}

TEST(ReliefPaperRadiusTest, BadOptionsRefused) {
  const Heightfield f = make_heightfield("fbm", 8, 2, 1);
  PaperRadiusOptions o;
  o.epsilon = 1.5;
  EXPECT_NE(paper_radius_problem(o).find("epsilon 1.5"), std::string::npos);
  EXPECT_THROW(paper_safety_radius(f, 8, o), nbsim::InputError);
  o = {};
  o.directions = 2;
  EXPECT_THROW(paper_safety_radius(f, 8, o), nbsim::InputError);
  EXPECT_THROW(paper_safety_radius(f, 0, PaperRadiusOptions{}), nbsim::InputError);
}

}  // namespace

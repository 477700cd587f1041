// ReliefRadiusTest: the safety radius (radius.h): its guarantee by brute force (no ray from a
// texel's square crosses the surface twice within the radius), a dense-profile cross-check, the
// paper's maximum over directions failing the guarantee, peaks at 0, and radius_problem.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "model/common/error.h"
#include "model/relief/heightfield.h"
#include "model/relief/radius.h"
#include "tests/model/relief/relief_brute_force.h"

namespace {

using namespace nbsim::relief;
using nbsim::InputError;
using nbsim::relief::test_support::random_field;
using nbsim::relief::test_support::Rng;

// The profile of the surface from (x, y) in direction angle `a` at horizontal distance s.
struct Profile {
  const Heightfield& f;
  double x, y, dx, dy;
  Profile(const Heightfield& field, double px, double py, double a) : f(field), x(px), y(py), dx(std::cos(a)), dy(std::sin(a)) {}
  double operator()(double s) const { return surface_height(f, x + s * dx, y + s * dy); }
};

// Sign changes of the height above the surface of the ray z0 + slope * s (z0 above the profile's
// start) for s in [0, distance], densely sampled; below or above means by more than 1e-9.
int crossings(const Profile& g, double z0, double slope, double distance) {
  constexpr int kSamples = 2000;
  int count = 0;
  bool below = false;
  for (int k = 1; k <= kSamples; ++k) {
    const double s = distance * k / kSamples;
    const double f = z0 + slope * s - g(s);
    if (!below && f < -1e-9) {
      below = true;
      ++count;
    } else if (below && f > 1e-9) {
      below = false;
      ++count;
    }
  }
  return count;
}

// A ray from a random point of texel (i, j)'s square, in a random direction (not one of the sampled
// ones), starting just above the surface and aimed at a random point of the profile (so that it
// grazes or crosses it): its crossings within `distance`.
int random_ray_crossings(const Heightfield& f, int i, int j, double distance, Rng& rng) {
  const Profile g(f, i + rng.uniform(), j + rng.uniform(), rng.uniform(0.0, 2.0 * std::numbers::pi));
  const double eps[] = {1e-7, 1e-4, 1e-2, 0.1};
  const double z0 = g(0.0) + eps[rng.below(4)];
  const double aim = rng.uniform(0.01, distance);
  const double slope = (g(aim) - z0) / aim + rng.uniform(-1e-3, 1e-3);
  return crossings(g, z0, slope, distance);
}

// The dense version of one profile's r: the slope from the start sampled every 1/64 texel; the
// first decrease lies in (lower, upper].
struct DenseR {
  double lower, upper;
};
DenseR dense_r(const Profile& g, double limit) {
  constexpr double kStep = 1.0 / 64;
  const double g0 = g(0.0);
  double previous = -std::numeric_limits<double>::infinity();
  for (int k = 1; k * kStep <= limit + 1e-12; ++k) {
    const double s = k * kStep;
    const double m = (g(s) - g0) / s;
    if (m < previous - 1e-12) return {s - kStep, s};
    previous = m;
  }
  return {limit, limit};
}

// The dense radius of texel (i, j) over radius.h's start points and directions (64, 3 x 3), with
// the minimum (radius.h) or the maximum (the paper's wording) over directions: from the lower and
// from the upper ends of the profiles' brackets.
DenseR dense_radius(const Heightfield& f, int i, int j, int max_radius, bool max_over_directions) {
  DenseR r{static_cast<double>(max_radius), static_cast<double>(max_radius)};
  for (int b = 0; b <= 2; ++b) {
    for (int a = 0; a <= 2; ++a) {
      DenseR over = max_over_directions ? DenseR{0.0, 0.0} : r;
      for (int k = 0; k < 64; ++k) {
        const DenseR d = dense_r(Profile(f, i + a / 2.0, j + b / 2.0, 2.0 * std::numbers::pi * k / 64), max_radius);
        over = max_over_directions ? DenseR{std::max(over.lower, d.lower), std::max(over.upper, d.upper)}
                                   : DenseR{std::min(over.lower, d.lower), std::min(over.upper, d.upper)};
      }
      r = {std::min(r.lower, over.lower), std::min(r.upper, over.upper)};
    }
  }
  return {std::floor(r.lower), std::floor(r.upper)};
}

struct Case {
  const char* name;
  Heightfield field;
};

std::vector<Case> small_fields() {
  Rng rng(77);
  std::vector<Case> cases = {
      {"random 6x6", random_field(6, rng)},
      {"random 8x8", random_field(8, rng)},
      {"spikes 8x8", make_heightfield("spikes", 8, 3, 4)},
      {"saddle 6x6", make_heightfield("saddle", 6, 0, 0)},
      {"step 8x8", make_heightfield("step", 8, 0, 0)},
      {"walls 8x8", make_heightfield("walls", 8, 4, 0)},
      {"spikes 8x8 sparse", make_heightfield("spikes", 8, 1, 9)},
  };
  Heightfield terrace{8, std::vector<float>(64, 0.2f)};  // a low terrace with a raised block: long flat runs
  for (int j = 2; j < 5; ++j)
    for (int i = 3; i < 6; ++i) terrace.heights[static_cast<std::size_t>(j) * 8 + i] = 0.6f;
  cases.push_back({"terrace 8x8", terrace});
  return cases;
}

// The guarantee: from any point of a texel's square, in any direction, a ray starting above the
// surface crosses it at most once within the texel's radius.
TEST(ReliefRadiusTest, NoRayCrossesTwiceWithinTheRadius) {
  Rng rng(1234);
  int tested = 0;
  std::vector<Case> cases = small_fields();
  // Fields with long radii: a convex bowl (twisted only by the heights' float rounding; convex
  // profiles inside the border), a wider step and sparse spikes.
  Heightfield bowl{12, std::vector<float>(144)};
  for (int j = 0; j < 12; ++j)
    for (int i = 0; i < 12; ++i)
      bowl.heights[static_cast<std::size_t>(j) * 12 + i] = static_cast<float>(((i - 5.5) * (i - 5.5) + (j - 5.5) * (j - 5.5)) / 61.0);
  cases.push_back({"bowl 12x12", bowl});
  cases.push_back({"step 16x16", make_heightfield("step", 16, 0, 0)});
  cases.push_back({"spikes 16x16", make_heightfield("spikes", 16, 3, 8)});
  for (const Case& c : cases) {
    const SafetyRadius r = safety_radius(c.field, 8);
    const int n = c.field.size;
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const double radius = r.radius[static_cast<std::size_t>(j) * n + i];
        if (radius == 0.0) continue;
        for (int ray = 0; ray < 30; ++ray, ++tested) {
          const int count = random_ray_crossings(c.field, i, j, radius, rng);
          ASSERT_LE(count, 1) << c.name << ": a ray from texel (" << i << ", " << j << ") crosses " << count
                              << " times within its radius " << radius;
        }
      }
    }
  }
  EXPECT_GT(tested, 8000) << "too few texels with a radius above 0";
}

// Against an independent dense sampling of the profiles: never above its upper bound (conservative),
// and equal to its lower bound almost everywhere (not needlessly small).
TEST(ReliefRadiusTest, MatchesDenseProfiles) {
  int texels = 0, equal = 0;
  for (const Case& c : small_fields()) {
    const SafetyRadius r = safety_radius(c.field, 6);
    const int n = c.field.size;
    for (int j = 0; j < n; j += 1) {
      for (int i = (j % 2); i < n; i += 2) {  // every other texel keeps the test fast
        const float v = r.radius[static_cast<std::size_t>(j) * n + i];
        const DenseR dense = dense_radius(c.field, i, j, 6, false);
        ASSERT_LE(v, dense.upper) << c.name << ": texel (" << i << ", " << j << ") is not conservative";
        ++texels;
        equal += v == dense.lower;
      }
    }
  }
  EXPECT_GE(equal, texels * 9 / 10) << equal << " of " << texels << " texels agree with the dense lower bound";
}

// The paper's wording, the maximum over directions, breaks the guarantee: a ray from a texel beside
// a spike, aimed through it, crosses twice within that radius (and the minimum stays below).
TEST(ReliefRadiusTest, MaximumOverDirectionsFails) {
  Heightfield f{10, std::vector<float>(100, 0.1f)};
  f.heights[4 * 10 + 5] = 1.0f;  // a spike at texel (5, 4)
  const int i = 2, j = 4;
  const double paper = dense_radius(f, i, j, 8, true).lower;
  const float radius = safety_radius(f, 8).radius[static_cast<std::size_t>(j) * 10 + i];
  ASSERT_GE(paper, 3.0) << "the maximum over directions reaches past the spike";
  EXPECT_LT(radius, paper);
  Rng rng(99);
  int twice = 0;
  for (int ray = 0; ray < 400; ++ray) twice += random_ray_crossings(f, i, j, paper, rng) >= 2;
  EXPECT_GT(twice, 0) << "no ray crossed twice within the paper's radius " << paper;
  for (int ray = 0; ray < 400; ++ray) ASSERT_LE(random_ray_crossings(f, i, j, radius, rng), 1) << "within radius.h's radius " << radius;
}

// Every spike is a peak: radius 0; a flat field (the border is 0 too) gets max_radius everywhere.
TEST(ReliefRadiusTest, PeaksAreZeroFlatIsMax) {
  const Heightfield spikes = make_heightfield("spikes", 32, 12, 3);
  const SafetyRadius r = safety_radius(spikes, 16);
  ASSERT_EQ(r.size, 32);
  ASSERT_EQ(r.radius.size(), 32u * 32u);
  int peaks = 0;
  for (std::size_t t = 0; t < r.radius.size(); ++t) {
    if (spikes.heights[t] != 1.0f) continue;
    ++peaks;
    EXPECT_EQ(r.radius[t], 0.0f) << "spike at texel (" << t % 32 << ", " << t / 32 << ")";
  }
  EXPECT_EQ(peaks, 12);
  EXPECT_GT(*std::max_element(r.radius.begin(), r.radius.end()), 4.0f) << "the floor between spikes is not all 0";
  const SafetyRadius flat = safety_radius(Heightfield{16, std::vector<float>(256, 0.0f)}, 12);
  EXPECT_EQ(std::count(flat.radius.begin(), flat.radius.end(), 12.0f), 256);
  EXPECT_EQ(radius_problem(spikes, r, 16), "") << "safety_radius's own map is conservative";
}

// Each row: a radius map and the words its problem must contain.
TEST(ReliefRadiusTest, ProblemsAreNamed) {
  const Heightfield f = make_heightfield("spikes", 8, 2, 1);
  const SafetyRadius good = safety_radius(f, 4);
  const auto with = [&](int i, int j, float v) {
    SafetyRadius r = good;
    r.radius[static_cast<std::size_t>(j) * 8 + i] = v;
    return r;
  };
  std::size_t spike = 0;
  while (f.heights[spike] != 1.0f) ++spike;
  const int si = static_cast<int>(spike % 8), sj = static_cast<int>(spike / 8);
  SafetyRadius small = good;
  small.size = 4;
  SafetyRadius short_map = good;
  short_map.radius.pop_back();
  const struct {
    const char* why;
    SafetyRadius r;
    std::string expected;
  } rows[] = {
      {"size mismatch", small, "has size 4, but the heightfield's is 8"},
      {"wrong length", short_map, "has 63 radii, but 8 x 8 needs 64"},
      {"NaN", with(1, 2, std::numeric_limits<float>::quiet_NaN()), "texel (1, 2) has radius NaN"},
      {"negative", with(3, 0, -1.0f), "texel (3, 0) has radius -1, which is negative"},
      {"not whole", with(0, 5, 1.5f), "texel (0, 5) has radius 1.5, which is not whole"},
      {"too large at a spike", with(si, sj, 2.0f),
       "texel (" + std::to_string(si) + ", " + std::to_string(sj) + ") has radius 2, but the heightfield allows at most 0"},
      {"above max_radius", with(0, 0, 5.0f), "texel (0, 0) has radius 5, but the heightfield allows at most"},
  };
  for (const auto& row : rows)
    EXPECT_NE(radius_problem(f, row.r, 4).find(row.expected), std::string::npos)
        << row.why << ": got '" << radius_problem(f, row.r, 4) << "'";
  EXPECT_EQ(radius_problem(f, good, 4), "");
  EXPECT_EQ(radius_problem(f, SafetyRadius{8, std::vector<float>(64, 0.0f)}, 4), "") << "all 0 is conservative";
}

// Fewer directions and start points (8 and 2 x 2 are subsets of 64 and 3 x 3) never give a smaller radius.
TEST(ReliefRadiusTest, FewerSamplesNeverLowerTheRadius) {
  for (std::string_view kind : {"spikes", "step", "walls", "saddle"}) {
    const Heightfield f = make_heightfield(kind, 24, 0, 6);
    const SafetyRadius fine = safety_radius(f, 10), coarse = safety_radius(f, 10, 8, 2);
    int lower = 0;
    for (std::size_t t = 0; t < fine.radius.size(); ++t) {
      ASSERT_LE(fine.radius[t], coarse.radius[t]) << kind << ": texel (" << t % 24 << ", " << t / 24 << ")";
      lower += fine.radius[t] < coarse.radius[t];
    }
    if (kind == std::string_view("spikes")) {
      EXPECT_GT(lower, 0) << "the finer sampling finds nothing the coarse one misses";
    }
  }
}

// Bad arguments are the user's errors.
TEST(ReliefRadiusTest, BadArgumentsAreInputErrors) {
  const Heightfield f = make_heightfield("step", 4, 0, 0);
  EXPECT_THROW(safety_radius(f, 0), InputError);
  EXPECT_THROW(safety_radius(f, 256), InputError);
  EXPECT_THROW(safety_radius(f, 4, 7), InputError);
  EXPECT_THROW(safety_radius(f, 4, 64, 1), InputError);
  EXPECT_THROW(safety_radius(Heightfield{4, std::vector<float>(16, 2.0f)}, 4), InputError);
}

}  // namespace

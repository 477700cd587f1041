// ReliefReferenceTest: the exact reference of a relief ray (reference.h) against a dense-sampling
// brute force on random fields and rays, and the cases a cell walk gets wrong: a saddle dipped
// under inside one cell, a tangent touch, vertical and axis-parallel rays, cell corners, a start
// below the surface, a clear miss.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>
#include <optional>

#include "model/relief/heightfield.h"
#include "model/relief/reference.h"
#include "tests/model/relief/relief_brute_force.h"

namespace {

using namespace nbsim::relief;
using nbsim::relief::test_support::above;
using nbsim::relief::test_support::box_interval;
using nbsim::relief::test_support::random_field;
using nbsim::relief::test_support::Rng;
using Vec = std::array<double, 3>;

// Brute force samples along a ray, and the margin that makes a crossing or a miss "clear": with at
// most ~12 units of travel, 20000 samples are < 6e-4 apart, so f (slopes below ~3 on either side
// of a kink) cannot dip from above the margin to below 0 between two samples.
constexpr int kSamples = 20000;
constexpr double kClear = 1e-3;

struct BruteForce {
  enum Kind { Unclear, Miss, EnterBelow, Crossing } kind = Unclear;
  double t = 0.0;
};

// The first sign change of f along [t0, t1] from kSamples samples, refined by bisection; Unclear
// when, before it, the samples come within kClear of the surface at a local minimum (a touch or a
// dip the samples may not resolve; a crossing's own approach is not one).
BruteForce brute_force(const Heightfield& f, const Vec& o, const Vec& d, double t0, double t1) {
  double before = above(f, o, d, t0);
  if (before <= 0.0) return {BruteForce::EnterBelow, t0};
  bool near = false, falling = true;  // the first sample is a minimum when the next is not lower
  double previous_t = t0;
  for (int k = 1; k <= kSamples; ++k) {
    const double t = k == kSamples ? t1 : t0 + (t1 - t0) * k / kSamples;
    const double v = above(f, o, d, t);
    if (v <= 0.0) {
      if (near) return {};
      double lo = previous_t, hi = t;
      for (int b = 0; b < 80; ++b) {
        const double mid = 0.5 * (lo + hi);
        (above(f, o, d, mid) > 0.0 ? lo : hi) = mid;
      }
      return {BruteForce::Crossing, hi};
    }
    if (falling && v >= before && before <= kClear) near = true;  // the previous sample is a local minimum
    falling = v <= before;
    before = v;
    previous_t = t;
  }
  if (falling && before <= kClear) near = true;  // the last sample
  return near ? BruteForce{} : BruteForce{BruteForce::Miss, 0.0};
}

// The reference's hit checked against brute force on one ray: returns the brute force's kind.
BruteForce::Kind check_ray(const Heightfield& f, const Vec& o, const Vec& d, double t0, double t1, const char* what) {
  const ReferenceHit r = reference_hit(f, o, d, t0, t1);
  const BruteForce b = brute_force(f, o, d, t0, t1);
  if (r.hit) {
    EXPECT_GE(r.t, t0) << what;
    EXPECT_LE(r.t, t1) << what;
    if (r.t > t0) {
      EXPECT_LE(std::abs(above(f, o, d, r.t)), 1e-9) << what << ": the hit must lie on the surface";
    }
  }
  switch (b.kind) {
    case BruteForce::EnterBelow:
      EXPECT_TRUE(r.hit && r.t == t0) << what << ": a ray entering below the surface hits at t_enter";
      break;
    case BruteForce::Crossing:
      EXPECT_TRUE(r.hit) << what << ": brute force crosses at t = " << b.t;
      if (r.hit) {
        EXPECT_NEAR(r.t, b.t, 1e-6) << what;
      }
      break;
    case BruteForce::Miss:
      EXPECT_FALSE(r.hit) << what << ": brute force stays above, the reference hits at t = " << r.t;
      break;
    case BruteForce::Unclear:
      break;
  }
  return b.kind;
}

// Random 4x4 to 8x8 fields, rays from all around the box towards a random point inside it.
TEST(ReliefReferenceTest, AgreesWithBruteForceOnRandomRays) {
  Rng rng(20260601);
  int counts[4] = {};
  for (int field_index = 0; field_index < 40; ++field_index) {
    const int n = 4 + rng.below(5);
    const Heightfield f = random_field(n, rng);
    for (int ray = 0; ray < 40; ++ray) {
      const Vec o = {rng.uniform(-2.0, n + 2.0), rng.uniform(-2.0, n + 2.0), rng.uniform(0.0, 2.0)};
      const Vec target = {rng.uniform(0.0, n), rng.uniform(0.0, n), rng.uniform(0.0, 1.0)};
      Vec d = {target[0] - o[0], target[1] - o[1], target[2] - o[2]};
      if (ray % 5 == 0) d[2] *= 0.05;  // grazing
      const double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      if (length == 0.0) continue;
      for (double& c : d) c /= length;
      const auto interval = box_interval(n, o, d);
      if (!interval) continue;
      ++counts[check_ray(f, o, d, interval->first, interval->second, "random ray")];
    }
  }
  EXPECT_GT(counts[BruteForce::Crossing], 300) << "too few clear crossings compared";
  EXPECT_GT(counts[BruteForce::Miss], 50) << "too few clear misses compared";
  EXPECT_GT(counts[BruteForce::EnterBelow], 20) << "too few rays entering below the surface";
}

// Figure 3's saddle: a ray above both ends of the saddle cell dips under its middle; a cell walk
// that tests only cell boundaries misses it, the reference must not.
TEST(ReliefReferenceTest, FindsTheSaddleDip) {
  const Heightfield f = make_heightfield("saddle", 4, 0, 0);  // cell (1, 1): h = u + v - 2uv
  // Along the diagonal (through cell corners) at z = 0.4: h = 2w(1 - w) = 0.4 at w = (1 - sqrt(0.2)) / 2.
  const Vec o = {0.0, 0.0, 0.4}, d = {1.0, 1.0, 0.0};
  ASSERT_GT(above(f, o, d, 1.5), 0.0) << "above the saddle cell's entry";
  ASSERT_GT(above(f, o, d, 2.5), 0.0) << "above the saddle cell's exit";
  const ReferenceHit r = reference_hit(f, o, d, 0.0, 4.0);
  ASSERT_TRUE(r.hit) << "the dip under the saddle is a hit";
  EXPECT_NEAR(r.t, 1.5 + (1.0 - std::sqrt(0.2)) / 2.0, 1e-12);
  // Off the diagonal, entering and leaving through edges.
  const Vec o2 = {1.5, 1.55, 0.45}, d2 = {1.0, 0.95, 0.0};
  ASSERT_GT(above(f, o2, d2, 0.0), 0.0);
  ASSERT_GT(above(f, o2, d2, 1.0), 0.0);
  EXPECT_EQ(check_ray(f, o2, d2, 0.0, 2.0, "off-diagonal saddle dip"), BruteForce::Crossing);
}

// A tangent touch (a double root) is a hit; 1e-6 above it is a miss.
TEST(ReliefReferenceTest, TangentTouchIsAHit) {
  const Heightfield f = make_heightfield("saddle", 4, 0, 0);
  const ReferenceHit touch = reference_hit(f, {0.0, 0.0, 0.5}, {1.0, 1.0, 0.0}, 0.0, 4.0);  // h peaks at 0.5 on the diagonal
  ASSERT_TRUE(touch.hit) << "touching the saddle's ridge at its top";
  EXPECT_NEAR(touch.t, 2.0, 1e-6);
  EXPECT_FALSE(reference_hit(f, {0.0, 0.0, 0.5 + 1e-6}, {1.0, 1.0, 0.0}, 0.0, 4.0).hit) << "1e-6 above the top";
}

// Vertical rays (no horizontal motion: one cell, a linear f) at random points, texel centres
// (cell corners) and cell boundaries hit at z = the surface height.
TEST(ReliefReferenceTest, VerticalRays) {
  Rng rng(5);
  const Heightfield f = random_field(5, rng);
  const std::array<double, 2> points[] = {{2.5, 2.5}, {1.5, 3.2}, {0.7, 4.5}, {0.0, 0.0}, {5.0, 2.5}, {0.25, 0.25}, {3.3, 1.9}};
  for (const auto& [x, y] : points) {
    const ReferenceHit r = reference_hit(f, {x, y, 1.5}, {0.0, 0.0, -1.0}, 0.5, 1.5);
    ASSERT_TRUE(r.hit) << "a vertical ray always reaches the surface or the floor (" << x << ", " << y << ")";
    EXPECT_NEAR(r.t, 1.5 - surface_height(f, x, y), 1e-12) << "at (" << x << ", " << y << ")";
  }
  // Upwards from below: hits at t_enter.
  const ReferenceHit up = reference_hit(f, {2.5, 2.5, 0.0}, {0.0, 0.0, 1.0}, 0.0, 1.0);
  EXPECT_TRUE(up.hit && up.t == 0.0);
}

// A ray starting below the surface (inside the box, or through a side face below the border's
// slope) hits at t_enter.
TEST(ReliefReferenceTest, EnteringBelowHitsAtEnter) {
  const Heightfield f{4, std::vector<float>(16, 0.8f)};
  const ReferenceHit inside = reference_hit(f, {1.0, 1.0, 0.2}, {1.0, 0.0, 0.1}, 0.0, 3.0);
  EXPECT_TRUE(inside.hit && inside.t == 0.0) << "origin below the surface";
  const ReferenceHit side = reference_hit(f, {-1.0, 2.0, 0.3}, {1.0, 0.0, 0.0}, 1.0, 5.0);  // surface 0.4 at x = 0
  EXPECT_TRUE(side.hit && side.t == 1.0) << "entering through the side face under the surface";
}

// Axis-parallel rays, along a cell boundary (x = a texel centre) and inside a row of cells.
TEST(ReliefReferenceTest, AxisParallelRays) {
  const Heightfield step = make_heightfield("step", 4, 0, 0);  // 1 at texel centres x >= 2.5
  // Along x = 2.5 (between cells 1 and 2) at z = 0.9: the border's slope h = y + 0.5 reaches 0.9 at y = 0.4.
  const ReferenceHit r = reference_hit(step, {2.5, 0.0, 0.9}, {0.0, 1.0, 0.0}, 0.0, 4.0);
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.t, 0.4, 1e-12);
  // Across the step along y = 1.5 (a boundary) at z = 0.6: h = x - 1.5 on [1.5, 2.5].
  const ReferenceHit across = reference_hit(step, {0.0, 1.5, 0.6}, {1.0, 0.0, 0.0}, 0.0, 4.0);
  ASSERT_TRUE(across.hit);
  EXPECT_NEAR(across.t, 2.1, 1e-12);
  Rng rng(11);
  const Heightfield f = random_field(6, rng);
  int compared = 0;
  for (double c : {0.5, 1.5, 2.0, 3.5, 4.25, 5.5}) {
    compared += check_ray(f, {c, -0.5, 1.0}, {0.0, 1.0, -0.12}, 0.5, 6.5, "along y") == BruteForce::Crossing;
    compared += check_ray(f, {-0.5, c, 1.0}, {1.0, 0.0, -0.12}, 0.5, 6.5, "along x") == BruteForce::Crossing;
  }
  EXPECT_GE(compared, 6) << "too few axis-parallel crossings compared";
}

// The block maxima change only the speed: the same answer, bit for bit, on every kind of field
// (smooth terrain, walls, spikes on a floor, a step, random noise) and sizes that leave partial
// blocks, for random rays from above the box and from its sides, axis-parallel ones, rays along
// cell boundaries and rays grazing just above a field's highest texel.
TEST(ReliefReferenceTest, BlocksGiveTheSameAnswer) {
  Rng rng(20261205);
  int hits = 0, rays = 0;
  for (const int n : {5, 16, 37, 64}) {
    std::vector<Heightfield> fields;
    for (const char* kind : {"fbm", "walls", "spikes", "step"}) fields.push_back(make_heightfield(kind, n, 0, 7));
    fields.push_back(random_field(n, rng));
    for (const Heightfield& f : fields) {
      const ReferenceBlocks blocks(f);
      const float top = *std::max_element(f.heights.begin(), f.heights.end());
      for (int k = 0; k < 1500; ++k) {
        Vec o{rng.uniform(-2.0, n + 2.0), rng.uniform(-2.0, n + 2.0), rng.uniform(0.0, 1.6)};
        Vec d{rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-0.3, 0.05)};
        switch (k % 6) {
          case 1: d[rng.below(2)] = 0.0; break;                                    // axis-parallel
          case 2: o[0] = std::floor(o[0]) + 0.5, d[0] = 0.0; break;                // along a cell boundary
          case 3: o[2] = static_cast<double>(top) + 1e-6 * rng.uniform(), d[2] = 0.0; break;  // grazing the top
          case 4: o[2] = static_cast<double>(top) + 0.01, d[2] = -1e-3; break;     // slowly descending
          default: break;
        }
        if (d[0] == 0.0 && d[1] == 0.0) d[0] = 0.5;
        const auto interval = box_interval(n, o, d);
        if (!interval) continue;
        ++rays;
        const ReferenceHit plain = reference_hit(f, o, d, interval->first, interval->second);
        const ReferenceHit fast = reference_hit(f, o, d, interval->first, interval->second, &blocks);
        hits += plain.hit;
        ASSERT_EQ(plain.hit, fast.hit) << "n " << n << " ray " << k;
        ASSERT_EQ(std::bit_cast<std::uint64_t>(plain.t), std::bit_cast<std::uint64_t>(fast.t)) << "n " << n << " ray " << k;
      }
    }
  }
  EXPECT_GT(rays, 10000);
  EXPECT_GT(hits, rays / 10) << "too few hits compared";
  EXPECT_LT(hits, rays - rays / 10) << "too few misses compared";
}

// Above everything: no hit, also for a descending ray that leaves the box first.
TEST(ReliefReferenceTest, MissAboveEverything) {
  const Heightfield f = make_heightfield("fbm", 8, 0, 2);  // heights up to 0.9
  EXPECT_FALSE(reference_hit(f, {0.0, 0.0, 0.95}, {1.0, 1.0, 0.0}, 0.0, 8.0).hit);
  EXPECT_FALSE(reference_hit(f, {0.0, 3.0, 0.98}, {1.0, 0.2, -0.01}, 0.0, 8.0).hit);
  EXPECT_EQ(check_ray(f, {0.0, 0.0, 0.95}, {0.6, 0.8, 0.0}, 0.0, 10.0, "flat above the top"), BruteForce::Miss);
}

}  // namespace

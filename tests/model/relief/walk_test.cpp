// ReliefWalkTest: the walks of model/relief/walk.h on the relief hard cases, each against the exact
// reference (reference.h, score.h): the saddle of Baboud & Decoret's Figure 3 (the exact walk
// misses it, the robust search and the N-buffer walk must not), a single-texel spike (radius 0), a 0
// to 1 step seen at grazing angles, a long empty run (the N-buffer walk skips it in a few lookups),
// and rays entering through the box's sides. The GL twin of every walk is ReliefGlWalkTest's.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <random>

#include "model/nbuffer/nbuffer.h"
#include "model/relief/heightfield.h"
#include "model/relief/radius.h"
#include "model/relief/reference.h"
#include "model/relief/score.h"
#include "model/relief/walk.h"

namespace nbsim::relief {
namespace {

// A field with its radius and max N-buffer (brute force), and the views walk() reads.
struct Fixture {
  Heightfield field;
  SafetyRadius radius;
  std::vector<float> levels;
  int level_count = 0;

  explicit Fixture(Heightfield f, int max_radius = 16) : field(std::move(f)) {
    radius = safety_radius(field, max_radius);
    const int n = field.size;
    DepthImage heights(n, n, 0.0f);
    heights.texels = field.heights;
    const NBuffer nb(heights, NBufferConfig{});
    level_count = nb.level_count();
    for (int l = 0; l < level_count; ++l) levels.insert(levels.end(), nb.level(l).begin(), nb.level(l).end());
  }
  FieldView view() const { return {field.size, field.heights, radius.radius, levels, level_count}; }
};

// The ray from `o` along `d` (texel space) clipped to the box, as fragment_ray clips it.
FragmentRay clipped(const Fixture& s, std::array<float, 3> o, std::array<float, 3> d) {
  FragmentRay r;
  r.o = o;
  r.d = d;
  float tmin = 0.0f, tmax = 3.0e38f;
  const float hi[3] = {static_cast<float>(s.field.size), static_cast<float>(s.field.size), 1.0f};
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0.0f) continue;
    const float t1 = (0.0f - o[k]) / d[k], t2 = (hi[k] - o[k]) / d[k];
    tmin = std::max(tmin, std::min(t1, t2));
    tmax = std::min(tmax, std::max(t1, t2));
  }
  r.t_in = tmin;
  r.t_out = tmax;
  return r;
}

HitError error_of(const Fixture& s, Method m, const FragmentRay& r, const WalkParams& p = {}) {
  const WalkResult w = walk(m, s.view(), p, r);
  EXPECT_FALSE(w.capped) << to_string(m);
  return score_hit(s.field, r, w.hit, w.t, 1.0 / s.field.size, kDefaultHitTolerance).error;
}

TEST(ReliefWalkTest, SaddleOfFigure3) {
  const Fixture s(make_heightfield("saddle", 16, 0, 1));
  // A horizontal ray at height 0.4 just off the saddle cell's diagonal: the height above the patch
  // is positive where it enters and leaves the cell and negative in between.
  const float m = 8.0f;
  const FragmentRay r = clipped(s, {m - 0.5f - 4.0f, m - 0.5f - 4.0f + 0.05f, 0.4f}, {1.0f, 1.0f, 0.0f});
  const std::array<double, 3> o = {r.o[0], r.o[1], r.o[2]}, d = {r.d[0], r.d[1], r.d[2]};
  ASSERT_TRUE(reference_hit(s.field, o, d, r.t_in, r.t_out).hit);
  EXPECT_EQ(error_of(s, Method::Exact, r), HitError::WrongMiss);  // their Figure 3
  EXPECT_EQ(error_of(s, Method::NBuffer, r), HitError::None);
  EXPECT_EQ(error_of(s, Method::Robust, r), HitError::None);
}

TEST(ReliefWalkTest, SingleTexelSpike) {
  Heightfield f;
  f.size = 16;
  f.heights.assign(256, 0.1f);
  f.heights[8 * 16 + 8] = 1.0f;
  const Fixture s(f);
  EXPECT_EQ(s.radius.radius[8 * 16 + 8], 0.0f);  // a peak: radius 0
  // Horizontal rays through the spike at heights near its tip and across its width.
  WalkParams coarse;
  coarse.linear_steps = 4;
  int binary_errors = 0, clamp_errors = 0, checked = 0;
  for (float z : {0.5f, 0.8f, 0.95f})
    for (float y = 8.2f; y < 8.85f; y += 0.1f) {
      const FragmentRay r = clipped(s, {0.0f, y, z}, {1.0f, 0.013f, 0.0f});
      for (Method m : {Method::Exact, Method::NBuffer, Method::Robust}) EXPECT_EQ(error_of(s, m, r), HitError::None) << to_string(m) << " z " << z << " y " << y;
      binary_errors += error_of(s, Method::Binary, r, coarse) != HitError::None;
      clamp_errors += error_of(s, Method::RobustClamp, r) != HitError::None;
      ++checked;
    }
  EXPECT_GT(binary_errors, 0) << "binary search with 4 linear steps should step over a one-texel spike";
  RecordProperty("robust_clamp_errors", clamp_errors);
  RecordProperty("checked", checked);
}

TEST(ReliefWalkTest, StepAtGrazingAngles) {
  const Fixture s(make_heightfield("step", 32, 0, 1));
  // Rays from the low side toward the 0 to 1 step, 80 to 89 degrees off vertical.
  int binary_errors = 0;
  for (double angle = 80.0; angle <= 89.0; angle += 1.0)
    for (float y = 3.3f; y < 29.0f; y += 2.9f) {
      const double a = angle * M_PI / 180.0;
      const std::array<float, 3> d = {static_cast<float>(std::sin(a) * 32.0), 0.11f, static_cast<float>(-std::cos(a))};
      const FragmentRay r = clipped(s, {0.0f, y, 0.999f}, d);
      for (Method m : {Method::Exact, Method::NBuffer, Method::Robust}) EXPECT_EQ(error_of(s, m, r), HitError::None) << to_string(m) << " at " << angle;
      binary_errors += error_of(s, Method::Binary, r) != HitError::None;
    }
  RecordProperty("binary_errors", binary_errors);
}

TEST(ReliefWalkTest, LongEmptyRunIsSkipped) {
  Heightfield f;
  f.size = 256;
  f.heights.assign(256 * 256, 0.0f);
  for (int j = 120; j < 136; ++j)
    for (int i = 240; i < 250; ++i) f.heights[static_cast<std::size_t>(j * 256 + i)] = 0.9f;
  const Fixture s(f);
  const FragmentRay r = clipped(s, {0.0f, 128.3f, 0.5f}, {1.0f, 0.0001f, 0.0f});
  const WalkResult exact = walk(Method::Exact, s.view(), {}, r);
  const WalkResult nb = walk(Method::NBuffer, s.view(), {}, r);
  ASSERT_TRUE(exact.hit);
  ASSERT_TRUE(nb.hit);
  EXPECT_FLOAT_EQ(exact.t, nb.t);
  EXPECT_LT(nb.lookups * 5, exact.lookups) << "nbuffer " << nb.lookups << " exact " << exact.lookups;
  EXPECT_EQ(error_of(s, Method::NBuffer, r), HitError::None);
}

TEST(ReliefWalkTest, RaysThroughTheSides) {
  const Fixture s(make_heightfield("fbm", 32, 0, 3));
  // Enters through a side (x = 0) below the border's height 0... so above it, then climbs out
  // through the top: a miss for every method and the reference.
  const FragmentRay up = clipped(s, {-1.0f, 16.2f, 0.02f}, {1.0f, 0.01f, 0.5f});
  ASSERT_LE(up.t_in, up.t_out);
  for (Method m : kAllMethods) EXPECT_EQ(error_of(s, m, up), HitError::None) << to_string(m);
  // Enters through a side where the surface is higher than the ray: the side wall is a hit at t_in
  // for every method... the surface at x = 0 is 0 (the zero border), so enter one texel in instead
  // from the top and leave through the far side.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int k = 0; k < 200; ++k) {
    const float y = 1.0f + 30.0f * u(rng), z = u(rng);
    const FragmentRay r = clipped(s, {-0.5f, y, z}, {1.0f, 0.2f * (u(rng) - 0.5f), 0.05f * (u(rng) - 0.5f)});
    if (!(r.t_in <= r.t_out)) continue;
    for (Method m : {Method::Exact, Method::NBuffer}) {
      const HitError e = error_of(s, m, r);
      EXPECT_TRUE(e == HitError::None || (m == Method::Exact && e == HitError::WrongMiss)) << to_string(m) << " ray " << k;
    }
  }
}

TEST(ReliefWalkTest, ExactMethodsAgreeWithTheReferenceOnRandomRays) {
  const Fixture s(make_heightfield("fbm", 64, 0, 11));
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int nbuffer_errors = 0, robust_errors = 0, exact_misses = 0, rays = 0;
  for (int k = 0; k < 3000; ++k) {
    const std::array<float, 3> o = {64.0f * u(rng), 64.0f * u(rng), 1.2f};
    const std::array<float, 3> d = {40.0f * (u(rng) - 0.5f), 40.0f * (u(rng) - 0.5f), -0.2f - u(rng)};
    const FragmentRay r = clipped(s, o, d);
    if (!(r.t_in <= r.t_out)) continue;
    ++rays;
    nbuffer_errors += error_of(s, Method::NBuffer, r) != HitError::None;
    robust_errors += error_of(s, Method::Robust, r) != HitError::None;
    const HitError e = error_of(s, Method::Exact, r);
    exact_misses += e == HitError::WrongMiss;
    EXPECT_TRUE(e == HitError::None || e == HitError::WrongMiss) << "the exact walk errs only by missing saddles, ray " << k;
  }
  EXPECT_GT(rays, 2000);
  EXPECT_EQ(nbuffer_errors, 0);
  EXPECT_EQ(robust_errors, 0);
  RecordProperty("exact_saddle_misses", exact_misses);
}

// walk_each's lanes (every method, in AVX2 and, where the CPU has it, AVX-512; the hits' refinements
// of the exact and N-buffer walks) against the one-by-one walks: every result and the record of lookups the
// same bit for bit, on fields of every kind and size 2 to 64 and on rays from above, through the
// sides, grazing, vertical, axis-aligned and along cell diagonals, with step counts that vary with
// the size (1 to 16 linear steps, 0 to 9 bisections), and records of caches whose sets a cell's
// lines share or not (the repeats the lanes' replay leaves out: 64-byte lines in 64 or 4 sets,
// 16-byte lines in 2, a line a texel in 8).
TEST(ReliefWalkTest, LanesWalkAsOneByOne) {
  if (!lane_set_available(LaneSet::Avx2)) GTEST_SKIP() << "no AVX2 here: walk_each walks one by one";
  std::mt19937 rng(23);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int hits = 0, refined = 0, walked = 0;
  for (const std::string_view kind : heightfield_kinds())
    for (const int n : {2, 5, 15, 16, 17, 64}) {
      const Fixture s(make_heightfield(kind, n, 0, 7));
      const float size = static_cast<float>(n);
      std::vector<FragmentRay> rays;
      for (int k = 0; k < 600; ++k) {
        std::array<float, 3> o = {size * (1.4f * u(rng) - 0.2f), size * (1.4f * u(rng) - 0.2f), 1.5f * u(rng)};
        std::array<float, 3> d = {u(rng) - 0.5f, u(rng) - 0.5f, -u(rng)};
        switch (k % 6) {
          case 1: d[2] = 0.02f * (u(rng) - 0.7f); break;  // grazing
          case 2: d[0] = d[1] = 0.0f; break;                // vertical
          case 3: d[k % 4 == 3 ? 1 : 0] = 0.0f; break;      // along an axis
          case 4: d[1] = d[0]; o[1] = o[0] = std::floor(o[0]) + 0.5f; break;  // through cell corners
          default: break;
        }
        if (d[2] == 0.0f && d[0] == 0.0f && d[1] == 0.0f) continue;
        const FragmentRay r = clipped(s, o, d);
        if (r.t_in <= r.t_out) rays.push_back(r);
      }
      std::vector<const FragmentRay*> pointers;
      for (const FragmentRay& r : rays) pointers.push_back(&r);
      for (const Method m : kAllMethods)
      for (const LineGeometry g : {LineGeometry{6, 64, true}, LineGeometry{6, 0, false}, LineGeometry{7, 3, true}, LineGeometry{6, 4, true},
                                   LineGeometry{4, 2, true}, LineGeometry{2, 8, true}}) {
        const int linear[] = {16, 1, 5}, bisections[] = {8, 0, 9};
        const auto variant = static_cast<std::size_t>(n % 3);
        const WalkParams p{linear[variant], bisections[variant], 16 - (n % 3) * 5, {}};
        LookupLines want;
        want.reset(g);
        std::vector<WalkResult> a(rays.size());
        walk_each(m, s.view(), p, pointers, a, &want, LaneSet::None);
        for (const LaneSet lanes : {LaneSet::Avx2, LaneSet::Avx512}) {
          if (!lane_set_available(lanes)) continue;
          const char* set = lanes == LaneSet::Avx2 ? "avx2" : "avx512";
          LookupLines got;
          got.reset(g);
          std::vector<WalkResult> b(rays.size()), c(rays.size());
          walk_each(m, s.view(), p, pointers, b, &got, lanes);
          walk_each(m, s.view(), p, pointers, c, nullptr, lanes);
          for (std::size_t k = 0; k < rays.size(); ++k) {
            ASSERT_TRUE(a[k].hit == b[k].hit && std::bit_cast<std::uint32_t>(a[k].t) == std::bit_cast<std::uint32_t>(b[k].t) &&
                        a[k].lookups == b[k].lookups && a[k].steps == b[k].steps && a[k].bisections == b[k].bisections &&
                        a[k].capped == b[k].capped)
                << set << " " << to_string(m) << " " << kind << " " << n << ": ray " << k << " hit " << a[k].hit << "/" << b[k].hit << " t " << a[k].t
                << "/" << b[k].t << " steps " << a[k].steps << "/" << b[k].steps;
            ASSERT_TRUE(b[k].hit == c[k].hit && b[k].t == c[k].t && b[k].lookups == c[k].lookups) << set << " " << kind << " " << n << ": ray " << k;
            if (lanes == LaneSet::Avx2) hits += a[k].hit, refined += a[k].bisections > 0, walked += a[k].steps > 0;
          }
          ASSERT_TRUE(std::ranges::equal(want.lines(), got.lines())) << set << " " << kind << " " << n;
          EXPECT_EQ(want.repeats(), got.repeats()) << set << " " << kind << " " << n;
        }
      }
    }
  // The rays take every way out of a walk.
  EXPECT_GT(hits, 1000);
  EXPECT_GT(refined, 500);
  EXPECT_GT(walked, 5000);
}

}  // namespace
}  // namespace nbsim::relief

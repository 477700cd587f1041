// ReliefGlWalkTest: the relief walks on llvmpipe (traces/capture/relief/gl_walk.h,
// shaders/relief/relief.frag) against the model's float twin (model/relief/walk.h), fragment by
// fragment: the same fragments, and per fragment the same hit or miss, the same t bit for bit and
// the same lookups, steps and bisections, for every method at head-on, oblique and grazing views.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <random>

#include "model/relief/walk.h"
#include "tests/common/gl_context_suite.h"
#include "traces/capture/relief/gl_walk.h"
#include "traces/capture/relief/view.h"

namespace nbsim {
namespace {

using relief::Method;

class ReliefGlWalkTest : public testing::GlContextSuite {};

relief::Heightfield random_field(int n, std::uint64_t seed, float floor_height) {
  relief::Heightfield f;
  f.size = n;
  std::mt19937 rng(static_cast<std::uint32_t>(seed));
  for (int k = 0; k < n * n; ++k) f.heights.push_back(floor_height + (1.0f - floor_height) * static_cast<float>(rng() % 1000) / 999.0f);
  return f;
}

// Levels of the max N-buffer, brute force (the model side builds its own; here only for walk()).
std::vector<float> brute_levels(const relief::Heightfield& f, int levels) {
  const int n = f.size;
  std::vector<float> out;
  for (int l = 0; l < levels; ++l)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        float m = 0.0f;
        for (int j = y; j < std::min(n, y + (1 << l)); ++j)
          for (int i = x; i < std::min(n, x + (1 << l)); ++i) m = std::max(m, f.heights[static_cast<std::size_t>(j * n + i)]);
        out.push_back(m);
      }
  return out;
}

struct Mismatch {
  std::uint64_t fragments = 0, differing = 0, hits = 0;
};

Mismatch compare(const capture::GlFragments& gl, Method m, const relief::FieldView& fv, const relief::WalkParams& params,
                 const capture::ReliefView& view, int width) {
  Mismatch r;
  for (std::size_t k = 0; k < gl.pixel.size(); ++k) {
    const int x = static_cast<int>(gl.pixel[k] % static_cast<std::uint32_t>(width)), y = static_cast<int>(gl.pixel[k] / static_cast<std::uint32_t>(width));
    ++r.fragments;
    const auto ray = relief::fragment_ray(view.ray, fv.size, static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
    relief::WalkResult w;
    if (ray) w = relief::walk(m, fv, params, *ray);
    const std::uint32_t code = w.capped ? 2u : w.hit ? 1u : 0u;
    r.hits += code == 1u;
    const bool same = code == gl.hit[k] && std::memcmp(&w.t, &gl.t[k], 4) == 0 && w.lookups == gl.lookups[k] &&
                      w.steps == gl.steps[k] && w.bisections == gl.bisections[k];
    if (!same) {
      if (r.differing < 5)
        ADD_FAILURE() << relief::to_string(m) << " pixel (" << x << ", " << y << "): GL hit " << gl.hit[k] << " t " << gl.t[k] << " lookups "
                      << gl.lookups[k] << " steps " << gl.steps[k] << " bisections " << gl.bisections[k] << "; model hit " << code << " t "
                      << w.t << " lookups " << w.lookups << " steps " << w.steps << " bisections " << w.bisections;
      ++r.differing;
    }
  }
  return r;
}

TEST_F(ReliefGlWalkTest, EveryMethodMatchesTheModelBitForBit) {
  const int width = 64, height = 64, n = 16;
  const relief::Heightfield field = random_field(n, 7, 0.0f);
  relief::SafetyRadius radius{n, std::vector<float>(static_cast<std::size_t>(n * n), 0.0f)};
  for (std::size_t k = 0; k < radius.radius.size(); k += 3) radius.radius[k] = static_cast<float>(k % 4);
  capture::DrawRecorder recorder;
  recorder.begin_frame(8);
  capture::GlReliefWalker gl(width, height);
  gl.set_field(field, radius, recorder);
  const std::vector<float> levels = gl.levels();
  ASSERT_EQ(levels, brute_levels(field, gl.level_count()));
  relief::FieldView fv{n, field.heights, radius.radius, levels, gl.level_count()};
  const relief::WalkParams params;
  for (double angle : {0.0, 30.0, 60.0, 85.0, 89.0}) {
    const capture::ReliefCamera cam = capture::relief_camera(n, 0.4, angle, 25.0 + angle, width, height);
    for (Method m : relief::kAllMethods) {
      gl.clear_depth();
      const capture::GlFragments f = gl.draw(m, cam.view, params, recorder);
      const Mismatch r = compare(f, m, fv, params, cam.view, width);
      EXPECT_GT(r.fragments, 200u) << angle;
      EXPECT_GT(r.hits, 100u) << angle;
      EXPECT_EQ(r.differing, 0u) << relief::to_string(m) << " at " << angle << " degrees, of " << r.fragments;
    }
  }
  recorder.collect();
}

}  // namespace
}  // namespace nbsim

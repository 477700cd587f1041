// ReliefGlWalkTest: the relief walks on llvmpipe (traces/capture/relief/gl_walk.h,
// shaders/relief/relief.frag) against the model's float twin (model/relief/walk.h), fragment by
// fragment: the same fragments, and per fragment the same hit or miss, the same t bit for bit and
// the same lookups, steps and bisections, for every method at head-on, oblique and grazing views.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <cmath>
#include <random>

#include "model/relief/walk.h"
#include "tests/common/gl_context_suite.h"
#include "traces/capture/gl_program.h"
#include "traces/capture/relief/gl_walk.h"
#include "traces/capture/render_target.h"
#include "traces/capture/relief/view.h"

namespace nbsim {
namespace {

using relief::Method;

class ReliefGlWalkTest : public testing::GlContextSuite {};

// A 64x64 walker over a field with a zero radius everywhere, its N-buffer built on GL, and the view
// the model's walks read.
struct WalkerOver {
  static constexpr int kSize = 64;
  relief::Heightfield field;
  relief::SafetyRadius radius;
  capture::DrawRecorder recorder;
  capture::GlReliefWalker gl{kSize, kSize};
  std::vector<float> levels;
  relief::FieldView fv;

  explicit WalkerOver(relief::Heightfield f) : field(std::move(f)) {
    radius = {field.size, std::vector<float>(field.heights.size(), 0.0f)};
    recorder.begin_frame(8);
    gl.set_field(field, radius, recorder);
    levels = gl.levels();
    fv = {field.size, field.heights, radius.radius, levels, gl.level_count()};
  }
  ~WalkerOver() { recorder.collect(); }
};

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
  // The default tunables, and odd step counts (the model's bisections run two at a time, the last one
  // alone when the count is odd).
  for (const relief::WalkParams& params : {relief::WalkParams{}, relief::WalkParams{5, 7, 3, {}}})
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

// The reverse-perspective frustum (apex one box height below the bottom face): the same walks with
// rays from the projective ray frame, at views from above, grazing and from below.
TEST_F(ReliefGlWalkTest, FrustumMatchesTheModelBitForBit) {
  const int width = WalkerOver::kSize, height = WalkerOver::kSize, n = 16;
  WalkerOver w(random_field(n, 9, 0.1f));
  capture::GlReliefWalker& gl = w.gl;
  capture::DrawRecorder& recorder = w.recorder;
  const relief::FieldView& fv = w.fv;
  for (double angle : {0.0, 50.0, 86.0, 130.0}) {
    const capture::ReliefCamera cam = capture::relief_camera(n, 0.3, angle, 40.0, width, height, 1.0);
    ASSERT_TRUE(cam.view.ray.frustum);
    for (Method m : relief::kAllMethods) {
      gl.clear_depth();
      const Mismatch r = compare(gl.draw(m, cam.view, {}, recorder), m, fv, {}, cam.view, width);
      EXPECT_GT(r.fragments, 200u) << angle;
      EXPECT_EQ(r.differing, 0u) << relief::to_string(m) << " at " << angle << " degrees, of " << r.fragments;
    }
  }
}

// The hard case: the eye on the frustum's w = 0 plane (the apex's height), where its image in texel
// space is at infinity and every ray parallel. The angle putting it there is found by bisection on
// the camera itself; the walks stay finite, exact (bit for bit with GL) and keep their hits.
TEST_F(ReliefGlWalkTest, EyeOnTheFrustumsApexPlane) {
  const int width = WalkerOver::kSize, height = WalkerOver::kSize, n = 16;
  const double box_height = 0.3, apex = 1.0;
  const auto w_of = [&](double angle) { return capture::relief_camera(n, box_height, angle, 40.0, width, height, apex).view.ray.eye_h[3]; };
  double lo = 90.0, hi = 179.0;  // the eye above the apex plane at 90 degrees, below it at 179
  ASSERT_GT(w_of(lo), 0.0f);
  ASSERT_LT(w_of(hi), 0.0f);
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (w_of(mid) > 0.0f ? lo : hi) = mid;
  }
  const capture::ReliefCamera cam = capture::relief_camera(n, box_height, lo, 40.0, width, height, apex);
  const std::array<float, 4>& e = cam.view.ray.eye_h;
  EXPECT_LT(std::abs(e[3]), 1e-4f * (std::abs(e[0]) + std::abs(e[1]) + std::abs(e[2]))) << "the eye is on the apex plane";
  WalkerOver w(random_field(n, 13, 0.0f));
  capture::GlReliefWalker& gl = w.gl;
  capture::DrawRecorder& recorder = w.recorder;
  const relief::FieldView& fv = w.fv;
  for (Method m : relief::kAllMethods) {
    gl.clear_depth();
    const capture::GlFragments f = gl.draw(m, cam.view, {}, recorder);
    const Mismatch r = compare(f, m, fv, {}, cam.view, width);
    EXPECT_GT(r.fragments, 200u);
    EXPECT_GT(r.hits, 100u);
    EXPECT_EQ(r.differing, 0u) << relief::to_string(m);
    for (float t : f.t) EXPECT_TRUE(std::isfinite(t));
  }
  // Every ray of this view is parallel in texel space (the eye's image is at infinity).
  gl.clear_depth();
  const capture::GlFragments f = gl.draw(Method::Exact, cam.view, {}, recorder);
  ASSERT_GE(f.pixel.size(), 2u);
  const auto centre = [&](std::size_t k, int axis) {
    return static_cast<float>(axis == 0 ? f.pixel[k] % width : f.pixel[k] / width) + 0.5f;
  };
  const std::size_t last = f.pixel.size() - 1;
  const auto r0 = relief::fragment_ray(cam.view.ray, n, centre(0, 0), centre(0, 1));
  const auto r1 = relief::fragment_ray(cam.view.ray, n, centre(last, 0), centre(last, 1));
  ASSERT_TRUE(r0 && r1);
  const double cross = std::abs(double(r0->d[0]) * r1->d[1] - double(r0->d[1]) * r1->d[0]) /
                       (std::hypot(r0->d[0], r0->d[1]) * std::hypot(r1->d[0], r1->d[1]));
  EXPECT_LT(cross, 1e-3) << "the rays' horizontal directions are parallel";
}

// What llvmpipe stores for a gl_FragDepth outside [0, 1] in a DEPTH_COMPONENT32F buffer without
// depth clamp (the exact-depth box writes its hit's depth, which lies before the near plane when the
// box crosses it): the model's raster path (model/raster/depth_test.h, FragmentShader::frag_depth)
// stores what this finds.
TEST_F(ReliefGlWalkTest, FragDepthOutsideTheUnitRange) {
  static const char* kVert = "#version 450 core\nvoid main() { vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);"
                             " gl_Position = vec4(p, 0.5, 1.0); }\n";
  static const char* kFrag = "#version 450 core\nuniform float depth;\nvoid main() { gl_FragDepth = depth; }\n";
  const GLuint p = capture::link_program({capture::compile_shader(GL_VERTEX_SHADER, kVert, "fullscreen"),
                                          capture::compile_shader(GL_FRAGMENT_SHADER, kFrag, "frag depth")},
                                         "frag depth");
  capture::RenderTarget target(4, 4);
  GLuint vao = 0;
  glCreateVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glUseProgram(p);
  for (const float written : {-0.25f, 1.5f, 0.375f}) {
    target.bind();
    target.clear_depth(false);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_ALWAYS);
    glDepthMask(GL_TRUE);
    glDisable(GL_DEPTH_CLAMP);
    glUniform1f(glGetUniformLocation(p, "depth"), written);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    float stored = -9.0f;
    glReadPixels(1, 1, 1, 1, GL_DEPTH_COMPONENT, GL_FLOAT, &stored);
    EXPECT_EQ(stored, written < 0.0f ? 0.0f : written > 1.0f ? 1.0f : written) << "gl_FragDepth " << written;
  }
  glUseProgram(0);
  glDeleteVertexArrays(1, &vao);
  glDeleteProgram(p);
}

}  // namespace
}  // namespace nbsim

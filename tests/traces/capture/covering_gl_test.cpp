// CoveringGlTest: the GLSL covering (shaders/common/covering.glsl, inserted into every shader that
// queries an N-buffer) against the C++ core (model/nbuffer/covering.h), box for box on llvmpipe:
// the level, the squares and, over N-buffer levels built by the core and uploaded as a texture
// array, the farthest depth, for every covering and alignment, on thousands of random boxes and
// on every box that touches an image edge, of odd, power-of-two and 1-pixel-wide images.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "model/nbuffer/covering.h"
#include "model/nbuffer/nbuffer.h"
#include "nbsim_shaders.h"
#include "tests/common/gl_context_suite.h"
#include "traces/capture/draw_recorder.h"
#include "traces/capture/gl_program.h"
#include "traces/capture/glsl_nbuffer.h"

namespace nbsim {
namespace {

// One box a thread: nb_cover (or nb_cover_sprite) and the farthest texel over the squares.
constexpr const char* kShader = R"glsl(#version 450 core
layout(local_size_x = 64) in;
layout(std430, binding = 1) readonly buffer Boxes { ivec4 boxes[]; };
struct Out { int level; int count; int pad0; int pad1; ivec4 xs; ivec4 ys; float value; float pad2, pad3, pad4; };
layout(std430, binding = 2) writeonly buffer Results { Out results[]; };
uniform sampler2DArray levels;
uniform int top_level;
uniform uint count;
void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  int level;
  ivec2 sq[4];
#ifdef SPRITE
  const int n = nb_cover_sprite(boxes[i], top_level, level, sq);
#else
  const int n = nb_cover(boxes[i], top_level, level, sq);
#endif
  float f = texelFetch(levels, ivec3(sq[0], level), 0).r;
  for (int k = 1; k < n; ++k) f = max(f, texelFetch(levels, ivec3(sq[k], level), 0).r);
  results[i] = Out(level, n, 0, 0, ivec4(sq[0].x, sq[1].x, sq[2].x, sq[3].x), ivec4(sq[0].y, sq[1].y, sq[2].y, sq[3].y), f,
                   0.0, 0.0, 0.0);
}
)glsl";

struct GpuOut {
  std::int32_t level, count, pad0, pad1;
  std::int32_t xs[4], ys[4];
  float value, pad2, pad3, pad4;
};

class CoveringGlTest : public testing::GlContextSuite {
 protected:
  // The GL answers for `boxes` over `nb`'s levels, with `spec`'s covering.
  static std::vector<GpuOut> run(const NBuffer& nb, const std::vector<Rect>& boxes, CoveringSpec spec) {
    std::string defines = spec.direct_squares ? "#define SPRITE\n" : "";
    defines += capture::covering_glsl(spec);
    const GLuint prog = capture::link_program(
        {capture::compile_shader(GL_COMPUTE_SHADER, capture::with_defines(kShader, defines), "covering test")}, "covering test");
    GLuint levels = 0, in = 0, out = 0;
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &levels);
    glTextureStorage3D(levels, 1, GL_R32F, nb.width(), nb.height(), nb.level_count());
    glTextureParameteri(levels, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(levels, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    for (int k = 0; k < nb.level_count(); ++k)
      glTextureSubImage3D(levels, 0, 0, 0, k, nb.width(), nb.height(), 1, GL_RED, GL_FLOAT, nb.level(k).data());
    std::vector<std::int32_t> packed;
    for (const Rect& r : boxes) packed.insert(packed.end(), {r.x, r.y, r.w, r.h});
    glCreateBuffers(1, &in);
    glNamedBufferStorage(in, static_cast<GLsizeiptr>(packed.size() * 4), packed.data(), 0);
    glCreateBuffers(1, &out);
    glNamedBufferStorage(out, static_cast<GLsizeiptr>(boxes.size() * sizeof(GpuOut)), nullptr, 0);
    glUseProgram(prog);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, in);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, out);
    glBindTextureUnit(0, levels);
    glUniform1i(glGetUniformLocation(prog, "levels"), 0);
    glUniform1i(glGetUniformLocation(prog, "top_level"), nb.level_count() - 1);
    glUniform1ui(glGetUniformLocation(prog, "count"), static_cast<GLuint>(boxes.size()));
    glDispatchCompute(static_cast<GLuint>((boxes.size() + 63) / 64), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<GpuOut> result(boxes.size());
    glGetNamedBufferSubData(out, 0, static_cast<GLsizeiptr>(result.size() * sizeof(GpuOut)), result.data());
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
    glDeleteBuffers(1, &in);
    glDeleteBuffers(1, &out);
    glDeleteTextures(1, &levels);
    glDeleteProgram(prog);
    return result;
  }
};

// Random boxes inside the image, every box along each edge and corner, and boxes of the sides that
// matter (1, powers of two, one more than a power of two, the whole image).
std::vector<Rect> boxes_for(int w, int h, std::mt19937& rng, int random_count) {
  std::vector<Rect> boxes;
  for (int k = 0; k < random_count; ++k) {
    const int bw = std::uniform_int_distribution<int>(1, w)(rng), bh = std::uniform_int_distribution<int>(1, h)(rng);
    boxes.push_back({std::uniform_int_distribution<int>(0, w - bw)(rng), std::uniform_int_distribution<int>(0, h - bh)(rng), bw, bh});
  }
  std::vector<int> sides = {1, 2, 3};
  for (int s = 4; s <= std::max(w, h); s *= 2) sides.insert(sides.end(), {s - 1, s, s + 1});
  sides.push_back(w), sides.push_back(h);
  for (int bw : sides)
    for (int bh : sides) {
      if (bw < 1 || bh < 1 || bw > w || bh > h) continue;
      for (const auto& [x, y] : {std::pair{0, 0}, std::pair{w - bw, 0}, std::pair{0, h - bh}, std::pair{w - bw, h - bh}})
        boxes.push_back({x, y, bw, bh});
    }
  return boxes;
}

TEST_F(CoveringGlTest, ShaderCoversEveryBoxAsTheCore) {
  std::mt19937 rng(2024);
  const CoveringSpec specs[] = {{CoveringKind::Paper, CoveringAlign::Top},
                                {CoveringKind::Paper, CoveringAlign::Bottom},
                                {CoveringKind::Corners, CoveringAlign::Top},
                                {CoveringKind::Corners, CoveringAlign::Bottom},
                                {CoveringKind::One, CoveringAlign::Top},
                                {CoveringKind::One, CoveringAlign::Bottom},
                                {CoveringKind::Paper, CoveringAlign::Top, true},
                                {CoveringKind::Corners, CoveringAlign::Bottom, true}};
  int compared = 0;
  for (const auto& [w, h] : {std::pair{37, 23}, std::pair{64, 64}, std::pair{1, 40}, std::pair{129, 3}}) {
    DepthImage d(w, h, 0.0f);
    for (float& v : d.texels) v = std::uniform_real_distribution<float>(0.0f, 1.0f)(rng);
    const NBuffer nb(d);
    const std::vector<Rect> boxes = boxes_for(w, h, rng, 1500);
    for (const CoveringSpec& spec : specs) {
      const std::vector<GpuOut> gl = run(nb, boxes, spec);
      int wrong = 0;
      for (std::size_t i = 0; i < boxes.size(); ++i) {
        const Rect& r = boxes[i];
        const Covering c = cover(r, spec, nb.full_level_count() - 1);
        bool same = gl[i].level == c.level && gl[i].count == c.count;
        for (int k = 0; same && k < c.count; ++k)
          same = gl[i].xs[k] == c.squares[static_cast<std::size_t>(k)].x && gl[i].ys[k] == c.squares[static_cast<std::size_t>(k)].y;
        same = same && gl[i].value == nb.query(r, spec).value;
        if (!same && ++wrong <= 5)
          ADD_FAILURE() << covering_name(spec) << (spec.direct_squares ? " direct" : "") << " box " << r.x << "," << r.y << " " << r.w
                        << "x" << r.h << " in " << w << "x" << h << ": GL level " << gl[i].level << " count " << gl[i].count
                        << " first square " << gl[i].xs[0] << "," << gl[i].ys[0] << " value " << gl[i].value << "; core level "
                        << c.level << " count " << c.count << " first square " << c.squares[0].x << "," << c.squares[0].y;
        ++compared;
      }
      EXPECT_EQ(wrong, 0) << covering_name(spec) << " on " << w << "x" << h;
    }
  }
  EXPECT_GT(compared, 50000);
}

// Occlusion culling's own query shader (shaders/common/nbuffer_query.comp through GlslNBuffer, its
// levels built by GL from a depth texture) answers thousands of random boxes as the core does: a
// box whose nearest depth is the core's answer is visible, one a hair farther is hidden, so GL's
// farthest depth equals the core's bit for bit, for each covering and both ops.
TEST_F(CoveringGlTest, OcclusionQueryShaderAnswersAsTheCore) {
  std::mt19937 rng(77);
  for (const auto& [w, h] : {std::pair{45, 31}, std::pair{64, 32}})
    for (const FarOp op : {FarOp::Max, FarOp::Min})
      for (const CoveringSpec spec : {CoveringSpec{CoveringKind::Paper, CoveringAlign::Top},
                                      CoveringSpec{CoveringKind::Corners, CoveringAlign::Bottom},
                                      CoveringSpec{CoveringKind::One, CoveringAlign::Top}}) {
        DepthImage d(w, h, 0.0f);
        for (float& v : d.texels) v = std::uniform_real_distribution<float>(0.0f, 1.0f)(rng);
        GLuint depth = 0;
        glCreateTextures(GL_TEXTURE_2D, 1, &depth);
        glTextureStorage2D(depth, 1, GL_DEPTH_COMPONENT32F, w, h);
        glTextureSubImage2D(depth, 0, 0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, d.texels.data());
        capture::GlslNBuffer gl(w, h, op, 1 << 30, spec);
        capture::DrawRecorder recorder;
        recorder.begin_frame(64);
        gl.build(depth, recorder, {});
        const NBuffer core(d, {op});
        std::vector<Rect> boxes = boxes_for(w, h, rng, 1000);
        std::vector<scene::BoundsTest> tests;
        for (const Rect& r : boxes) {
          const float v = core.query(r, spec).value;
          const float farther = std::nextafter(v, op == FarOp::Max ? 2.0f : -1.0f);
          tests.push_back({r.x, r.y, r.w, r.h, v, false, true});
          tests.push_back({r.x, r.y, r.w, r.h, farther, false, true});
        }
        gl.query(tests);
        int wrong = 0;
        for (std::size_t i = 0; i < boxes.size(); ++i)
          if (!tests[2 * i].visible || tests[2 * i + 1].visible) {
            if (++wrong <= 5)
              ADD_FAILURE() << covering_name(spec) << " box " << boxes[i].x << "," << boxes[i].y << " " << boxes[i].w << "x"
                            << boxes[i].h << ": GL's answer differs from the core's " << core.query(boxes[i], spec).value;
          }
        EXPECT_EQ(wrong, 0) << covering_name(spec) << " " << w << "x" << h;
        glDeleteTextures(1, &depth);
      }
}

}  // namespace
}  // namespace nbsim

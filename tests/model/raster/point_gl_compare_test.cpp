// PointGlCompareTest: point sprites through the model (geometry centre clipping -> point setup ->
// rasterizer -> early depth test) against GL_POINTS drawn by Mesa's llvmpipe in a headless EGL
// context, bit for bit: per pixel the rasterized fragments (an image atomic without early
// fragment tests) and the passed samples (the same with early_fragment_tests), the final depth
// buffer, and per draw GL_SAMPLES_PASSED and the clipper's input and output primitives. Each case
// is one draw of many points with gl_PointSize from the vertex shader on a prepared depth buffer.
// UnitsReplayPointTraceExactly replays GL's draws through the SystemC units (`nbsim compare`), and
// PointReplayInputTest feeds `nbsim compare` bad point draws.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "model/common/depth.h"
#include "model/raster/raster_path.h"
#include "tests/model/raster/point_coverage.h"
#include "traces/capture/gl_program.h"
#include "traces/format/writer.h"
#include "tests/model/raster/gl_suite.h"
#include "traces/gl/context.h"
#include "tests/common/run_nbsim.h"
#include <nlohmann/json.hpp>

namespace nbsim::raster {
namespace {

using namespace nbsim::raster::testing;
using geometry::ClipControl;
using geometry::ClipPosition;

// Powers of two, so that clip x = (window x - W/2) / (W/2) is exact and ties stay ties.
constexpr int kW = 256, kH = 128;

constexpr const char* kVertex = R"(#version 450
layout(location = 0) in vec4 position;
layout(location = 1) in float size;
void main() { gl_Position = position; gl_PointSize = size; }
)";
constexpr const char* kCountFragments = R"(#version 450
layout(r32ui, binding = 0) uniform coherent uimage2D counts;
void main() { imageAtomicAdd(counts, ivec2(gl_FragCoord.xy), 1u); }
)";
constexpr const char* kCountPassed = R"(#version 450
layout(early_fragment_tests) in;
layout(r32ui, binding = 0) uniform coherent uimage2D counts;
void main() { imageAtomicAdd(counts, ivec2(gl_FragCoord.xy), 1u); }
)";

struct Case {
  std::string name;
  std::vector<ClipPosition> clip;
  std::vector<float> sizes;
  DepthFunc func = DepthFunc::Less;
  bool write = true;
  bool test = true;
  bool depth_clamp = false;  // GL_DEPTH_CLAMP: no near/far clipping, fragment depth clamped to [0, 1]
  ClipControl clip_control = ClipControl::NegativeOneToOne;
  std::vector<float> depth;  // prepared depth buffer, y up
};

struct GlResult {
  std::vector<std::uint32_t> fragments, passed;
  std::vector<float> depth;
  std::uint64_t samples_passed = 0, clip_in = 0, clip_out = 0;
  GLenum gl_error = GL_NO_ERROR;
};

GLenum gl_func(DepthFunc f) { return GL_NEVER + static_cast<GLenum>(f); }

// The GL side: one context, two programs, a depth texture and a count image.
class GlPoints {
 public:
  GlPoints() {
    count_fragments_ = capture::link_program({capture::compile_shader(GL_VERTEX_SHADER, kVertex, "points.vert"),
                                              capture::compile_shader(GL_FRAGMENT_SHADER, kCountFragments, "frag.frag")},
                                             "count fragments");
    count_passed_ = capture::link_program({capture::compile_shader(GL_VERTEX_SHADER, kVertex, "points.vert"),
                                           capture::compile_shader(GL_FRAGMENT_SHADER, kCountPassed, "passed.frag")},
                                          "count passed");
    glCreateTextures(GL_TEXTURE_2D, 1, &depth_);
    glTextureStorage2D(depth_, 1, GL_DEPTH_COMPONENT32F, kW, kH);
    glCreateTextures(GL_TEXTURE_2D, 1, &counts_);
    glTextureStorage2D(counts_, 1, GL_R32UI, kW, kH);
    glCreateFramebuffers(1, &fbo_);
    glNamedFramebufferTexture(fbo_, GL_DEPTH_ATTACHMENT, depth_, 0);
    glNamedFramebufferDrawBuffer(fbo_, GL_NONE);
    glNamedFramebufferReadBuffer(fbo_, GL_NONE);
    complete_ = glCheckNamedFramebufferStatus(fbo_, GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    glCreateVertexArrays(1, &vao_);
    glCreateBuffers(2, vbo_.data());
    // glGenQueries: Mesa's glCreateQueries refuses the pipeline-statistics targets in a 4.5 context.
    GLuint q[3] = {};
    glGenQueries(3, q);
    q_samples_ = q[0];
    q_in_ = q[1];
    q_out_ = q[2];
  }
  bool complete() const { return complete_; }

  GlResult run(const Case& c) {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glViewport(0, 0, kW, kH);
    glDepthRange(0.0, 1.0);
    glClipControl(GL_LOWER_LEFT, c.clip_control == ClipControl::ZeroToOne ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
    glEnable(GL_PROGRAM_POINT_SIZE);
    if (c.depth_clamp) glEnable(GL_DEPTH_CLAMP); else glDisable(GL_DEPTH_CLAMP);
    if (c.test) glEnable(GL_DEPTH_TEST); else glDisable(GL_DEPTH_TEST);
    glDepthFunc(gl_func(c.func));
    glDepthMask(c.write ? GL_TRUE : GL_FALSE);
    glNamedBufferData(vbo_[0], static_cast<GLsizeiptr>(c.clip.size() * sizeof(ClipPosition)), c.clip.data(), GL_STATIC_DRAW);
    glNamedBufferData(vbo_[1], static_cast<GLsizeiptr>(c.sizes.size() * sizeof(float)), c.sizes.data(), GL_STATIC_DRAW);
    glBindVertexArray(vao_);
    glBindBuffer(GL_ARRAY_BUFFER, vbo_[0]);
    glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, 0, nullptr);
    glEnableVertexAttribArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, vbo_[1]);
    glVertexAttribPointer(1, 1, GL_FLOAT, GL_FALSE, 0, nullptr);
    glEnableVertexAttribArray(1);
    glBindImageTexture(0, counts_, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);

    GlResult r;
    // Pass 1: rasterized fragments per pixel, samples passed, clipper counts, final depth.
    prepare(c);
    glUseProgram(count_fragments_);
    glBeginQuery(GL_SAMPLES_PASSED, q_samples_);
    glBeginQuery(GL_CLIPPING_INPUT_PRIMITIVES, q_in_);
    glBeginQuery(GL_CLIPPING_OUTPUT_PRIMITIVES, q_out_);
    glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(c.clip.size()));
    glEndQuery(GL_CLIPPING_OUTPUT_PRIMITIVES);
    glEndQuery(GL_CLIPPING_INPUT_PRIMITIVES);
    glEndQuery(GL_SAMPLES_PASSED);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    r.fragments = read_counts();
    r.depth.resize(static_cast<std::size_t>(kW * kH));
    glGetTextureImage(depth_, 0, GL_DEPTH_COMPONENT, GL_FLOAT, static_cast<GLsizei>(r.depth.size() * 4), r.depth.data());
    r.samples_passed = query(q_samples_);
    r.clip_in = query(q_in_);
    r.clip_out = query(q_out_);
    r.gl_error = glGetError();
    // Pass 2: the same draw on the same prepared depth, counting the fragments that pass.
    prepare(c);
    glUseProgram(count_passed_);
    glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(c.clip.size()));
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    r.passed = read_counts();
    glFinish();
    return r;
  }

 private:
  void prepare(const Case& c) {
    glTextureSubImage2D(depth_, 0, 0, 0, kW, kH, GL_DEPTH_COMPONENT, GL_FLOAT, c.depth.data());
    const GLuint zero = 0;
    glClearTexImage(counts_, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
  }
  static std::uint64_t query(GLuint q) {
    GLuint64 v = ~GLuint64{0};  // stays so when GL refuses the query
    glGetQueryObjectui64v(q, GL_QUERY_RESULT, &v);
    return v;
  }
  std::vector<std::uint32_t> read_counts() {
    std::vector<std::uint32_t> out(static_cast<std::size_t>(kW * kH));
    glGetTextureImage(counts_, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, static_cast<GLsizei>(out.size() * 4), out.data());
    return out;
  }
  GLuint count_fragments_ = 0, count_passed_ = 0, depth_ = 0, counts_ = 0, fbo_ = 0, vao_ = 0;
  std::array<GLuint, 2> vbo_{};
  GLuint q_samples_ = 0, q_in_ = 0, q_out_ = 0;
  bool complete_ = false;
};

// ---- cases ------------------------------------------------------------------------------------

const std::vector<float> kSizes = {1, 1.5f, 2, 3, 7.5f, 16, 24, 33, 64, 100, 255, 300, 0.5f, 1.001953125f};

// Depth values on a 1/64 grid so that points and stored depths are often exactly equal.
float grid_depth(Rng& r) { return static_cast<float>(r.below(65)) / 64.0f; }

std::vector<float> prepared_depth(Rng& r) {
  std::vector<float> d(static_cast<std::size_t>(kW * kH));
  for (float& v : d) v = grid_depth(r);
  return d;
}

// Clip position of window (x, y) and depth d, w = 1 (exact for the power-of-two target).
ClipPosition at_window(float x, float y, float d, ClipControl cc = ClipControl::NegativeOneToOne) {
  const float z = cc == ClipControl::ZeroToOne ? d : 2.0f * d - 1.0f;
  return {(x - kW / 2) / (kW / 2), (y - kH / 2) / (kH / 2), z, 1.0f};
}

Case base(const std::string& name, unsigned seed) {
  Case c;
  c.name = name;
  Rng r(seed);
  c.depth = prepared_depth(r);
  return c;
}

// Every size at pixel centres, on pixel edges (x.0 or y.0) and on pixel corners.
Case centres_edges_corners() {
  Case c = base("centres, edges and corners", 1);
  Rng r(101);
  const std::array<std::array<float, 2>, 4> offsets = {{{0.5f, 0.5f}, {0.0f, 0.5f}, {0.5f, 0.0f}, {0.0f, 0.0f}}};
  for (float s : kSizes)
    for (const auto& o : offsets)
      for (int k = 0; k < 6; ++k) {
        const float x = static_cast<float>(r.below(kW)) + o[0], y = static_cast<float>(r.below(kH)) + o[1];
        c.clip.push_back(at_window(x, y, grid_depth(r)));
        c.sizes.push_back(s);
      }
  return c;
}

// Centres on odd multiples of 1/512 px, where the snap to 1/256 px is a tie.
Case snap_ties() {
  Case c = base("1/512 snap ties", 2);
  Rng r(102);
  for (int k = 0; k < 400; ++k) {
    const float x = static_cast<float>(r.below(kW * 256)) / 256.0f + 1.0f / 512.0f;
    const float y = static_cast<float>(r.below(kH * 256)) / 256.0f + (k % 2 ? 1.0f / 512.0f : 0.0f);
    c.clip.push_back(at_window(x, y, grid_depth(r)));
    c.sizes.push_back(k % 3 == 0 ? kSizes[r.below(static_cast<unsigned>(kSizes.size()))]
                                 : static_cast<float>(1 + r.below(40)) + static_cast<float>(r.below(4)) / 512.0f);
  }
  c.func = DepthFunc::Lequal;
  return c;
}

// Random sub-pixel centres with random w (so the divide and the fused viewport matter), random
// sizes from 0.25 to 300.
Case random_subpixel(unsigned seed, DepthFunc func, bool write) {
  Case c = base("random sub-pixel, func " + std::to_string(static_cast<int>(func)) + (write ? "" : ", no writes"), seed);
  Rng r(seed + 1000);
  for (int k = 0; k < 500; ++k) {
    const float w = r.range(0.25f, 4.0f);
    c.clip.push_back({r.range(-1.0f, 1.0f) * w, r.range(-1.0f, 1.0f) * w, r.range(-1.0f, 1.0f) * w, w});
    c.sizes.push_back(k % 4 == 0 ? kSizes[r.below(static_cast<unsigned>(kSizes.size()))] : r.range(0.25f, 70.0f));
  }
  c.func = func;
  c.write = write;
  return c;
}

// Centres inside the viewport near its borders: the squares hang over the edges.
Case partly_offscreen() {
  Case c = base("partly off-screen", 4);
  Rng r(104);
  for (int k = 0; k < 300; ++k) {
    const float s = kSizes[r.below(static_cast<unsigned>(kSizes.size()))];
    float x = r.range(0.0f, 12.0f), y = r.range(0.0f, static_cast<float>(kH));
    if (k % 4 == 1) x = static_cast<float>(kW) - x;
    if (k % 4 == 2) std::swap(x, y), x = r.range(0.0f, static_cast<float>(kW));
    if (k % 4 == 3) y = static_cast<float>(kH) - r.range(0.0f, 12.0f), x = r.range(0.0f, static_cast<float>(kW));
    if (k % 10 == 0) x = 0.0f;                        // exactly on the left border (inside: x == -w)
    if (k % 10 == 5) y = static_cast<float>(kH);      // exactly on the top border (inside: y == w)
    c.clip.push_back(at_window(x, y, grid_depth(r)));
    c.sizes.push_back(s);
  }
  return c;
}

// Centres just outside the viewport in x or y, or beyond near and far: GL drops the whole point
// (centre clipping) although its square would overlap the viewport; mixed with points inside.
Case centres_outside() {
  Case c = base("centres outside the clip volume", 5);
  Rng r(105);
  for (int k = 0; k < 300; ++k) {
    const float s = k % 2 ? 64.0f : kSizes[r.below(static_cast<unsigned>(kSizes.size()))];
    float x = r.range(0.0f, static_cast<float>(kW)), y = r.range(0.0f, static_cast<float>(kH));
    float d = grid_depth(r);
    switch (k % 6) {
      case 0: x = -r.range(0.001f, 20.0f); break;
      case 1: x = static_cast<float>(kW) + r.range(0.001f, 20.0f); break;
      case 2: y = -r.range(0.001f, 20.0f); break;
      case 3: y = static_cast<float>(kH) + r.range(0.001f, 20.0f); break;
      case 4: d = k % 12 == 4 ? -r.range(0.0001f, 0.5f) : 1.0f + r.range(0.0001f, 0.5f); break;  // beyond near / far
      default: break;  // inside
    }
    c.clip.push_back(at_window(x, y, d));
    c.sizes.push_back(s);
  }
  // Behind the eye (w < 0) with a centre that would project inside.
  c.clip.push_back({0.1f, 0.1f, 0.0f, -1.0f});
  c.sizes.push_back(32.0f);
  c.func = DepthFunc::Always;
  return c;
}

// Reversed Z: ZERO_TO_ONE clip control, GREATER, stored and sprite depths often equal.
Case reversed_z(DepthFunc func) {
  Case c = base(std::string("reversed Z ") + (func == DepthFunc::Greater ? "GREATER" : "GEQUAL"), 6);
  Rng r(106);
  for (int k = 0; k < 400; ++k) {
    const float x = static_cast<float>(r.below(kW * 4)) / 4.0f, y = static_cast<float>(r.below(kH * 4)) / 4.0f;
    float d = grid_depth(r);
    if (k % 25 == 0) d = -r.range(0.0001f, 0.1f);  // beyond the near plane z = 0
    c.clip.push_back(at_window(x, y, d, ClipControl::ZeroToOne));
    c.sizes.push_back(kSizes[r.below(static_cast<unsigned>(kSizes.size()))]);
  }
  c.clip_control = ClipControl::ZeroToOne;
  c.func = func;
  return c;
}

// The depth test off: every fragment passes, nothing is written.
Case depth_test_off() {
  Case c = random_subpixel(7, DepthFunc::Less, true);
  c.name = "depth test disabled";
  c.test = false;
  return c;
}

// ---- comparison -------------------------------------------------------------------------------

struct Outcome {
  std::uint64_t fragments = 0, passed = 0;
};

Outcome compare(GlPoints& gl, const Case& c) {
  SCOPED_TRACE(c.name);
  const GlResult g = gl.run(c);
  EXPECT_EQ(g.gl_error, static_cast<GLenum>(GL_NO_ERROR)) << "GL reported an error";

  geometry::GeometryState gs;
  gs.clip = c.clip_control;
  gs.face.cull = geometry::CullFace::None;
  gs.depth_clamp = c.depth_clamp;
  DepthState ds;
  ds.func = c.func;
  ds.write = c.write;
  ds.test = c.test;
  DepthImage depth(kW, kH, 0.0f);
  depth.texels = c.depth;
  const PointDrawResult m = model_point_draw(c.clip, c.sizes, gs, ds, depth);
  EXPECT_EQ(m.outside, 0) << "no pixel outside the target";

  // The path the units use gives the same totals.
  DepthImage depth2(kW, kH, 0.0f);
  depth2.texels = c.depth;
  RasterPathConfig cfg;
  cfg.width_px = kW;
  cfg.height_px = kH;
  RasterPath path(cfg, depth2);
  DrawState st;
  st.geometry = gs;
  st.depth = ds;
  const DrawCounters k = path.draw_points(c.clip, c.sizes, st);
  EXPECT_EQ(k.depth.fragments, m.depth.fragments) << "RasterPath::draw_points and the per-pixel walk agree";
  EXPECT_EQ(k.depth.passed, m.depth.passed);
  EXPECT_TRUE(depth2.texels == depth.texels);

  Outcome o;
  int bad_frag = 0, bad_pass = 0, bad_depth = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const std::size_t i = static_cast<std::size_t>(y * kW + x);
      o.fragments += g.fragments[i];
      o.passed += g.passed[i];
      if (g.fragments[i] != m.fragments[i] && bad_frag++ < 5)
        ADD_FAILURE() << "pixel (" << x << ", " << y << "): GL rasterized " << g.fragments[i] << " fragments, model "
                      << m.fragments[i];
      if (g.passed[i] != m.passed[i] && bad_pass++ < 5)
        ADD_FAILURE() << "pixel (" << x << ", " << y << "): GL passed " << g.passed[i] << ", model " << m.passed[i];
      if (std::bit_cast<std::uint32_t>(g.depth[i]) != std::bit_cast<std::uint32_t>(depth.texels[i]) && bad_depth++ < 5)
        ADD_FAILURE() << "pixel (" << x << ", " << y << "): GL depth " << g.depth[i] << ", model " << depth.texels[i];
    }
  EXPECT_EQ(bad_frag, 0) << "pixels whose fragment count differs from GL's";
  EXPECT_EQ(bad_pass, 0) << "pixels whose passed count differs from GL's";
  EXPECT_EQ(bad_depth, 0) << "depth pixels not bit-identical to GL's";
  EXPECT_EQ(m.depth.fragments, o.fragments) << "rasterized fragments of the draw";
  EXPECT_EQ(m.depth.passed, g.samples_passed) << "GL_SAMPLES_PASSED";
  EXPECT_EQ(o.passed, g.samples_passed) << "GL's two passes agree";
  EXPECT_EQ(m.geometry.prims_in, g.clip_in) << "GL_CLIPPING_INPUT_PRIMITIVES";
  EXPECT_EQ(m.geometry.prims_out, g.clip_out) << "GL_CLIPPING_OUTPUT_PRIMITIVES";
  ::testing::Test::RecordProperty(c.name, std::to_string(o.fragments) + " fragments, " + std::to_string(o.passed) + " passed");
  return o;
}

using PointGlCompareTest = testing::GlSuite<GlPoints>;

// Every size from 0.5 to 300 at pixel centres, edges and corners (fill-rule ties on both axes).
TEST_F(PointGlCompareTest, CentresEdgesAndCornersMatchGl) {
  const Outcome o = compare(*gl_, centres_edges_corners());
  EXPECT_GT(o.fragments, 100000u) << "the case must rasterize big sprites";
  EXPECT_GT(o.passed, 0u);
}

// Centres on exact 1/512 px ties: llvmpipe's snap rounds them away from zero.
TEST_F(PointGlCompareTest, SnapTiesMatchGl) { EXPECT_GT(compare(*gl_, snap_ties()).fragments, 1000u); }

// Random sub-pixel centres, random w, sizes 0.25..300, under LESS, LEQUAL and GREATER, with and
// without depth writes, against a depth buffer that often equals the sprite depth.
TEST_F(PointGlCompareTest, RandomSubpixelPointsMatchGl) {
  for (const auto& [func, write] : {std::pair{DepthFunc::Less, true}, std::pair{DepthFunc::Lequal, true},
                                    std::pair{DepthFunc::Greater, true}, std::pair{DepthFunc::Less, false},
                                    std::pair{DepthFunc::Lequal, false}}) {
    const Outcome o = compare(*gl_, random_subpixel(3 + static_cast<unsigned>(func), func, write));
    EXPECT_GT(o.fragments, 10000u);
    EXPECT_GT(o.passed, 0u);
    EXPECT_LT(o.passed, o.fragments) << "the prepared depth must reject some fragments";
  }
}

// Squares partly off-screen (centres inside, down to exactly on the borders) are cut to the target.
TEST_F(PointGlCompareTest, PartlyOffscreenMatchesGl) { EXPECT_GT(compare(*gl_, partly_offscreen()).fragments, 1000u); }

// Centres outside the viewport in x/y or beyond near/far: GL draws none of those points; the
// model's clipper counts and coverage match.
TEST_F(PointGlCompareTest, CentresOutsideFrustumDropWholePoint) {
  const Case c = centres_outside();
  compare(*gl_, c);
  // Of the 301 points, 200 (cases 0..3) are outside in x or y, 50 beyond near/far, one behind the eye.
  DepthImage depth(kW, kH, 1.0f);
  depth.texels = c.depth;
  geometry::GeometryState gs;
  const PointDrawResult m = model_point_draw(c.clip, c.sizes, gs, DepthState{DepthFunc::Always, true, true}, depth);
  EXPECT_EQ(m.geometry.prims_in, 301u);
  EXPECT_EQ(m.geometry.trivially_rejected, 251u) << "centres outside, each dropped whole";
}

// Reversed Z (ZERO_TO_ONE, GREATER and GEQUAL) with equal depths.
TEST_F(PointGlCompareTest, ReversedZMatchesGl) {
  compare(*gl_, reversed_z(DepthFunc::Greater));
  compare(*gl_, reversed_z(DepthFunc::Gequal));
}

// Depth clamp: centres beyond near and far are kept and their fragments tested at 0 or 1.
TEST_F(PointGlCompareTest, DepthClampKeepsPointsBeyondNearAndFar) {
  Case c = centres_outside();
  c.name = "depth clamp";
  c.depth_clamp = true;
  c.func = DepthFunc::Lequal;
  for (std::size_t i = 0; i < c.depth.size(); i += 3) c.depth[i] = i % 2 ? 1.0f : 0.0f;  // equal to the clamped depths
  const Outcome o = compare(*gl_, c);
  EXPECT_GT(o.passed, 0u);
}

// With the depth test off every rasterized fragment passes.
TEST_F(PointGlCompareTest, DepthTestOffMatchesGl) {
  const Outcome o = compare(*gl_, depth_test_off());
  EXPECT_EQ(o.passed, o.fragments);
}

// ---- the hard cases of particle sprites, each stated as what GL draws ---------------------------

// A one-point case on the cleared (far) buffer under LESS.
Case single(const std::string& name, float x, float y, float size, float d = 0.5f) {
  Case c;
  c.name = name;
  c.depth.assign(static_cast<std::size_t>(kW * kH), 1.0f);
  c.clip.push_back(at_window(x, y, d));
  c.sizes.push_back(size);
  return c;
}

std::vector<int> covered_pixels(const GlResult& g) {
  std::vector<int> px;
  for (int i = 0; i < kW * kH; ++i)
    if (g.fragments[static_cast<std::size_t>(i)]) px.push_back(i);
  return px;
}

// GL reports llvmpipe's point size range, 1 .. 255 (PIPE_CAPF_MAX_POINT_SIZE = LP_MAX_POINT_WIDTH).
TEST_F(PointGlCompareTest, PointSizeRangeIs1To255) {
  GLfloat range[2] = {0, 0};
  glGetFloatv(GL_POINT_SIZE_RANGE, range);
  EXPECT_EQ(range[0], 1.0f);
  EXPECT_EQ(range[1], kMaxPointSizePx) << "the model's clamp must be GL's maximum";
}

// Fill-rule tie: a size-1 point centred exactly on a pixel corner, its square's edges through
// four pixel centres, covers only the pixel below and left of the corner, in GL and in the model.
TEST_F(PointGlCompareTest, CentreOnPixelCornerCoversLowerLeftPixel) {
  const Case c = single("corner tie", 10.0f, 20.0f, 1.0f);
  const GlResult g = gl_->run(c);
  EXPECT_EQ(covered_pixels(g), std::vector<int>{19 * kW + 9}) << "GL: pixel (9, 19) only";
  compare(*gl_, c);
  // On a vertical pixel edge with an even size: 2x2 centred at (10.0, 20.5) covers x 9..10, y 19..20.
  const Case e = single("edge tie", 10.0f, 20.5f, 2.0f);
  EXPECT_EQ(covered_pixels(gl_->run(e)), (std::vector<int>{19 * kW + 9, 19 * kW + 10, 20 * kW + 9, 20 * kW + 10}));
  compare(*gl_, e);
}

// Sizes beyond GL's range draw as 255 px; sub-pixel sizes as one pixel; non-powers of two (7.5:
// 1920/256 px wide, whose half rounds down in fixed point) as the model says.
TEST_F(PointGlCompareTest, SizesOutsideRangeAndNonPowersOfTwo) {
  const GlResult big = gl_->run(single("300", 128.0f, 64.0f, 300.0f));
  const GlResult max = gl_->run(single("255", 128.0f, 64.0f, 255.0f));
  EXPECT_EQ(big.fragments, max.fragments) << "GL clamps gl_PointSize 300 to 255";
  EXPECT_EQ(covered_pixels(max).size(), static_cast<std::size_t>((kW - 1) * kH)) << "255 px covers the 256x128 target but one column";
  EXPECT_EQ(covered_pixels(gl_->run(single("0.25", 100.3f, 50.7f, 0.25f))).size(), 1u) << "sub-pixel size: one pixel";
  for (float s : {1.5f, 3.0f, 7.5f, 24.0f, 33.0f, 100.0f, 300.0f, 0.25f}) compare(*gl_, single("size", 100.3f, 50.7f, s));
}

// A sprite whose depth equals the stored depth: LESS rejects every fragment, LEQUAL keeps them.
TEST_F(PointGlCompareTest, SpriteDepthEqualToStoredDepth) {
  Case c = single("equal depth", 60.5f, 40.5f, 16.0f, 0.25f);
  std::fill(c.depth.begin(), c.depth.end(), 0.25f);
  c.func = DepthFunc::Less;
  const Outcome less = compare(*gl_, c);
  EXPECT_EQ(less.fragments, 256u);
  EXPECT_EQ(less.passed, 0u) << "GL: LESS fails on equal depth";
  c.func = DepthFunc::Lequal;
  const Outcome lequal = compare(*gl_, c);
  EXPECT_EQ(lequal.passed, 256u) << "GL: LEQUAL passes on equal depth";
}

// A 64 px sprite whose centre is 0.01 px outside the viewport draws nothing in GL (centre
// clipping), although 32 of its columns would lie on screen; with the centre just inside it draws.
TEST_F(PointGlCompareTest, CentreJustOutsideDrawsNothing) {
  const Outcome out = compare(*gl_, single("centre outside", -0.01f, 64.0f, 64.0f));
  EXPECT_EQ(out.fragments, 0u);
  const Outcome in = compare(*gl_, single("centre inside", 0.0f, 64.0f, 64.0f));
  EXPECT_EQ(in.fragments, 32u * 64u) << "centre on the left border: the right half of the square";
}

// A w = 0 vertex at the origin has no outcode bit (every comparison is with 0), so GL's clipper
// hands it to setup (GL_CLIPPING_OUTPUT_PRIMITIVES counts it), whose NaN window position draws
// nothing; the model counts it alike and sets it up as Unsupported.
TEST_F(PointGlCompareTest, ZeroWPointCountedButNotDrawn) {
  Case c = single("w zero", 0, 0, 4.0f);
  c.clip = {{0, 0, 0, 0}, {0, 0, 0.5f, 0}, {-0.0f, 0, 0, 0}};
  c.sizes = {4.0f, 8.0f, 2.0f};
  const GlResult g = gl_->run(c);
  EXPECT_EQ(g.clip_in, 3u);
  EXPECT_EQ(g.clip_out, 2u) << "GL: z > w drops the second, the others reach setup";
  EXPECT_EQ(compare(*gl_, c).fragments, 0u) << "GL draws nothing for them";
}

// The SystemC model (geometry and raster units, `nbsim compare`) replays a trace of point draws
// that GL drew one after another on one depth buffer: every draw's fragments and passed samples
// equal GL's, and the final depth buffer GL's bit for bit.
TEST_F(PointGlCompareTest, UnitsReplayPointTraceExactly) {
  std::vector<Case> cases = {centres_edges_corners(), snap_ties(), random_subpixel(11, DepthFunc::Less, true),
                             random_subpixel(12, DepthFunc::Greater, false), partly_offscreen(), centres_outside(),
                             depth_test_off()};
  const std::filesystem::path t = nbsim::testing::scratch_path("nbsim_points", "points.nbt");
  std::uint64_t fragments = 0;
  {
    trace::TraceWriter w(t, {{"viewport", std::to_string(kW) + "x" + std::to_string(kH)}, {"depth_func", "LESS"},
                             {"depth_clear", "1"}, {"frames", "1"}});
    w.begin_frame(trace::FrameBegin{});
    std::vector<float> depth(static_cast<std::size_t>(kW * kH), 1.0f);  // GL's buffer, draw after draw
    std::uint32_t index = 0;
    for (Case& c : cases) {
      c.depth = depth;
      const GlResult g = gl_->run(c);
      depth = g.depth;
      trace::DrawRecord d;
      d.index = index++;
      d.topology = trace::Topology::Points;
      d.clip_positions = c.clip;
      d.point_sizes = c.sizes;
      d.state.func = static_cast<scene::DepthFunc>(c.func);
      d.state.write = c.write;
      d.state.test = c.test;
      d.state.cull = scene::CullFace::None;
      for (std::uint32_t v : g.fragments) d.gl.fragments += v;
      d.gl.samples_passed = g.samples_passed;
      d.gl.clip_prims_in = g.clip_in;
      d.gl.clip_prims_out = g.clip_out;
      fragments += d.gl.fragments;
      w.write(d);
    }
    trace::DepthSnapshot fin;
    fin.name = "final";
    fin.width = kW;
    fin.height = kH;
    fin.texels = depth;
    w.write(fin);
    trace::FrameEnd e;
    e.draws = index;
    w.end_frame(e);
    w.close();
  }
  const nbsim::testing::CliResult r = nbsim::testing::run_nbsim("compare " + t.string() + " --json");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["draws"], cases.size());
  EXPECT_EQ(j["draws_exact"], cases.size()) << r.out;
  EXPECT_EQ(j["fragments_model"], fragments);
  EXPECT_EQ(j["fragments_gl"], fragments);
  EXPECT_EQ(j["passed_model"], j["passed_gl"]);
  EXPECT_EQ(j["depth_pixels_matching"], j["depth_pixels"]);
  EXPECT_EQ(j["depth_max_abs_error"], 0.0) << "the final depth buffer is GL's bit for bit";
  std::filesystem::remove(t);
}

// A point draw with a NaN point size or an infinite position in a trace is refused by `nbsim
// compare` with exit 2 and a message naming the point, not a crash (no GL needed).
TEST(PointReplayInputTest, NonFinitePointDrawsRefused) {
  const auto trace_with = [](const std::string& name, std::vector<ClipPosition> clip, std::vector<float> sizes) {
    const std::filesystem::path t = nbsim::testing::scratch_path("nbsim_points", name);
    trace::TraceWriter w(t, {{"viewport", "16x8"}, {"depth_func", "LESS"}, {"depth_clear", "1"}, {"frames", "1"}});
    w.begin_frame(trace::FrameBegin{});
    trace::DrawRecord d;
    d.topology = trace::Topology::Points;
    d.clip_positions = std::move(clip);
    d.point_sizes = std::move(sizes);
    w.write(d);
    trace::FrameEnd e;
    e.draws = 1;
    w.end_frame(e);
    w.close();
    return t;
  };
  struct Row {
    const char* name;
    std::vector<ClipPosition> clip;
    std::vector<float> sizes;
    const char* message;
  } rows[] = {
      {"nan_size.nbt", {{0, 0, 0, 1}, {0.5f, 0, 0, 1}}, {4.0f, NAN}, "point 1 of a point draw has a NaN or infinite point size"},
      {"inf_position.nbt", {{INFINITY, 0, 0, 1}}, {4.0f}, "point 0 of a point draw has a NaN or infinite clip position"},
  };
  for (const Row& row : rows) {
    const std::filesystem::path t = trace_with(row.name, row.clip, row.sizes);
    const nbsim::testing::CliResult r = nbsim::testing::run_nbsim("compare " + t.string());
    EXPECT_EQ(r.status, 2) << row.name << ": " << r.out << r.err;
    EXPECT_TRUE(nbsim::testing::has(r.err, row.message)) << row.name << ": " << r.err;
    std::filesystem::remove(t);
  }
}

}  // namespace
}  // namespace nbsim::raster

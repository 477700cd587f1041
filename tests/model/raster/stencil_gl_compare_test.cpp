// StencilGlCompareTest: the stencil test (model/raster/stencil_test.h) through RasterPath against
// GL's stencil buffer on Mesa's llvmpipe in a headless EGL context, bit for bit. Each case is a
// sequence of draws with their own depth and stencil state (two-sided, every func and op, random
// refs and masks, both windings, culling, triangles partly off-screen and crossing near and far,
// with and without GL_DEPTH_CLAMP, both clip-control depth modes) on a prepared depth and stencil buffer: after the last draw
// the stencil buffer must equal GL's pixel for pixel (and the depth buffer too, on
// DEPTH32F_STENCIL8), and every draw's passed samples GL_SAMPLES_PASSED.
// - DEPTH32F_STENCIL8: random triangles, and the shadow-volume z-fail setup (depth LESS, no depth
//   writes, no culling, back faces INCR_WRAP and front faces DECR_WRAP on depth fail) over closed
//   boxes in perspective, some through the near plane, then a pass counting stencil == 0.
// - DEPTH24_STENCIL8 (the shadows capture's format): the same random draws and z-fail volumes,
//   the model storing llvmpipe's 24-bit depths (DepthFormat::Unorm24); GL's 24-bit depth buffer
//   must equal the model's too.
// UnitsReplayStencilTraceExactly writes GL's z-fail draws (from a cleared DEPTH24_STENCIL8 buffer)
// to a trace with the final "stencil" image and checks `nbsim compare` (the SystemC depth unit)
// against it, and
// StencilReplayInputTest feeds `nbsim compare` a trace with an out-of-range stencil op and one
// with a depth format the model does not replay, and counts discarding stencil draws.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "model/common/depth.h"
#include "model/raster/raster_path.h"
#include "model/raster/stencil_test.h"
#include "tests/common/run_nbsim.h"
#include "traces/capture/gl_program.h"
#include "traces/format/codec.h"
#include "traces/format/writer.h"
#include "tests/model/raster/gl_suite.h"
#include "traces/gl/context.h"

namespace nbsim::raster {
namespace {

using geometry::ClipPosition;
using testing::Rng;

constexpr int kW = 256, kH = 128;
constexpr std::size_t kPixels = static_cast<std::size_t>(kW) * kH;
constexpr int kMaxDraws = 512;

constexpr const char* kVertex = R"(#version 450
layout(location = 0) in vec4 position;
void main() { gl_Position = position; }
)";
// No colour buffer, nothing written: llvmpipe tests depth and stencil early.
constexpr const char* kPlain = R"(#version 450
void main() {}
)";
// Rasterized fragments per draw (an SSBO atomic, no early_fragment_tests: the tests run late).
constexpr const char* kCount = R"(#version 450
layout(std430, binding = 0) buffer Counts { uint fragments[]; };
layout(location = 0) uniform uint draw_index;
void main() { atomicAdd(fragments[draw_index], 1u); }
)";

enum class Format { D32FS8, D24S8 };

struct Draw {
  std::vector<ClipPosition> clip;
  scene::DepthState depth;
  scene::StencilState stencil;
};

struct Case {
  std::string name;
  Format format = Format::D32FS8;
  std::vector<float> depth;           // prepared depth, y up (D24S8: on the 1/64 grid)
  std::vector<std::uint8_t> stencil;  // prepared stencil, y up
  std::vector<Draw> draws;
  bool count_fragments = false;  // the counting shader (late tests) instead of the plain one
};

struct GlResult {
  std::vector<std::uint64_t> samples_passed, fragments;
  std::vector<float> depth;            // D32FS8
  std::vector<std::uint32_t> depth24;  // D24S8: the 24-bit values
  std::vector<std::uint8_t> stencil;
  GLenum gl_error = GL_NO_ERROR;
};

GLenum gl_func(scene::DepthFunc f) { return GL_NEVER + static_cast<GLenum>(f); }
GLenum gl_op(scene::StencilOp op) {
  constexpr std::array<GLenum, 8> ops = {GL_KEEP, GL_ZERO, GL_REPLACE, GL_INCR, GL_INCR_WRAP, GL_DECR, GL_DECR_WRAP, GL_INVERT};
  return ops[static_cast<std::size_t>(op)];
}
std::uint32_t to_d24(float d) { return static_cast<std::uint32_t>(std::lround(static_cast<double>(d) * 16777215.0)); }

// The GL side: one context, both programs, a texture and framebuffer per format.
class GlStencil {
 public:
  GlStencil() {
    plain_ = capture::link_program({capture::compile_shader(GL_VERTEX_SHADER, kVertex, "stencil.vert"),
                                    capture::compile_shader(GL_FRAGMENT_SHADER, kPlain, "plain.frag")},
                                   "plain");
    count_ = capture::link_program({capture::compile_shader(GL_VERTEX_SHADER, kVertex, "stencil.vert"),
                                    capture::compile_shader(GL_FRAGMENT_SHADER, kCount, "count.frag")},
                                   "count fragments");
    const std::array<GLenum, 2> formats = {GL_DEPTH32F_STENCIL8, GL_DEPTH24_STENCIL8};
    glCreateTextures(GL_TEXTURE_2D, 2, tex_.data());
    glCreateFramebuffers(2, fbo_.data());
    complete_ = true;
    for (std::size_t i = 0; i < 2; ++i) {
      glTextureStorage2D(tex_[i], 1, formats[i], kW, kH);
      glNamedFramebufferTexture(fbo_[i], GL_DEPTH_STENCIL_ATTACHMENT, tex_[i], 0);
      glNamedFramebufferDrawBuffer(fbo_[i], GL_NONE);
      glNamedFramebufferReadBuffer(fbo_[i], GL_NONE);
      complete_ = complete_ && glCheckNamedFramebufferStatus(fbo_[i], GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    }
    glCreateVertexArrays(1, &vao_);
    glCreateBuffers(1, &vbo_);
    glCreateBuffers(1, &counts_);
    glNamedBufferStorage(counts_, kMaxDraws * 4, nullptr, GL_DYNAMIC_STORAGE_BIT);
    glGenQueries(kMaxDraws, queries_.data());
  }
  bool complete() const { return complete_; }

  GlResult run(const Case& c) {
    const std::size_t f = c.format == Format::D32FS8 ? 0 : 1;
    upload(c, f);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_[f]);
    glViewport(0, 0, kW, kH);
    glDepthRange(0.0, 1.0);
    glBindVertexArray(vao_);
    glBindBuffer(GL_ARRAY_BUFFER, vbo_);
    glUseProgram(c.count_fragments ? count_ : plain_);
    const std::vector<std::uint32_t> zeros(kMaxDraws, 0);
    glNamedBufferSubData(counts_, 0, kMaxDraws * 4, zeros.data());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, counts_);
    for (std::size_t i = 0; i < c.draws.size(); ++i) {
      const Draw& d = c.draws[i];
      set_state(d);
      glNamedBufferData(vbo_, static_cast<GLsizeiptr>(d.clip.size() * sizeof(ClipPosition)), d.clip.data(), GL_STREAM_DRAW);
      glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, 0, nullptr);
      glEnableVertexAttribArray(0);
      if (c.count_fragments) glUniform1ui(0, static_cast<GLuint>(i));
      glBeginQuery(GL_SAMPLES_PASSED, queries_[i]);
      glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(d.clip.size()));
      glEndQuery(GL_SAMPLES_PASSED);
    }
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    GlResult r;
    for (std::size_t i = 0; i < c.draws.size(); ++i) {
      GLuint64 v = ~GLuint64{0};
      glGetQueryObjectui64v(queries_[i], GL_QUERY_RESULT, &v);
      r.samples_passed.push_back(v);
    }
    std::vector<std::uint32_t> counts(kMaxDraws);
    glGetNamedBufferSubData(counts_, 0, kMaxDraws * 4, counts.data());
    r.fragments.assign(counts.begin(), counts.begin() + static_cast<std::ptrdiff_t>(c.draws.size()));
    read_back(f, r);
    r.gl_error = glGetError();
    glFinish();
    return r;
  }

 private:
  static void set_state(const Draw& d) {
    if (d.depth.test) glEnable(GL_DEPTH_TEST); else glDisable(GL_DEPTH_TEST);
    glDepthFunc(gl_func(d.depth.func));
    glDepthMask(d.depth.write ? GL_TRUE : GL_FALSE);
    if (d.depth.depth_clamp) glEnable(GL_DEPTH_CLAMP); else glDisable(GL_DEPTH_CLAMP);
    glClipControl(GL_LOWER_LEFT, d.depth.clip == scene::ClipControl::ZeroToOne ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
    glFrontFace(d.depth.front_ccw ? GL_CCW : GL_CW);
    if (d.depth.cull == scene::CullFace::None) {
      glDisable(GL_CULL_FACE);
    } else {
      glEnable(GL_CULL_FACE);
      constexpr std::array<GLenum, 4> faces = {GL_BACK, GL_BACK, GL_FRONT, GL_FRONT_AND_BACK};
      glCullFace(faces[static_cast<std::size_t>(d.depth.cull)]);
    }
    if (d.stencil.test) glEnable(GL_STENCIL_TEST); else glDisable(GL_STENCIL_TEST);
    for (const auto& [face, s] : {std::pair{GLenum{GL_FRONT}, d.stencil.front}, std::pair{GLenum{GL_BACK}, d.stencil.back}}) {
      glStencilFuncSeparate(face, gl_func(s.func), s.ref, s.value_mask);
      glStencilOpSeparate(face, gl_op(s.fail), gl_op(s.depth_fail), gl_op(s.pass));
      glStencilMaskSeparate(face, s.write_mask);
    }
  }
  void upload(const Case& c, std::size_t f) {
    if (c.format == Format::D32FS8) {
      struct Texel {
        float depth;
        std::uint32_t stencil;  // low 8 bits
      };
      std::vector<Texel> t(kPixels);
      for (std::size_t i = 0; i < kPixels; ++i) t[i] = {c.depth[i], c.stencil[i]};
      glTextureSubImage2D(tex_[f], 0, 0, 0, kW, kH, GL_DEPTH_STENCIL, GL_FLOAT_32_UNSIGNED_INT_24_8_REV, t.data());
    } else {
      std::vector<std::uint32_t> t(kPixels);
      for (std::size_t i = 0; i < kPixels; ++i) t[i] = to_d24(c.depth[i]) << 8 | c.stencil[i];
      glTextureSubImage2D(tex_[f], 0, 0, 0, kW, kH, GL_DEPTH_STENCIL, GL_UNSIGNED_INT_24_8, t.data());
    }
  }
  void read_back(std::size_t f, GlResult& r) {
    r.stencil.resize(kPixels);
    if (f == 0) {
      std::vector<std::uint32_t> t(kPixels * 2);
      glGetTextureImage(tex_[f], 0, GL_DEPTH_STENCIL, GL_FLOAT_32_UNSIGNED_INT_24_8_REV, static_cast<GLsizei>(t.size() * 4),
                        t.data());
      r.depth.resize(kPixels);
      for (std::size_t i = 0; i < kPixels; ++i) {
        r.depth[i] = std::bit_cast<float>(t[2 * i]);
        r.stencil[i] = static_cast<std::uint8_t>(t[2 * i + 1] & 0xFF);
      }
    } else {
      std::vector<std::uint32_t> t(kPixels);
      glGetTextureImage(tex_[f], 0, GL_DEPTH_STENCIL, GL_UNSIGNED_INT_24_8, static_cast<GLsizei>(t.size() * 4), t.data());
      r.depth24.resize(kPixels);
      for (std::size_t i = 0; i < kPixels; ++i) {
        r.stencil[i] = static_cast<std::uint8_t>(t[i] & 0xFF);
        r.depth24[i] = t[i] >> 8;
      }
    }
  }
  GLuint plain_ = 0, count_ = 0, vao_ = 0, vbo_ = 0, counts_ = 0;
  std::array<GLuint, 2> tex_{}, fbo_{};
  std::array<GLuint, kMaxDraws> queries_{};
  bool complete_ = false;
};

// ---- cases ------------------------------------------------------------------------------------

// Stencil values mostly 0..3 so that comparisons tie often, sometimes any byte.
std::uint8_t small_stencil(Rng& r) { return static_cast<std::uint8_t>(r.below(4) == 0 ? r.below(256) : r.below(4)); }

scene::StencilFace random_face(Rng& r) {
  scene::StencilFace f;
  f.func = static_cast<scene::DepthFunc>(r.below(8));
  f.ref = r.below(5) == 0 ? static_cast<std::int32_t>(r.below(341)) - 20 : static_cast<std::int32_t>(r.below(4));  // -20..320
  f.value_mask = r.below(3) == 0 ? static_cast<std::uint32_t>(r.e()) : 0xFFFFFFFFu;
  f.write_mask = r.below(3) == 0 ? static_cast<std::uint32_t>(r.e()) : (r.below(8) == 0 ? 0u : 0xFFFFFFFFu);
  f.fail = static_cast<scene::StencilOp>(r.below(8));
  f.depth_fail = static_cast<scene::StencilOp>(r.below(8));
  f.pass = static_cast<scene::StencilOp>(r.below(8));
  return f;
}

// A draw of 1 to 4 random triangles with random depth and stencil state, a quarter of them with
// ZERO_TO_ONE clip control.
Draw random_draw(Rng& r) {
  Draw d;
  const unsigned n = 1 + r.below(4);
  for (unsigned t = 0; t < 3 * n; ++t) {
    const float w = r.range(0.5f, 2.0f);
    const float z = r.range(-1.3f, 1.3f) * w;  // some vertices beyond near or far
    d.clip.push_back({r.range(-1.4f, 1.4f) * w, r.range(-1.4f, 1.4f) * w, z, w});
  }
  d.depth.test = r.below(8) != 0;
  d.depth.func = static_cast<scene::DepthFunc>(r.below(8));
  d.depth.write = r.below(3) != 0;
  d.depth.cull = r.below(4) == 0 ? static_cast<scene::CullFace>(1 + r.below(2)) : scene::CullFace::None;
  d.depth.front_ccw = r.below(2) == 0;
  d.depth.depth_clamp = r.below(3) == 0;
  if (r.below(4) == 0) d.depth.clip = scene::ClipControl::ZeroToOne;
  d.stencil.test = r.below(10) != 0;
  d.stencil.front = random_face(r);
  d.stencil.back = r.below(4) == 0 ? d.stencil.front : random_face(r);
  return d;
}

Case random_case(const std::string& name, unsigned seed, Format format, int draws) {
  Case c;
  c.name = name;
  c.format = format;
  Rng r(seed);
  c.depth.resize(kPixels);
  c.stencil.resize(kPixels);
  for (std::size_t i = 0; i < kPixels; ++i) {
    c.depth[i] = static_cast<float>(r.below(65)) / 64.0f;
    c.stencil[i] = small_stencil(r);
  }
  for (int k = 0; k < draws; ++k) c.draws.push_back(random_draw(r));
  return c;
}

// Column-major perspective (fovy 60 degrees, aspect W/H, near 1, far 10) of an eye-space point.
ClipPosition project(float x, float y, float z) {
  const float f = 1.0f / std::tan(0.5236f), aspect = static_cast<float>(kW) / kH, n = 1.0f, fa = 10.0f;
  return {f / aspect * x, f * y, (fa + n) / (n - fa) * z + 2.0f * fa * n / (n - fa), -z};
}

// The 12 triangles of an eye-space box, counter-clockwise seen from outside.
std::vector<ClipPosition> box(const std::array<float, 3>& lo, const std::array<float, 3>& hi) {
  const auto corner = [&](int i) { return std::array<float, 3>{i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1], i & 4 ? hi[2] : lo[2]}; };
  // Faces as corner quads (a, b, c, d) counter-clockwise seen from outside.
  constexpr std::array<std::array<int, 4>, 6> faces = {{{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}}};
  std::vector<ClipPosition> out;
  for (const auto& q : faces)
    for (const int i : {q[0], q[1], q[2], q[0], q[2], q[3]}) {
      const auto p = corner(i);
      out.push_back(project(p[0], p[1], p[2]));
    }
  return out;
}

// Shadow-volume z-fail state: depth LESS without writes, no culling, two-sided stencil.
Draw zfail_draw(std::vector<ClipPosition> clip, bool depth_clamp) {
  Draw d;
  d.clip = std::move(clip);
  d.depth.func = scene::DepthFunc::Less;
  d.depth.write = false;
  d.depth.cull = scene::CullFace::None;
  d.depth.depth_clamp = depth_clamp;
  d.stencil.test = true;
  d.stencil.front.depth_fail = scene::StencilOp::DecrWrap;
  d.stencil.back.depth_fail = scene::StencilOp::IncrWrap;
  return d;
}

// A full-screen quad at window depth 0.5 passing where stencil == 0 (the lit pixels), depth off.
Draw lit_pass() {
  Draw d;
  d.clip = {{-1, -1, 0, 1}, {1, -1, 0, 1}, {1, 1, 0, 1}, {-1, -1, 0, 1}, {1, 1, 0, 1}, {-1, 1, 0, 1}};
  d.depth.test = false;
  d.depth.write = false;
  d.depth.cull = scene::CullFace::None;
  d.stencil.test = true;
  d.stencil.front.func = d.stencil.back.func = scene::DepthFunc::Equal;
  return d;
}

// Boxes in perspective over a blocky receiver depth, some through the near plane (clipped, or
// clamped with GL_DEPTH_CLAMP), then the lit pass.
std::vector<Draw> zfail_draws(Rng& r, int boxes) {
  std::vector<Draw> draws;
  for (int b = 0; b < boxes; ++b) {
    const float cx = r.range(-2.5f, 2.5f), cy = r.range(-1.2f, 1.2f), cz = r.range(-5.0f, -1.2f);
    const float hx = r.range(0.1f, 1.2f), hy = r.range(0.1f, 1.0f), hz = r.range(0.2f, 2.5f);
    draws.push_back(zfail_draw(box({cx - hx, cy - hy, cz - hz}, {cx + hx, cy + hy, std::min(cz + hz, -0.2f)}), b % 2 == 0));
  }
  draws.push_back(lit_pass());
  return draws;
}

Case zfail_case(unsigned seed, Format format = Format::D32FS8) {
  Case c;
  c.name = format == Format::D24S8 ? "shadow-volume z-fail, D24_S8" : "shadow-volume z-fail";
  c.format = format;
  Rng r(seed);
  c.depth.resize(kPixels);
  c.stencil.assign(kPixels, 0);
  std::vector<float> blocks(static_cast<std::size_t>((kW / 8) * (kH / 8)));
  for (float& v : blocks) v = r.range(0.45f, 0.95f);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      c.depth[static_cast<std::size_t>(y * kW + x)] = blocks[static_cast<std::size_t>((y / 8) * (kW / 8) + x / 8)];
  c.draws = zfail_draws(r, 60);
  return c;
}

// The same with glFrontFace(GL_CW): the boxes' outside faces are now back faces, so the counts
// run the other way (255 wraps) and the lit pass still finds the pixels outside every volume.
Case zfail_cw_case(unsigned seed) {
  Case c = zfail_case(seed);
  c.name = "shadow-volume z-fail, front faces clockwise";
  for (Draw& d : c.draws) d.depth.front_ccw = false;
  return c;
}

// ---- comparison -------------------------------------------------------------------------------

struct ModelResult {
  std::vector<DrawCounters> draws;
  DepthImage depth;
  StencilImage stencil;
};

raster::DrawState model_state(const Draw& d) {
  raster::DrawState s;
  s.geometry.clip = static_cast<geometry::ClipControl>(d.depth.clip);
  s.geometry.face.cull = static_cast<geometry::CullFace>(d.depth.cull);
  s.geometry.face.front_ccw = d.depth.front_ccw;
  s.geometry.depth_clamp = d.depth.depth_clamp;
  s.depth.func = static_cast<DepthFunc>(d.depth.func);
  s.depth.test = d.depth.test;
  s.depth.write = d.depth.write;
  if (d.stencil.test) s.stencil = stencil_state(d.stencil);
  return s;
}

ModelResult run_model(const Case& c) {
  ModelResult m;
  m.depth = DepthImage(kW, kH, 1.0f);
  m.depth.texels = c.depth;
  m.stencil = StencilImage(kW, kH, 0);
  m.stencil.texels = c.stencil;
  RasterPathConfig cfg;
  cfg.width_px = kW;
  cfg.height_px = kH;
  if (c.format == Format::D24S8) {  // the buffer holds the 24-bit values GL was given
    cfg.depth_format = DepthFormat::Unorm24;
    for (float& d : m.depth.texels) d = from_unorm24(to_d24(d));
  }
  RasterPath path(cfg, m.depth, m.stencil);
  for (const Draw& d : c.draws) m.draws.push_back(path.draw(d.clip, model_state(d)));
  return m;
}

struct Outcome {
  std::uint64_t stencil_tests = 0, changed = 0, passed = 0;
};

Outcome compare(GlStencil& gl, const Case& c) {
  SCOPED_TRACE(c.name);
  const GlResult g = gl.run(c);
  EXPECT_EQ(g.gl_error, static_cast<GLenum>(GL_NO_ERROR)) << "GL reported an error";
  const ModelResult m = run_model(c);
  Outcome o;
  int bad_draws = 0;
  for (std::size_t i = 0; i < c.draws.size(); ++i) {
    const DrawCounters& k = m.draws[i];
    o.stencil_tests += k.stencil.tests;
    o.changed += k.stencil.changed;
    o.passed += k.depth.passed;
    if (k.depth.passed != g.samples_passed[i] && bad_draws++ < 5)
      ADD_FAILURE() << "draw " << i << ": GL_SAMPLES_PASSED " << g.samples_passed[i] << ", model " << k.depth.passed;
    if (c.count_fragments && k.depth.fragments != g.fragments[i] && bad_draws++ < 5)
      ADD_FAILURE() << "draw " << i << ": GL rasterized " << g.fragments[i] << " fragments, model " << k.depth.fragments;
  }
  EXPECT_EQ(bad_draws, 0) << "draws whose passed samples (or fragments) differ from GL's";
  int bad_stencil = 0, bad_depth = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const std::size_t i = static_cast<std::size_t>(y * kW + x);
      if (g.stencil[i] != m.stencil.texels[i] && bad_stencil++ < 5)
        ADD_FAILURE() << "pixel (" << x << ", " << y << "): GL stencil " << int{g.stencil[i]} << ", model "
                      << int{m.stencil.texels[i]} << " (prepared " << int{c.stencil[i]} << ")";
      if (c.format == Format::D32FS8 &&
          std::bit_cast<std::uint32_t>(g.depth[i]) != std::bit_cast<std::uint32_t>(m.depth.texels[i]) && bad_depth++ < 5)
        ADD_FAILURE() << "pixel (" << x << ", " << y << "): GL depth " << g.depth[i] << ", model " << m.depth.texels[i];
      if (c.format == Format::D24S8 && g.depth24[i] != to_d24(m.depth.texels[i]) && bad_depth++ < 5)
        ADD_FAILURE() << "pixel (" << x << ", " << y << "): GL 24-bit depth " << g.depth24[i] << ", model "
                      << to_d24(m.depth.texels[i]);
    }
  EXPECT_EQ(bad_stencil, 0) << "stencil pixels not identical to GL's";
  EXPECT_EQ(bad_depth, 0) << "depth pixels not bit-identical to GL's";
  ::testing::Test::RecordProperty(c.name, std::to_string(c.draws.size()) + " draws, " + std::to_string(o.stencil_tests) +
                                              " stencil tests, " + std::to_string(o.changed) + " values changed");
  return o;
}

using StencilGlCompareTest = testing::GlSuite<GlStencil>;

// Random triangles and random two-sided stencil state on DEPTH32F_STENCIL8, early tests.
TEST_F(StencilGlCompareTest, RandomStateD32FS8MatchesGl) {
  const Outcome o = compare(*gl_, random_case("random D32F_S8", 1, Format::D32FS8, 300));
  EXPECT_GT(o.stencil_tests, 100000u) << "the draws must test many fragments";
  EXPECT_GT(o.changed, 10000u) << "and change many stencil values";
}

// The same with the fragment-counting shader: llvmpipe tests late (the shader writes memory);
// the stencil buffer must not care, and every draw's rasterized fragments match too.
TEST_F(StencilGlCompareTest, RandomStateLateTestsMatchGl) {
  Case c = random_case("random D32F_S8, late tests", 2, Format::D32FS8, 150);
  c.count_fragments = true;
  const Outcome o = compare(*gl_, c);
  EXPECT_GT(o.changed, 5000u);
}

// The same on DEPTH24_STENCIL8: the model compares and stores llvmpipe's 24-bit depths.
TEST_F(StencilGlCompareTest, RandomStateD24S8MatchesGl) {
  const Outcome o = compare(*gl_, random_case("random D24_S8", 3, Format::D24S8, 250));
  EXPECT_GT(o.changed, 10000u);
}

// Shadow volumes, z-fail: closed boxes in perspective over a receiver depth buffer, half of
// them with GL_DEPTH_CLAMP; then the lit pass counts stencil == 0.
TEST_F(StencilGlCompareTest, ZFailShadowVolumesMatchGl) {
  const Case c = zfail_case(4);
  const Outcome o = compare(*gl_, c);
  EXPECT_GT(o.changed, 10000u) << "volumes must cover receivers";
  const GlResult g = gl_->run(c);
  std::uint64_t zero = 0;
  for (std::uint8_t s : g.stencil) zero += s == 0 ? 1 : 0;
  EXPECT_EQ(g.samples_passed.back(), zero) << "the lit pass passes where stencil == 0";
  EXPECT_LT(zero, kPixels) << "some pixels must be in shadow";
  EXPECT_GT(zero, 0u) << "some pixels must be lit";
}

// One frame of `c`'s draws with GL's counters, the final depth when `with_depth`, and `stencil` as
// the frame's "stencil" image.
void write_trace(const std::filesystem::path& file, const Case& c, const GlResult& g, const std::vector<std::uint8_t>& stencil,
                 bool with_depth) {
  trace::TraceWriter w(file, {{"viewport", std::to_string(kW) + "x" + std::to_string(kH)},
                              {"depth_format", c.format == Format::D24S8 ? "DEPTH24_STENCIL8" : "DEPTH32F_STENCIL8"},
                              {"depth_func", "LESS"}, {"depth_clear", "1"}, {"frames", "1"}});
  w.begin_frame(trace::FrameBegin{});
  for (std::size_t i = 0; i < c.draws.size(); ++i) {
    trace::DrawRecord d;
    d.index = static_cast<std::uint32_t>(i);
    d.clip_positions = c.draws[i].clip;
    d.state = c.draws[i].depth;
    d.stencil = c.draws[i].stencil;
    d.gl.fragments = g.fragments[i];
    d.gl.samples_passed = g.samples_passed[i];
    w.write(d);
  }
  if (with_depth) {
    trace::DepthSnapshot fin;
    fin.name = "final";
    fin.width = kW;
    fin.height = kH;
    fin.texels = g.depth;
    if (c.format == Format::D24S8)
      for (const std::uint32_t q : g.depth24) fin.texels.push_back(from_unorm24(q));
    w.write(fin);
  }
  trace::StencilSnapshot st;
  st.name = "stencil";
  st.width = kW;
  st.height = kH;
  st.texels = stencil;
  w.write(st);
  trace::FrameEnd e;
  e.draws = static_cast<std::uint32_t>(c.draws.size());
  w.end_frame(e);
  w.close();
}

// z-fail on DEPTH24_STENCIL8, the shadows capture's format.
TEST_F(StencilGlCompareTest, ZFailShadowVolumesD24S8MatchGl) {
  const Outcome o = compare(*gl_, zfail_case(7, Format::D24S8));
  EXPECT_GT(o.changed, 10000u);
}

// z-fail with glFrontFace(GL_CW): the volumes' stencil counts wrap below zero.
TEST_F(StencilGlCompareTest, ZFailClockwiseFrontMatchesGl) {
  const Outcome o = compare(*gl_, zfail_cw_case(6));
  EXPECT_GT(o.changed, 10000u);
}

// The SystemC model (depth unit, `nbsim compare`) replays a trace of z-fail shadow volumes that
// GL drew into DEPTH24_STENCIL8 from a cleared buffer (depth 1, stencil 0) after receiver draws: every draw exact and
// the final stencil buffer equal to the trace's "stencil" image.
TEST_F(StencilGlCompareTest, UnitsReplayStencilTraceExactly) {
  Case c;
  c.name = "trace";
  c.format = Format::D24S8;
  c.count_fragments = true;
  c.depth.assign(kPixels, 1.0f);
  c.stencil.assign(kPixels, 0);
  Rng r(5);
  for (int k = 0; k < 30; ++k) {  // receivers: random triangles writing depth, no stencil test
    Draw d = random_draw(r);
    d.depth = scene::DepthState{};
    d.depth.cull = scene::CullFace::None;
    d.stencil.test = false;
    c.draws.push_back(d);
  }
  for (Draw& d : zfail_draws(r, 40)) c.draws.push_back(d);
  for (int k = 0; k < 20; ++k) c.draws.push_back(random_draw(r));  // and random stencil state
  const GlResult g = gl_->run(c);
  ASSERT_EQ(g.gl_error, static_cast<GLenum>(GL_NO_ERROR));
  const std::filesystem::path t = nbsim::testing::scratch_path("nbsim_stencil", "stencil.nbt");
  write_trace(t, c, g, g.stencil, true);
  const nbsim::testing::CliResult res = nbsim::testing::run_nbsim("compare " + t.string() + " --json");
  ASSERT_EQ(res.status, 0) << res.out << res.err;
  const auto j = nlohmann::json::parse(res.out);
  EXPECT_EQ(j["draws"], c.draws.size());
  EXPECT_EQ(j["draws_exact"], c.draws.size()) << res.out;
  EXPECT_EQ(j["stencil_pixels"], kPixels);
  EXPECT_EQ(j["stencil_pixels_matching"], kPixels) << res.out;
  EXPECT_GT(j["stencil_tests"].get<std::uint64_t>(), 10000u);
  EXPECT_EQ(j["depth_max_abs_error"], 0.0) << "the final depth buffer is GL's bit for bit";
  // `nbsim replay`'s statistics: the stencil counters and the stencil plane's memory traffic.
  {
    const std::filesystem::path out = nbsim::testing::scratch_path("nbsim_stencil", "run");
    const nbsim::testing::CliResult rep = nbsim::testing::run_nbsim("replay " + t.string() + " --out " + out.string());
    ASSERT_EQ(rep.status, 0) << rep.out << rep.err;
    std::ifstream in(out / "run.json");
    const auto run = nlohmann::json::parse(in);
    const auto& depth = run["stats"]["gpu.depth"];
    std::uint64_t stencil_draws = 0;
    for (const Draw& d : c.draws) stencil_draws += d.stencil.test ? 1 : 0;
    EXPECT_EQ(depth["stencil_draws"], stencil_draws);
    EXPECT_EQ(depth["stencil_draws_unmodelled"], 0) << "no draw discards or writes depth";
    EXPECT_EQ(depth["stencil_tests"], j["stencil_tests"]);
    EXPECT_GT(depth["stencil_changed"].get<std::uint64_t>(), 0u);
    EXPECT_LE(depth["stencil_changed"].get<std::uint64_t>(), depth["stencil_written"].get<std::uint64_t>());
    EXPECT_GT(depth["stencil_read_bytes"].get<std::uint64_t>(), 0u) << "stencil tiles are read through the cache";
    EXPECT_EQ(run["stats"]["gpu.memory"]["bytes_stencil"],
              depth["stencil_read_bytes"].get<std::uint64_t>() + depth["stencil_write_bytes"].get<std::uint64_t>())
        << "the memory channel's stencil client moved the stencil plane's bytes";
    EXPECT_EQ(run["frames"][0]["stencil_pixels_matching"], kPixels);
    std::filesystem::remove_all(out);
  }
  // A stencil image one pixel off is reported, and the run leaves the thresholds (exit 1).
  {
    std::vector<std::uint8_t> wrong = g.stencil;
    wrong[static_cast<std::size_t>(3 * kW + 7)] ^= 0x10;
    const std::filesystem::path t2 = nbsim::testing::scratch_path("nbsim_stencil", "stencil_off.nbt");
    write_trace(t2, c, g, wrong, false);
    const nbsim::testing::CliResult off = nbsim::testing::run_nbsim("compare " + t2.string());
    EXPECT_EQ(off.status, 1) << off.out << off.err;
    EXPECT_TRUE(nbsim::testing::has(off.out, "stencil pixels     32767 of 32768")) << off.out;
    EXPECT_TRUE(nbsim::testing::has(off.out, "frame 0 pixel (7, 3): model")) << off.out;
    std::filesystem::remove(t2);
  }
  std::filesystem::remove(t);
}

// A trace whose draw has a stencil op outside GL's eight is refused by `nbsim compare` with exit 2
// and a message naming the field (the trace reader checks every enum), not a crash (no GL needed).
TEST(StencilReplayInputTest, OutOfRangeStencilOpRefused) {
  trace::DrawRecord d;
  d.clip_positions = {{-1, -1, 0, 1}, {1, -1, 0, 1}, {-1, 1, 0, 1}};
  d.stencil.test = true;
  d.stencil.back.write_mask = 0x55667788u;  // a marker: stencil.back.fail is the byte after it
  std::vector<std::uint8_t> payload = trace::encode(trace::DrawBatch{{d}});
  const std::array<std::uint8_t, 4> marker = {0x88, 0x77, 0x66, 0x55};
  const auto at = std::search(payload.begin(), payload.end(), marker.begin(), marker.end());
  ASSERT_NE(at, payload.end());
  at[4] = 9;  // stencil.back.fail = 9
  std::vector<std::uint8_t> file;
  const auto pre = trace::encode_preamble(trace::kFormatVersion);
  file.assign(pre.begin(), pre.end());
  const auto add = [&](trace::ChunkType type, const std::vector<std::uint8_t>& p) {
    const std::vector<std::uint8_t> ch = trace::encode_chunk(type, p, false);
    file.insert(file.end(), ch.begin(), ch.end());
  };
  add(trace::ChunkType::Header,
      trace::encode(trace::Properties{{"viewport", "16x8"}, {"depth_func", "LESS"}, {"depth_clear", "1"}, {"frames", "1"}}));
  add(trace::ChunkType::FrameBegin, trace::encode(trace::FrameBegin{}));
  add(trace::ChunkType::DrawBatch, payload);
  trace::FrameEnd e;
  e.draws = 1;
  add(trace::ChunkType::FrameEnd, trace::encode(e));
  add(trace::ChunkType::End, trace::encode(trace::EndMarker{4, 1}));
  const std::filesystem::path t = nbsim::testing::scratch_path("nbsim_stencil", "bad_op.nbt");
  std::ofstream(t, std::ios::binary).write(reinterpret_cast<const char*>(file.data()), static_cast<std::streamsize>(file.size()));
  const nbsim::testing::CliResult r = nbsim::testing::run_nbsim("compare " + t.string());
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_TRUE(nbsim::testing::has(r.err, "field 'stencil.back.fail' is 9")) << r.err;
  std::filesystem::remove(t);
}

// A depth_format the model does not replay is refused with exit 2 naming it, before any draw.
TEST(StencilReplayInputTest, UnknownDepthFormatRefused) {
  const std::filesystem::path t = nbsim::testing::scratch_path("nbsim_stencil", "d16.nbt");
  {
    trace::TraceWriter w(t, {{"viewport", "16x8"}, {"depth_format", "DEPTH_COMPONENT16"}, {"depth_func", "LESS"},
                             {"depth_clear", "1"}, {"frames", "1"}});
    w.begin_frame(trace::FrameBegin{});
    trace::FrameEnd e;
    w.end_frame(e);
    w.close();
  }
  const nbsim::testing::CliResult r = nbsim::testing::run_nbsim("compare " + t.string());
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_TRUE(nbsim::testing::has(r.err, "depth_format 'DEPTH_COMPONENT16' is not one the model replays")) << r.err;
  std::filesystem::remove(t);
}

// A stencil draw whose fragment shader may discard or writes depth is replayed as if it kept
// every fragment at its interpolated depth, and counted as such (no GL needed).
TEST(StencilReplayInputTest, DiscardingStencilDrawsAreCounted) {
  const std::filesystem::path t = nbsim::testing::scratch_path("nbsim_stencil", "discard.nbt");
  {
    trace::TraceWriter w(t, {{"viewport", "16x8"}, {"depth_func", "LESS"}, {"depth_clear", "1"}, {"frames", "1"}});
    w.begin_frame(trace::FrameBegin{});
    trace::DrawRecord d;
    d.clip_positions = {{-1, -1, 0, 1}, {1, -1, 0, 1}, {-1, 1, 0, 1}};
    d.stencil.test = true;
    d.stencil.front.pass = d.stencil.back.pass = scene::StencilOp::IncrWrap;
    for (const auto& [discards, writes_depth] : {std::pair{true, false}, std::pair{false, true}, std::pair{false, false}}) {
      d.discards = discards;
      d.writes_depth = writes_depth;
      w.write(d);
      ++d.index;
    }
    trace::FrameEnd e;
    e.draws = d.index;
    w.end_frame(e);
    w.close();
  }
  const std::filesystem::path out = nbsim::testing::scratch_path("nbsim_stencil", "discard_run");
  const nbsim::testing::CliResult r = nbsim::testing::run_nbsim("replay " + t.string() + " --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  std::ifstream in(out / "run.json");
  const auto run = nlohmann::json::parse(in);
  EXPECT_EQ(run["stats"]["gpu.depth"]["stencil_draws"], 3);
  EXPECT_EQ(run["stats"]["gpu.depth"]["stencil_draws_unmodelled"], 2) << "the discarding and the depth-writing draw";
  EXPECT_EQ(run["stats"]["gpu.depth"]["stencil_tests"], run["stats"]["gpu.depth"]["fragments"]);
  std::filesystem::remove_all(out);
  std::filesystem::remove(t);
}

}  // namespace
}  // namespace nbsim::raster

// Depth peeling into a layered R32F texture; see peel.h.
#include "traces/capture/ldi/peel.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "model/common/error.h"
#include "nbsim_shaders.h"
#include "traces/capture/draw_recorder.h"
#include "traces/capture/gl_program.h"
#include "model/ldi/roles.h"

namespace nbsim::capture {
namespace {

double dot(const mesh::Vec3d& a, const mesh::Vec3d& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// GL objects of one peel, deleted on every path out (a throw included).
struct PeelObjects {
  GLuint program = 0, vao = 0, vbo = 0, ebo = 0, ssbo = 0, query = 0, fbo = 0, depth = 0, array = 0;
  GLuint ping[2] = {0, 0};
  bool keep = false;  // the array texture goes to the caller
  GLint clip_origin = 0, clip_depth = 0;  // the clip control to restore (0: not changed)
  ~PeelObjects() {
    if (clip_origin != 0) glClipControl(static_cast<GLenum>(clip_origin), static_cast<GLenum>(clip_depth));
    glDeleteProgram(program);
    glDeleteVertexArrays(1, &vao);
    GLuint buffers[] = {vbo, ebo, ssbo};
    glDeleteBuffers(3, buffers);
    glDeleteQueries(1, &query);
    glDeleteFramebuffers(1, &fbo);
    GLuint textures[] = {depth, keep ? 0u : array, ping[0], ping[1]};
    glDeleteTextures(4, textures);
  }
};

}  // namespace

OrthoMapping OrthoMapping::fit_unit_cube(const mesh::OrthoFrame& frame, int width, int height) {
  if (width < 1 || width > ldi::kMaxSideTexels || height < 1 || height > ldi::kMaxSideTexels)
    throw InputError(fmt::format("peel: viewport {}x{} outside [1, {}]", width, height, ldi::kMaxSideTexels));
  OrthoMapping m;
  m.frame = frame;
  m.width = width;
  m.height = height;
  m.u0 = m.v0 = m.t0 = std::numeric_limits<double>::infinity();
  m.u1 = m.v1 = m.t1 = -std::numeric_limits<double>::infinity();
  for (int c = 0; c < 8; ++c) {
    const mesh::Vec3d p{double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1)};
    const double u = dot(p, frame.right), v = dot(p, frame.up), t = dot(p, frame.direction);
    m.u0 = std::min(m.u0, u), m.u1 = std::max(m.u1, u);
    m.v0 = std::min(m.v0, v), m.v1 = std::max(m.v1, v);
    m.t0 = std::min(m.t0, t), m.t1 = std::max(m.t1, t);
  }
  if (!(m.u1 > m.u0 && m.v1 > m.v0 && m.t1 > m.t0)) throw InputError("peel: the view frame is degenerate");
  return m;
}

mesh::Vec3d OrthoMapping::texel_line_point(int x, int y) const {
  const double u = u0 + (x + 0.5) * (u1 - u0) / width;
  const double v = v0 + (y + 0.5) * (v1 - v0) / height;
  const mesh::Vec3d& r = frame.right;
  const mesh::Vec3d& up = frame.up;
  const mesh::Vec3d& d = frame.direction;
  return {u * r[0] + v * up[0] + t0 * d[0], u * r[1] + v * up[1] + t0 * d[1], u * r[2] + v * up[2] + t0 * d[2]};
}

std::array<double, 3> OrthoMapping::project(const mesh::Vec3d& p) const {
  return {2.0 * (dot(p, frame.right) - u0) / (u1 - u0) - 1.0, 2.0 * (dot(p, frame.up) - v0) / (v1 - v0) - 1.0,
          linear_depth(dot(p, frame.direction))};
}

PeelResult peel_ldi(const mesh::TriMesh& m, const mesh::OrthoFrame& frame, const PeelConfig& config, DrawRecorder* recorder) {
  if (config.max_layers < 1 || config.max_layers > ldi::kMaxLayers)
    throw InputError(fmt::format("peel: max_layers {} outside [1, {}]", config.max_layers, ldi::kMaxLayers));
  const OrthoMapping map = OrthoMapping::fit_unit_cube(frame, config.width_px, config.height_px);
  const int w = config.width_px, h = config.height_px;
  for (const mesh::Tri& t : m.triangles)
    for (std::uint32_t i : t)
      if (i >= m.vertices.size()) throw InputError("peel: the mesh has an out-of-range vertex index");

  std::vector<float> vertices;
  vertices.reserve(m.vertices.size() * 3);
  for (const mesh::Vec3f& p : m.vertices) {
    const auto q = map.project({p[0], p[1], p[2]});
    for (double c : q) vertices.push_back(static_cast<float>(c));
  }

  PeelObjects o;
  o.program = link_program({compile_shader(GL_VERTEX_SHADER, shaders::ldi_peel_vert, "ldi/peel.vert"),
                            compile_shader(GL_FRAGMENT_SHADER, shaders::ldi_peel_frag, "ldi/peel.frag")},
                           "ldi peel", true);
  static_assert(sizeof(mesh::Tri) == 3 * sizeof(std::uint32_t));
  make_triangle_vertex_array(vertices, {reinterpret_cast<const std::uint32_t*>(m.triangles.data()), m.triangles.size() * 3}, o.vao, o.vbo,
                             o.ebo);

  // One fragment counter per pass, the last pass (which writes nothing) included.
  const int max_passes = config.max_layers + 1;
  glCreateBuffers(1, &o.ssbo);
  const std::vector<std::uint32_t> zeros(static_cast<std::size_t>(max_passes), 0u);
  glNamedBufferStorage(o.ssbo, static_cast<GLsizeiptr>(zeros.size() * 4), zeros.data(), GL_DYNAMIC_STORAGE_BIT);
  glCreateQueries(GL_SAMPLES_PASSED, 1, &o.query);

  // Not reading the layer we render to: each pass renders into one of two 2D R32F textures
  // (ping-pong) and samples the other, which holds the previous layer; the finished layer is then
  // copied (glCopyImageSubData) into the array texture, which is never attached nor sampled while
  // drawing. So no image is both attached and sampled in a draw: no feedback loop in GL's rules.
  glCreateTextures(GL_TEXTURE_2D, 2, o.ping);
  for (GLuint t : o.ping) {
    glTextureStorage2D(t, 1, GL_R32F, w, h);
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  }
  glCreateTextures(GL_TEXTURE_2D, 1, &o.depth);
  glTextureStorage2D(o.depth, 1, GL_DEPTH_COMPONENT32F, w, h);
  glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &o.array);
  glTextureStorage3D(o.array, 1, GL_R32F, w, h, config.max_layers);
  const float invalid = ldi::kInvalidDepth;
  glClearTexImage(o.array, 0, GL_RED, GL_FLOAT, &invalid);  // missing layers read +inf
  glCreateFramebuffers(1, &o.fbo);
  glNamedFramebufferTexture(o.fbo, GL_DEPTH_ATTACHMENT, o.depth, 0);

  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, o.fbo);
  glViewport(0, 0, w, h);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glDisable(GL_SCISSOR_TEST);
  glEnable(GL_DEPTH_TEST);
  // LEQUAL, not LESS: the depth buffer is cleared to 1.0 (glClearDepth clamps to [0, 1]) and a
  // shape touching the cube's far face has fragments at exactly 1.0, which LESS would lose. A
  // fragment replacing one of equal depth writes the same colour, so the layer is the same.
  glDepthFunc(GL_LEQUAL);
  glGetIntegerv(GL_CLIP_ORIGIN, &o.clip_origin);
  glGetIntegerv(GL_CLIP_DEPTH_MODE, &o.clip_depth);
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);  // window depth = the linear depth (peel.vert)
  glDepthMask(GL_TRUE);
  glColorMaski(0, GL_TRUE, GL_FALSE, GL_FALSE, GL_FALSE);
  glUseProgram(o.program);
  glBindVertexArray(o.vao);
  if (recorder)
    recorder->bind();
  else
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, o.ssbo);
  const GLint slot_loc = glGetUniformLocation(o.program, "draw_slot");
  const GLint first_loc = glGetUniformLocation(o.program, "first_pass");
  glUniform1i(glGetUniformLocation(o.program, "previous_layer"), 0);

  std::vector<std::uint64_t> samples;
  std::uint64_t depth_checked = 0, depth_mismatches = 0;
  int layers = 0;
  for (int pass = 0; pass < max_passes; ++pass) {
    const GLuint target = o.ping[pass % 2], previous = o.ping[(pass + 1) % 2];
    glNamedFramebufferTexture(o.fbo, GL_COLOR_ATTACHMENT0, target, 0);
    glNamedFramebufferDrawBuffer(o.fbo, GL_COLOR_ATTACHMENT0);
    if (glCheckNamedFramebufferStatus(o.fbo, GL_DRAW_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("peel: framebuffer incomplete");
    glClearNamedFramebufferfv(o.fbo, GL_COLOR, 0, &invalid);
    const float far_depth = 1.0f;
    glClearNamedFramebufferfv(o.fbo, GL_DEPTH, 0, &far_depth);
    glBindTextureUnit(0, previous);
    glUniform1i(first_loc, pass == 0 ? 1 : 0);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
    GLuint64 passed = 0;
    if (recorder) {
      scene::DrawRecord d;
      d.role = nbsim::ldi::kLdiPeelRole;
      d.state.func = scene::DepthFunc::Lequal;
      d.state.test = true;
      d.state.write = true;
      d.state.cull = scene::CullFace::None;
      d.state.clip = scene::ClipControl::ZeroToOne;
      d.discards = pass > 0;
      const std::size_t slot = recorder->begin_draw(std::move(d), m.triangles.size() * 3);
      glUniform1ui(slot_loc, static_cast<GLuint>(slot));
      glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(m.triangles.size() * 3), GL_UNSIGNED_INT, nullptr);
      recorder->end_draw();
      passed = recorder->samples_passed(slot);
    } else {
      glUniform1ui(slot_loc, static_cast<GLuint>(pass));
      glBeginQuery(GL_SAMPLES_PASSED, o.query);
      glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(m.triangles.size() * 3), GL_UNSIGNED_INT, nullptr);
      glEndQuery(GL_SAMPLES_PASSED);
      glGetQueryObjectui64v(o.query, GL_QUERY_RESULT, &passed);
    }
    samples.push_back(passed);
    if (passed == 0) break;
    if (config.verify_depth_buffer) {
      // The depth attachment against the layer just written, bit for bit, where the layer is valid.
      glFinish();
      std::vector<float> zb(static_cast<std::size_t>(w) * h), layer(zb.size());
      glGetTextureImage(o.depth, 0, GL_DEPTH_COMPONENT, GL_FLOAT, static_cast<GLsizei>(zb.size() * 4), zb.data());
      glGetTextureImage(target, 0, GL_RED, GL_FLOAT, static_cast<GLsizei>(layer.size() * 4), layer.data());
      for (std::size_t i = 0; i < zb.size(); ++i) {
        if (!std::isfinite(layer[i])) continue;
        ++depth_checked;
        if (std::bit_cast<std::uint32_t>(layer[i]) != std::bit_cast<std::uint32_t>(zb[i])) ++depth_mismatches;
      }
    }
    if (pass == config.max_layers)
      throw InputError(fmt::format("peel: the shape has more than max_layers = {} layers", config.max_layers));
    glCopyImageSubData(target, GL_TEXTURE_2D, 0, 0, 0, 0, o.array, GL_TEXTURE_2D_ARRAY, 0, 0, 0, pass, w, h, 1);
    layers = pass + 1;
  }
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);

  std::vector<std::uint32_t> fragments(samples.size());
  if (!recorder) glGetNamedBufferSubData(o.ssbo, 0, static_cast<GLsizeiptr>(fragments.size() * 4), fragments.data());
  std::vector<float> depths(static_cast<std::size_t>(w) * h * layers);
  if (layers > 0)
    glGetTextureSubImage(o.array, 0, 0, 0, 0, w, h, layers, GL_RED, GL_FLOAT,
                         static_cast<GLsizei>(depths.size() * sizeof(float)), depths.data());
  if (glGetError() != GL_NO_ERROR) throw std::runtime_error("peel: a GL call failed");

  PeelResult r{ldi::Ldi(w, h, layers, std::move(depths)), {}};
  for (std::size_t i = 0; i < samples.size(); ++i) r.passes.push_back({fragments[i], samples[i]});
  r.depth_buffer_checked = depth_checked;
  r.depth_buffer_mismatches = depth_mismatches;
  if (config.keep_gl_layers) {
    o.keep = true;
    r.gl_layers = o.array;
  }
  return r;
}

}  // namespace nbsim::capture

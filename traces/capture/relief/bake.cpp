// Heightfields baked from meshes; see bake.h.
#include "traces/capture/relief/bake.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <stdexcept>
#include <vector>

#include "model/common/error.h"
#include "nbsim_shaders.h"
#include "traces/capture/gl_program.h"
#include "traces/capture/relief/view.h"

namespace nbsim::capture {

namespace {
struct BakeObjects {
  GLuint program = 0, vao = 0, vbo = 0, ebo = 0, fbo = 0, depth = 0;
  GLint clip_origin = 0, clip_depth = 0;
  ~BakeObjects() {
    if (clip_origin != 0) glClipControl(static_cast<GLenum>(clip_origin), static_cast<GLenum>(clip_depth));
    glDeleteProgram(program);
    glDeleteVertexArrays(1, &vao);
    GLuint buffers[] = {vbo, ebo};
    glDeleteBuffers(2, buffers);
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &depth);
  }
};
}  // namespace

relief::Heightfield bake_heightfield(mesh::TriMesh m, int size, double box_height, double apex) {
  if (size < relief::kMinSize || size > relief::kMaxSize)
    throw InputError(fmt::format("a heightfield of size {} is not supported ({} to {})", size, relief::kMinSize, relief::kMaxSize));
  if (m.triangles.empty()) throw InputError("the mesh to bake has no triangles");
  mesh::normalize_to_unit_cube(m, 0.0);
  const double n = size, inner = (n - 2.0) / n, border = 1.0 / n;
  std::vector<float> vertices;
  vertices.reserve(m.vertices.size() * 3);
  const std::array<double, 16> map = frustum_map(size, box_height, apex);  // world -> texel space, column-major
  for (const mesh::Vec3f& p : m.vertices) {
    const double w[4] = {border + inner * p[0], border + inner * p[1], box_height * p[2], 1.0};
    double t[4] = {0, 0, 0, 0};
    for (int row = 0; row < 4; ++row)
      for (int col = 0; col < 4; ++col) t[row] += map[static_cast<std::size_t>(col * 4 + row)] * w[col];
    vertices.push_back(static_cast<float>(2.0 * t[0] / t[3] / n - 1.0));
    vertices.push_back(static_cast<float>(2.0 * t[1] / t[3] / n - 1.0));
    vertices.push_back(static_cast<float>(1.0 - t[2] / t[3]));
  }
  BakeObjects o;
  o.program = link_program({compile_shader(GL_VERTEX_SHADER, shaders::ldi_peel_vert, "ldi/peel.vert"),
                            compile_shader(GL_FRAGMENT_SHADER, shaders::relief_bake_frag, "relief/bake.frag")},
                           "relief bake");
  static_assert(sizeof(mesh::Tri) == 3 * sizeof(std::uint32_t));
  make_triangle_vertex_array(vertices, {reinterpret_cast<const std::uint32_t*>(m.triangles.data()), m.triangles.size() * 3}, o.vao, o.vbo,
                             o.ebo);
  glCreateTextures(GL_TEXTURE_2D, 1, &o.depth);
  glTextureStorage2D(o.depth, 1, GL_DEPTH_COMPONENT32F, size, size);
  glCreateFramebuffers(1, &o.fbo);
  glNamedFramebufferTexture(o.fbo, GL_DEPTH_ATTACHMENT, o.depth, 0);
  glNamedFramebufferDrawBuffer(o.fbo, GL_NONE);
  if (glCheckNamedFramebufferStatus(o.fbo, GL_DRAW_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error("relief bake: framebuffer incomplete");
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, o.fbo);
  glViewport(0, 0, size, size);
  glGetIntegerv(GL_CLIP_ORIGIN, &o.clip_origin);
  glGetIntegerv(GL_CLIP_DEPTH_MODE, &o.clip_depth);
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_STENCIL_TEST);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  const float far_depth = 1.0f;
  glClearNamedFramebufferfv(o.fbo, GL_DEPTH, 0, &far_depth);
  glUseProgram(o.program);
  glBindVertexArray(o.vao);
  glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(m.triangles.size() * 3), GL_UNSIGNED_INT, nullptr);
  glFinish();
  std::vector<float> depth(static_cast<std::size_t>(size) * static_cast<std::size_t>(size));
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glGetTextureImage(o.depth, 0, GL_DEPTH_COMPONENT, GL_FLOAT, static_cast<GLsizei>(depth.size() * sizeof(float)), depth.data());
  glUseProgram(0);
  relief::Heightfield f;
  f.size = size;
  f.heights.resize(depth.size());
  for (std::size_t k = 0; k < depth.size(); ++k) f.heights[k] = depth[k] < 1.0f ? std::clamp(1.0f - depth[k], 0.0f, 1.0f) : 0.0f;
  return f;
}

}  // namespace nbsim::capture

// The GLSL Hi-Z pyramid; see glsl_hiz.h.
#include "traces/capture/particles/glsl_hiz.h"

#include <algorithm>
#include <string>

#include "nbsim_shaders.h"

namespace nbsim::capture {

namespace {

int level_side(int side, int level) { return (side + (1 << level) - 1) >> level; }

}  // namespace

GlslHiZ::GlslHiZ(int width, int height, FarOp op, int max_level) : width_(width), height_(height) {
  int top = 0;
  while (level_side(width, top) > 1 || level_side(height, top) > 1) ++top;
  levels_ = std::clamp(max_level, 0, top) + 1;
  const std::string far = op == FarOp::Min ? "#define FAR(a, b) min(a, b)\n" : "#define FAR(a, b) max(a, b)\n";
  build_prog_ = link_program({compile_shader(GL_VERTEX_SHADER, shaders::common_fullscreen_vert, "common/fullscreen.vert"),
                              compile_shader(GL_FRAGMENT_SHADER, with_defines(shaders::particles_hiz_build_frag, far),
                                             "particles/hiz_build.frag")},
                             "hiz_build");
  glCreateVertexArrays(1, &empty_vao_);
  const auto n = static_cast<std::size_t>(levels_);
  level_tex_.resize(n);
  level_fbo_.resize(n);
  glCreateTextures(GL_TEXTURE_2D, levels_, level_tex_.data());
  glCreateFramebuffers(levels_, level_fbo_.data());
  for (std::size_t i = 0; i < n; ++i) {
    glTextureStorage2D(level_tex_[i], 1, GL_R32F, width, height);
    glTextureParameteri(level_tex_[i], GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(level_tex_[i], GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glNamedFramebufferTexture(level_fbo_[i], GL_COLOR_ATTACHMENT0, level_tex_[i], 0);
  }
  glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &level_array_);
  glTextureStorage3D(level_array_, 1, GL_R32F, width, height, levels_);
  glTextureParameteri(level_array_, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(level_array_, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
}

GlslHiZ::~GlslHiZ() {
  glDeleteProgram(build_prog_);
  glDeleteVertexArrays(1, &empty_vao_);
  glDeleteFramebuffers(static_cast<GLsizei>(level_fbo_.size()), level_fbo_.data());
  glDeleteTextures(static_cast<GLsizei>(level_tex_.size()), level_tex_.data());
  glDeleteTextures(1, &level_array_);
}

void GlslHiZ::build(GLuint depth_texture, DrawRecorder& recorder, const scene::DepthState& state) {
  glUseProgram(build_prog_);
  glBindVertexArray(empty_vao_);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  recorder.bind();
  glBindTextureUnit(1, depth_texture);
  glUniform1i(glGetUniformLocation(build_prog_, "depth"), 1);
  glUniform1i(glGetUniformLocation(build_prog_, "levels"), 0);
  const GLint u_src = glGetUniformLocation(build_prog_, "source_level"), u_size = glGetUniformLocation(build_prog_, "source_size");
  const GLint u_is_depth = glGetUniformLocation(build_prog_, "source_is_depth"), u_slot = glGetUniformLocation(build_prog_, "draw_slot");
  for (int k = 0; k < levels_; ++k) {
    scene::DrawRecord d;
    d.role = scene::DrawRole::HiZBuild;
    d.level = static_cast<std::uint8_t>(k);
    d.state = state;
    const int w = level_side(width_, k), h = level_side(height_, k);
    glBindFramebuffer(GL_FRAMEBUFFER, level_fbo_[static_cast<std::size_t>(k)]);
    glViewport(0, 0, w, h);
    glBindTextureUnit(0, level_array_);
    glUniform1i(u_src, std::max(k - 1, 0));
    glUniform2i(u_size, level_side(width_, std::max(k - 1, 0)), level_side(height_, std::max(k - 1, 0)));
    glUniform1i(u_is_depth, k == 0);
    const std::size_t slot = recorder.begin_draw(std::move(d), 0);
    glUniform1ui(u_slot, static_cast<GLuint>(slot));
    glDrawArrays(GL_TRIANGLES, 0, 3);
    recorder.end_draw();
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
    glCopyImageSubData(level_tex_[static_cast<std::size_t>(k)], GL_TEXTURE_2D, 0, 0, 0, 0, level_array_, GL_TEXTURE_2D_ARRAY, 0, 0,
                       0, k, w, h, 1);
  }
  glViewport(0, 0, width_, height_);
  glEnable(GL_CULL_FACE);
}

}  // namespace nbsim::capture

// The level chain of the GLSL N-buffer and Hi-Z builds; see level_chain.h.
#include "traces/capture/level_chain.h"

#include <algorithm>
#include <cstdint>

#include "model/common/error.h"

namespace nbsim::capture {

LevelChain::LevelChain(std::vector<std::pair<int, int>> sides) : sides_(std::move(sides)) {
  NBSIM_CHECK(!sides_.empty(), "a level chain needs at least one level");
  const auto n = sides_.size();
  const auto count = static_cast<GLsizei>(n);
  tex_.resize(n);
  fbo_.resize(n);
  glCreateTextures(GL_TEXTURE_2D, count, tex_.data());
  glCreateFramebuffers(count, fbo_.data());
  for (std::size_t i = 0; i < n; ++i) {
    glTextureStorage2D(tex_[i], 1, GL_R32F, sides_[i].first, sides_[i].second);
    glTextureParameteri(tex_[i], GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(tex_[i], GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glNamedFramebufferTexture(fbo_[i], GL_COLOR_ATTACHMENT0, tex_[i], 0);
  }
  glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &array_);
  glTextureStorage3D(array_, 1, GL_R32F, sides_[0].first, sides_[0].second, count);
  glTextureParameteri(array_, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(array_, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glCreateVertexArrays(1, &empty_vao_);
}

LevelChain::~LevelChain() {
  glDeleteVertexArrays(1, &empty_vao_);
  glDeleteFramebuffers(static_cast<GLsizei>(fbo_.size()), fbo_.data());
  glDeleteTextures(static_cast<GLsizei>(tex_.size()), tex_.data());
  glDeleteTextures(1, &array_);
}

void LevelChain::build(GLuint program, GLuint depth_texture, DrawRecorder& recorder, scene::DrawRole role,
                       const scene::DepthState& state, const std::function<void(int)>& per_level) {
  glUseProgram(program);
  glBindVertexArray(empty_vao_);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  recorder.bind();
  glBindTextureUnit(1, depth_texture);
  glUniform1i(glGetUniformLocation(program, "depth"), 1);
  glUniform1i(glGetUniformLocation(program, "levels"), 0);
  const GLint u_src = glGetUniformLocation(program, "source_level");
  const GLint u_is_depth = glGetUniformLocation(program, "source_is_depth");
  const GLint u_slot = glGetUniformLocation(program, "draw_slot");
  for (int k = 0; k < levels(); ++k) {
    const auto [w, h] = sides_[static_cast<std::size_t>(k)];
    scene::DrawRecord d;
    d.role = role;
    d.level = static_cast<std::uint8_t>(k);
    d.state = state;
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_[static_cast<std::size_t>(k)]);
    glViewport(0, 0, w, h);
    glBindTextureUnit(0, array_);
    glUniform1i(u_src, std::max(k - 1, 0));
    glUniform1i(u_is_depth, k == 0);
    per_level(k);
    const std::size_t slot = recorder.begin_draw(std::move(d), 0);
    glUniform1ui(u_slot, static_cast<GLuint>(slot));
    glDrawArrays(GL_TRIANGLES, 0, 3);
    recorder.end_draw();
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
    glCopyImageSubData(tex_[static_cast<std::size_t>(k)], GL_TEXTURE_2D, 0, 0, 0, 0, array_, GL_TEXTURE_2D_ARRAY, 0, 0, 0, k, w,
                       h, 1);
  }
  glViewport(0, 0, sides_[0].first, sides_[0].second);
  glEnable(GL_CULL_FACE);
}

}  // namespace nbsim::capture

// The GLSL N-buffer; see glsl_nbuffer.h.
#include "traces/capture/glsl_nbuffer.h"

#include <algorithm>
#include <cstdint>
#include <string>

#include "model/common/error.h"
#include "model/nbuffer/covering.h"
#include "nbsim_shaders.h"
#include "traces/capture/readback.h"

namespace nbsim::capture {

GlslNBuffer::GlslNBuffer(int width, int height, FarOp op, int max_level)
    : width_(width), height_(height), levels_(std::clamp(max_level + 1, 1, nbuffer_level_count(width, height))), op_(op) {
  const std::string far = op == FarOp::Min ? "#define FAR(a, b) min(a, b)\n#define FARTHER_THAN(a, b) ((a) < (b))\n"
                                           : "#define FAR(a, b) max(a, b)\n#define FARTHER_THAN(a, b) ((a) > (b))\n";
  build_prog_ = link_program({compile_shader(GL_VERTEX_SHADER, shaders::common_fullscreen_vert, "common/fullscreen.vert"),
                              compile_shader(GL_FRAGMENT_SHADER, with_defines(shaders::common_nbuffer_build_frag, far),
                                             "common/nbuffer_build.frag")},
                             "nbuffer_build");
  query_prog_ = link_program({compile_shader(GL_COMPUTE_SHADER, with_defines(shaders::common_nbuffer_query_comp, far),
                                             "common/nbuffer_query.comp")},
                             "nbuffer_query");
  glCreateVertexArrays(1, &empty_vao_);
  glCreateBuffers(1, &query_ssbo_);
  glCreateBuffers(1, &result_ssbo_);

  const auto n = static_cast<std::size_t>(levels_);
  level_tex_.resize(n);
  level_fbo_.resize(n);
  glCreateTextures(GL_TEXTURE_2D, levels_, level_tex_.data());
  glCreateFramebuffers(levels_, level_fbo_.data());
  for (std::size_t i = 0; i < n; ++i) {
    glTextureStorage2D(level_tex_[i], 1, GL_R32F, width, height);
    glNamedFramebufferTexture(level_fbo_[i], GL_COLOR_ATTACHMENT0, level_tex_[i], 0);
  }
  glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &level_array_);
  glTextureStorage3D(level_array_, 1, GL_R32F, width, height, levels_);
  for (GLuint t : level_tex_) {
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  }
  glTextureParameteri(level_array_, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(level_array_, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
}

GlslNBuffer::~GlslNBuffer() {
  glDeleteProgram(build_prog_);
  glDeleteProgram(query_prog_);
  glDeleteVertexArrays(1, &empty_vao_);
  const GLuint buffers[] = {query_ssbo_, result_ssbo_};
  glDeleteBuffers(2, buffers);
  glDeleteFramebuffers(static_cast<GLsizei>(level_fbo_.size()), level_fbo_.data());
  glDeleteTextures(static_cast<GLsizei>(level_tex_.size()), level_tex_.data());
  glDeleteTextures(1, &level_array_);
}

void GlslNBuffer::build(GLuint depth_texture, DrawRecorder& recorder, const scene::DepthState& state) {
  glUseProgram(build_prog_);
  glBindVertexArray(empty_vao_);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  recorder.bind();
  glBindTextureUnit(1, depth_texture);
  glUniform1i(glGetUniformLocation(build_prog_, "depth"), 1);
  glUniform1i(glGetUniformLocation(build_prog_, "levels"), 0);
  const GLint u_src = glGetUniformLocation(build_prog_, "source_level"), u_step = glGetUniformLocation(build_prog_, "step");
  const GLint u_is_depth = glGetUniformLocation(build_prog_, "source_is_depth"), u_slot = glGetUniformLocation(build_prog_, "draw_slot");
  for (int i = 0; i < levels_; ++i) {
    scene::DrawRecord d;
    d.role = scene::DrawRole::NBufferBuild;
    d.level = static_cast<std::uint8_t>(i);
    d.state = state;
    // Level i is rendered into its own texture while level i - 1 is read from the array copy,
    // so no texture is read and written by the same pass.
    glBindFramebuffer(GL_FRAMEBUFFER, level_fbo_[static_cast<std::size_t>(i)]);
    glViewport(0, 0, width_, height_);
    glBindTextureUnit(0, level_array_);
    glUniform1i(u_src, std::max(i - 1, 0));
    glUniform1i(u_step, i > 0 ? 1 << (i - 1) : 0);
    glUniform1i(u_is_depth, i == 0);
    const std::size_t slot = recorder.begin_draw(std::move(d), 0);
    glUniform1ui(u_slot, static_cast<GLuint>(slot));
    glDrawArrays(GL_TRIANGLES, 0, 3);
    recorder.end_draw();
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
    glCopyImageSubData(level_tex_[static_cast<std::size_t>(i)], GL_TEXTURE_2D, 0, 0, 0, 0, level_array_, GL_TEXTURE_2D_ARRAY,
                       0, 0, 0, i, width_, height_, 1);
  }
  glEnable(GL_CULL_FACE);
}

void GlslNBuffer::query(std::vector<scene::BoundsTest>& tests) {
  struct alignas(16) Gpu { std::int32_t rect[4]; float nearest; std::uint32_t always, pad0, pad1; };
  std::vector<Gpu> in;
  in.reserve(tests.size());
  for (const auto& t : tests) {
    Gpu g{};
    // Off-screen bounds are never visible; crossing the near plane always is.
    g.rect[0] = std::min(t.x, width_ - 1), g.rect[1] = std::min(t.y, height_ - 1);
    g.rect[2] = std::max(t.w, 1), g.rect[3] = std::max(t.h, 1);
    g.nearest = t.nearest_depth;
    g.always = t.crosses_near ? 1u : 0u;
    in.push_back(g);
  }
  if (in.empty()) return;
  // A rectangle wider than the top level's squares would be answered from too small a square.
  NBSIM_CHECK(levels_ == nbuffer_level_count(width_, height_), "GlslNBuffer::query() on a partial build");
  glDeleteBuffers(1, &query_ssbo_);
  glCreateBuffers(1, &query_ssbo_);
  glNamedBufferStorage(query_ssbo_, static_cast<GLsizeiptr>(in.size() * sizeof(Gpu)), in.data(), 0);
  glDeleteBuffers(1, &result_ssbo_);
  glCreateBuffers(1, &result_ssbo_);
  glNamedBufferStorage(result_ssbo_, static_cast<GLsizeiptr>(in.size() * 4), nullptr, 0);
  glUseProgram(query_prog_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, query_ssbo_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, result_ssbo_);
  glBindTextureUnit(0, level_array_);
  glUniform1i(glGetUniformLocation(query_prog_, "levels"), 0);
  glUniform1i(glGetUniformLocation(query_prog_, "top_level"), levels_ - 1);
  glUniform1ui(glGetUniformLocation(query_prog_, "count"), static_cast<GLuint>(in.size()));
  glDispatchCompute(static_cast<GLuint>((in.size() + 63) / 64), 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<std::uint32_t> out(in.size());
  glGetNamedBufferSubData(result_ssbo_, 0, static_cast<GLsizeiptr>(out.size() * 4), out.data());
  for (std::size_t i = 0; i < tests.size(); ++i) tests[i].visible = tests[i].w > 0 && tests[i].h > 0 && out[i] != 0;
}

scene::NBufferLevels GlslNBuffer::read() const { return read_levels(level_array_, width_, height_, levels_, op_); }

}  // namespace nbsim::capture

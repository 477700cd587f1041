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

GlslNBuffer::GlslNBuffer(int width, int height, FarOp op, int max_level, CoveringSpec covering)
    : width_(width),
      height_(height),
      levels_(std::clamp(max_level + 1, 1, nbuffer_level_count(width, height))),
      op_(op),
      chain_(std::vector<std::pair<int, int>>(static_cast<std::size_t>(levels_), {width, height})) {
  const std::string far = op == FarOp::Min ? "#define FAR(a, b) min(a, b)\n#define FARTHER_THAN(a, b) ((a) < (b))\n"
                                           : "#define FAR(a, b) max(a, b)\n#define FARTHER_THAN(a, b) ((a) > (b))\n";
  build_prog_ = link_program({compile_shader(GL_VERTEX_SHADER, shaders::common_fullscreen_vert, "common/fullscreen.vert"),
                              compile_shader(GL_FRAGMENT_SHADER, with_defines(shaders::common_nbuffer_build_frag, far),
                                             "common/nbuffer_build.frag")},
                             "nbuffer_build");
  query_prog_ = link_program({compile_shader(GL_COMPUTE_SHADER,
                                             with_defines(shaders::common_nbuffer_query_comp, far + covering_glsl(covering)),
                                             "common/nbuffer_query.comp")},
                             "nbuffer_query");
  glCreateBuffers(1, &query_ssbo_);
  glCreateBuffers(1, &result_ssbo_);
}

GlslNBuffer::~GlslNBuffer() {
  glDeleteProgram(build_prog_);
  glDeleteProgram(query_prog_);
  const GLuint buffers[] = {query_ssbo_, result_ssbo_};
  glDeleteBuffers(2, buffers);
}

void GlslNBuffer::build(GLuint depth_texture, DrawRecorder& recorder, const scene::DepthState& state) {
  // Level i reads level i - 1 at offsets of step = 2^(i-1) texels (level 0 copies the depth).
  const GLint u_step = glGetUniformLocation(build_prog_, "step");
  chain_.build(build_prog_, depth_texture, recorder, scene::DrawRole::NBufferBuild, state,
               [&](int i) { glUniform1i(u_step, i > 0 ? 1 << (i - 1) : 0); });
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
  glBindTextureUnit(0, chain_.array());
  glUniform1i(glGetUniformLocation(query_prog_, "levels"), 0);
  glUniform1i(glGetUniformLocation(query_prog_, "top_level"), levels_ - 1);
  glUniform1ui(glGetUniformLocation(query_prog_, "count"), static_cast<GLuint>(in.size()));
  glDispatchCompute(static_cast<GLuint>((in.size() + 63) / 64), 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<std::uint32_t> out(in.size());
  glGetNamedBufferSubData(result_ssbo_, 0, static_cast<GLsizeiptr>(out.size() * 4), out.data());
  for (std::size_t i = 0; i < tests.size(); ++i) tests[i].visible = tests[i].w > 0 && tests[i].h > 0 && out[i] != 0;
}

scene::NBufferLevels GlslNBuffer::read() const { return read_levels(chain_.array(), width_, height_, levels_, op_); }

}  // namespace nbsim::capture

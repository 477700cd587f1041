// The GLSL Hi-Z pyramid; see glsl_hiz.h.
#include "traces/capture/particles/glsl_hiz.h"

#include <algorithm>
#include <string>

#include "nbsim_shaders.h"
#include "model/particles/roles.h"

namespace nbsim::capture {

namespace {

int level_side(int side, int level) { return (side + (1 << level) - 1) >> level; }

// Levels 0 .. min(max_level, the level of one texel), each ceil(side / 2^k).
std::vector<std::pair<int, int>> pyramid_sides(int width, int height, int max_level) {
  int top = 0;
  while (level_side(width, top) > 1 || level_side(height, top) > 1) ++top;
  std::vector<std::pair<int, int>> sides;
  for (int k = 0; k <= std::clamp(max_level, 0, top); ++k) sides.emplace_back(level_side(width, k), level_side(height, k));
  return sides;
}

}  // namespace

GlslHiZ::GlslHiZ(int width, int height, FarOp op, int max_level)
    : width_(width), height_(height), chain_(pyramid_sides(width, height, max_level)) {
  const std::string far = op == FarOp::Min ? "#define FAR(a, b) min(a, b)\n" : "#define FAR(a, b) max(a, b)\n";
  build_prog_ = link_program({compile_shader(GL_VERTEX_SHADER, shaders::common_fullscreen_vert, "common/fullscreen.vert"),
                              compile_shader(GL_FRAGMENT_SHADER, with_defines(shaders::particles_hiz_build_frag, far),
                                             "particles/hiz_build.frag")},
                             "hiz_build");
}

GlslHiZ::~GlslHiZ() { glDeleteProgram(build_prog_); }

void GlslHiZ::build(GLuint depth_texture, DrawRecorder& recorder, const scene::DepthState& state) {
  // Level k reads level k - 1, whose size the shader needs for its edge texels.
  const GLint u_size = glGetUniformLocation(build_prog_, "source_size");
  chain_.build(build_prog_, depth_texture, recorder, nbsim::particles::kHiZBuildRole, state, [&](int k) {
    glUniform2i(u_size, level_side(width_, std::max(k - 1, 0)), level_side(height_, std::max(k - 1, 0)));
  });
}

}  // namespace nbsim::capture

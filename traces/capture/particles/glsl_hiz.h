// The Hi-Z mip pyramid of the particles technique's `hiz` mode, the comparison baseline: a max
// (min under reversed Z) pyramid built in GLSL (shaders/particles/hiz_build.frag), one full-screen
// pass a level (each a recorded draw, role HiZBuild), level k of ceil(W / 2^k) x ceil(H / 2^k)
// texels kept in the lower-left corner of layer k of an R32F array texture, which the vertex stage
// reads. Levels 0 .. max_level (at most the level of one texel).
#pragma once

#include <vector>

#include "model/common/depth.h"
#include "model/scene/frame.h"
#include "traces/capture/draw_recorder.h"
#include "traces/capture/gl_program.h"
#include "traces/capture/level_chain.h"

namespace nbsim::capture {

class GlslHiZ {
 public:
  GlslHiZ(int width, int height, FarOp op, int max_level);
  ~GlslHiZ();
  GlslHiZ(const GlslHiZ&) = delete;
  GlslHiZ& operator=(const GlslHiZ&) = delete;

  int levels() const noexcept { return chain_.levels(); }
  GLuint texture() const noexcept { return chain_.array(); }

  // Builds every level from `depth_texture`, recording each pass (role HiZBuild, its level, `state`).
  // Leaves back-face culling on and depth testing off.
  void build(GLuint depth_texture, DrawRecorder& recorder, const scene::DepthState& state);

 private:
  int width_ = 0, height_ = 0;
  GLuint build_prog_ = 0;
  LevelChain chain_;  // level k: ceil(W / 2^k) x ceil(H / 2^k)
};

}  // namespace nbsim::capture

// The GLSL N-buffer the capture techniques share (N-buffer paper, Fig. 2 and section 3.2): built
// from a depth texture by one full-screen pass per level (shaders/common/nbuffer_build.frag, each
// pass a recorded draw), up to a level cap (the paper's partial build: only the levels the largest
// query needs); queried in batches of rectangles by a compute shader
// (shaders/common/nbuffer_query.comp: bounds tests) or sampled by a technique's own shaders
// (texture()), read back as the trace's level record. Levels are R32F; max under LESS, min under
// reversed Z, or either over any depth-like texture a technique renders. Texels
// outside the image are skipped, never read (the paper's border value: +inf for a min N-buffer,
// -inf for a max one), so the same level chain serves both ops.
#pragma once

#include <vector>

#include "model/common/depth.h"
#include "model/scene/frame.h"
#include "traces/capture/draw_recorder.h"
#include "traces/capture/gl_program.h"
#include "traces/capture/level_chain.h"

namespace nbsim::capture {

class GlslNBuffer {
 public:
  // Levels: nbuffer_level_count(width, height) (model/nbuffer/covering.h), or fewer: levels 0 ..
  // max_level when max_level is below the last of them (a partial build).
  // query() covers each rectangle as `covering` says (shaders/common/covering.glsl).
  GlslNBuffer(int width, int height, FarOp op, int max_level = 1 << 30, CoveringSpec covering = {});
  ~GlslNBuffer();
  GlslNBuffer(const GlslNBuffer&) = delete;
  GlslNBuffer& operator=(const GlslNBuffer&) = delete;

  int levels() const noexcept { return levels_; }

  // Builds every level from `depth_texture`, recording each pass (role NBufferBuild, its level,
  // `state`) with `recorder`. Leaves back-face culling on and depth testing off.
  void build(GLuint depth_texture, DrawRecorder& recorder, const scene::DepthState& state);

  // One compute dispatch over the batch: sets each test's .visible (off-screen rectangles are
  // never visible; bounds crossing the near plane always are). Needs every level (no cap).
  void query(std::vector<scene::BoundsTest>& tests);

  scene::NBufferLevels read() const;

  // The levels as a 2D array texture, one R32F layer a level (for a technique's own queries).
  GLuint texture() const noexcept { return chain_.array(); }

 private:
  int width_ = 0, height_ = 0, levels_ = 1;
  FarOp op_ = FarOp::Max;
  GLuint build_prog_ = 0, query_prog_ = 0;
  GLuint query_ssbo_ = 0, result_ssbo_ = 0;
  LevelChain chain_;  // every level full size
};

}  // namespace nbsim::capture

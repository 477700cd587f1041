// A chain of R32F levels that full-screen passes build one level at a time from a depth texture
// (the GLSL N-buffer, a Hi-Z pyramid): level k is rendered into its own 2D texture and
// then copied into layer k of one 2D array texture, which the next pass and the technique's
// queries read, so no pass reads the texture it writes. Each pass is a recorded draw.
#pragma once

#include <functional>
#include <utility>
#include <vector>

#include "model/scene/frame.h"
#include "traces/capture/draw_recorder.h"
#include "traces/capture/gl_program.h"

namespace nbsim::capture {

class LevelChain {
 public:
  // One level per entry of `sides` (width, height in texels; level 0 the largest, which sizes the
  // array's layers). Texels are read with nearest filtering.
  explicit LevelChain(std::vector<std::pair<int, int>> sides);
  ~LevelChain();
  LevelChain(const LevelChain&) = delete;
  LevelChain& operator=(const LevelChain&) = delete;

  int levels() const noexcept { return static_cast<int>(sides_.size()); }
  // The levels as a 2D array texture, one layer a level.
  GLuint array() const noexcept { return array_; }

  // Runs `program` once a level, k = 0, 1, ...: depth test and face culling off, `depth_texture`
  // on unit 1 (uniform "depth"), the array on unit 0 ("levels"), "source_level" = max(k - 1, 0),
  // "source_is_depth" = (k == 0), "draw_slot" = the pass's recorder slot, the viewport the level's
  // size; `per_level(k)` sets the program's other uniforms. Each pass is recorded as a draw of
  // `role`, level k and `state`. Leaves back-face culling on, the viewport at level 0's size.
  void build(GLuint program, GLuint depth_texture, DrawRecorder& recorder, scene::DrawRole role,
             const scene::DepthState& state, const std::function<void(int)>& per_level);

 private:
  std::vector<std::pair<int, int>> sides_;
  std::vector<GLuint> tex_, fbo_;  // one render target a level
  GLuint array_ = 0, empty_vao_ = 0;
};

}  // namespace nbsim::capture

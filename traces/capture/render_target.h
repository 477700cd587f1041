// The framebuffer a capture technique renders into: a DEPTH_COMPONENT32F depth texture (read back
// exactly, sampled without compare mode; or DEPTH24_STENCIL8 for techniques that use the stencil
// buffer, sampled as depth) and an R32UI colour texture for object ids (the ID buffer of the
// ground truth). Window depth in [0, 1], y up (model/common/depth.h).
#pragma once

#include "traces/capture/gl_program.h"

namespace nbsim::capture {

class RenderTarget {
 public:
  // depth_format: GL_DEPTH_COMPONENT32F or GL_DEPTH24_STENCIL8 (attached as depth and stencil).
  RenderTarget(int width, int height, GLenum depth_format = GL_DEPTH_COMPONENT32F);
  ~RenderTarget();
  RenderTarget(const RenderTarget&) = delete;
  RenderTarget& operator=(const RenderTarget&) = delete;

  // Binds the framebuffer for drawing with the whole viewport.
  void bind() const;
  // Clears the depth to the far value of the convention (1, or 0 under reversed Z).
  void clear_depth(bool reversed) const;
  // Clears the stencil to `value` (with GL_DEPTH24_STENCIL8).
  void clear_stencil(int value) const;

  int width() const noexcept { return width_; }
  int height() const noexcept { return height_; }
  GLuint framebuffer() const noexcept { return fbo_; }
  GLuint depth_texture() const noexcept { return depth_tex_; }
  GLuint id_texture() const noexcept { return id_tex_; }

 private:
  int width_ = 0, height_ = 0;
  GLuint fbo_ = 0, depth_tex_ = 0, id_tex_ = 0;
};

}  // namespace nbsim::capture

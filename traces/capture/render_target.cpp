// The capture framebuffer; see render_target.h.
#include "traces/capture/render_target.h"

#include <stdexcept>

namespace nbsim::capture {

RenderTarget::RenderTarget(int width, int height, GLenum depth_format) : width_(width), height_(height) {
  glCreateTextures(GL_TEXTURE_2D, 1, &depth_tex_);
  glTextureStorage2D(depth_tex_, 1, depth_format, width, height);
  glTextureParameteri(depth_tex_, GL_TEXTURE_COMPARE_MODE, GL_NONE);
  glTextureParameteri(depth_tex_, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(depth_tex_, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glCreateTextures(GL_TEXTURE_2D, 1, &id_tex_);
  glTextureStorage2D(id_tex_, 1, GL_R32UI, width, height);
  glCreateFramebuffers(1, &fbo_);
  glNamedFramebufferTexture(fbo_, depth_format == GL_DEPTH24_STENCIL8 ? GL_DEPTH_STENCIL_ATTACHMENT : GL_DEPTH_ATTACHMENT,
                            depth_tex_, 0);
  glNamedFramebufferTexture(fbo_, GL_COLOR_ATTACHMENT0, id_tex_, 0);
  if (glCheckNamedFramebufferStatus(fbo_, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error("the capture framebuffer is incomplete");
}

RenderTarget::~RenderTarget() {
  glDeleteFramebuffers(1, &fbo_);
  glDeleteTextures(1, &depth_tex_);
  glDeleteTextures(1, &id_tex_);
}

void RenderTarget::bind() const {
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glViewport(0, 0, width_, height_);
}

void RenderTarget::clear_depth(bool reversed) const {
  const float clear = reversed ? 0.0f : 1.0f;
  glDepthMask(GL_TRUE);  // clears obey the write masks
  glClearNamedFramebufferfv(fbo_, GL_DEPTH, 0, &clear);
}

}  // namespace nbsim::capture

namespace nbsim::capture {

void RenderTarget::clear_stencil(int value) const {
  glStencilMask(0xFFu);  // clears obey the write masks
  glClearNamedFramebufferiv(fbo_, GL_STENCIL, 0, &value);
}

}  // namespace nbsim::capture

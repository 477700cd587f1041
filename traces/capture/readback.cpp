// Depth and level read-back; see readback.h.
#include "traces/capture/readback.h"

namespace nbsim::capture {

scene::DepthSnapshot read_depth(GLuint framebuffer, int width, int height, scene::DepthWhich which) {
  scene::DepthSnapshot d;
  d.name = std::string(scene::to_string(which));
  d.width = width;
  d.height = height;
  d.texels.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, d.texels.data());  // bottom row first = y up
  return d;
}

scene::NBufferLevels read_levels(GLuint level_array, int width, int height, int levels, FarOp op) {
  scene::NBufferLevels l;
  l.op = static_cast<std::uint8_t>(op);
  l.width = width;
  l.height = height;
  l.levels = levels;
  l.texels.resize(static_cast<std::size_t>(levels) * static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glGetTextureImage(level_array, 0, GL_RED, GL_FLOAT, static_cast<GLsizei>(l.texels.size() * 4), l.texels.data());
  return l;
}

}  // namespace nbsim::capture

// Read-back of what a capture technique rendered into the trace's records: the depth buffer of a
// framebuffer and the levels of an N-buffer kept as a 2D array texture (one R32F layer a level).
// Rows bottom first (y up), row-major, as the records store them.
#pragma once

#include "model/common/depth.h"
#include "model/scene/frame.h"
#include "traces/capture/gl_program.h"

namespace nbsim::capture {

scene::DepthSnapshot read_depth(GLuint framebuffer, int width, int height, scene::DepthWhich which);

scene::NBufferLevels read_levels(GLuint level_array, int width, int height, int levels, FarOp op);

}  // namespace nbsim::capture

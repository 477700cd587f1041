// The capture renderer: runs the occlusion-culling technique of the N-buffer paper (sections 3.1
// and 4.2) on real OpenGL (Mesa llvmpipe, headless) for one frame at a time and records what the
// trace needs: every draw with its GL state, clip-space geometry and GL counters, the depth buffer
// after the occluders and at the end, the GLSL N-buffer levels, and the ID-buffer ground truth.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "traces/capture/camera.h"
#include "traces/capture/city.h"
#include "traces/format/records.h"
#include "traces/gl/context.h"

namespace nbsim::capture {

struct RendererOptions {
  int width = 512;
  int height = 512;
  trace::TestMode mode = trace::TestMode::NBufferHier;
  Projection projection;
  // Margin subtracted from (LESS) or added to (reversed Z) a bounds' nearest depth, so that GL's
  // interpolated fragment depths can never be nearer than it. Tunable; 1e-6 is ~16 float ulps at 1.
  float nearest_margin = 1e-6f;
};

// One frame as the trace stores it.
struct CapturedFrame {
  trace::FrameBegin begin;
  std::vector<trace::DrawRecord> draws;
  std::vector<trace::DepthSnapshot> depth;      // after occluders, final
  std::optional<trace::NBufferLevels> levels;   // when requested and the mode builds an N-buffer
  trace::GroundTruth truth;
  trace::FrameEnd end;
  std::vector<std::uint32_t> rendered_objects;  // objects the technique drew (occluders + visible)
};

class Renderer {
 public:
  Renderer(const City& city, RendererOptions options);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Renders frame `index` from `pose`. Occluders are the objects visible (ground truth) in the
  // previous call. keep_levels: read the GLSL N-buffer levels back into the frame.
  CapturedFrame render(std::uint32_t index, const CameraPose& pose, bool keep_levels);

  const gl::ContextInfo& gl_info() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nbsim::capture

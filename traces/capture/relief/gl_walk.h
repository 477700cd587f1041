// The relief ray walks on GL (shaders/relief/relief.frag): a heightfield, its safety radius and the
// max N-buffer GL builds from it (GlslNBuffer, each level a recorded nbuffer_build draw) as
// textures, and one box draw per method into an own framebuffer (DEPTH_COMPONENT32F cleared to 1.0,
// LESS with early fragment tests, depth writes off, back faces culled) whose fragment shader
// writes every fragment's walk into an SSBO, read back as GlFragments. The model's twin is
// model/relief/walk.h; ReliefGlWalkTest compares them fragment by fragment.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "model/relief/box_depth.h"
#include "model/relief/heightfield.h"
#include "model/relief/radius.h"
#include "model/relief/walk.h"
#include "model/scene/frame.h"
#include "traces/capture/draw_recorder.h"

namespace nbsim::capture {

// GL's walk of every fragment of one box draw (pixel order).
struct GlFragments {
  std::vector<std::uint32_t> pixel, hit, lookups, steps, bisections;
  std::vector<float> t;
  // With a box depth other than none: the CRC-32 (zlib) of the depth buffer right after the draw,
  // window depths as floats, y up, row-major; and the milliseconds its read-back took (capture
  // work, not the technique's: the caller takes it off the frame's GL time).
  std::optional<std::uint32_t> depth_crc;
  double readback_ms = 0.0;
};

// A camera on the box: texel space to clip (column-major, float, as GL takes it) and the ray frame.
struct ReliefView {
  std::array<float, 16> texel_to_clip{};
  relief::RayFrame ray;
};

class GlReliefWalker {
 public:
  // A width x height viewport; the N-buffer walk covers its spans as `covering` says (draw()'s
  // params must carry the same).
  // `box_depth`: what each box draw leaves in the depth buffer (model/relief/box_depth.h); box adds
  // a depth pass after each walk (relief_keep.frag), exact compiles relief.frag to write
  // gl_FragDepth (no early tests).
  GlReliefWalker(int width, int height, CoveringSpec covering = {}, relief::BoxDepth box_depth = relief::BoxDepth::None);
  ~GlReliefWalker();
  GlReliefWalker(const GlReliefWalker&) = delete;
  GlReliefWalker& operator=(const GlReliefWalker&) = delete;

  // Uploads the field and its radius and builds the N-buffer on GL (its passes recorded with
  // `recorder`). The radius may be empty (the robust methods then read 0 everywhere).
  void set_field(const relief::Heightfield& field, const relief::SafetyRadius& radius, DrawRecorder& recorder);
  // The N-buffer GL built, levels * N * N, level-major.
  std::vector<float> levels() const;
  int level_count() const noexcept;

  // Clears the depth buffer (1.0).
  void clear_depth();
  // One box draw with `method`, recorded (role relief_box, the box's 36 vertices captured), into the
  // walker's own framebuffer or, when `framebuffer` is not 0, into that one (its depth attachment
  // holds a scene drawn before, LESS; no colour is written there).
  GlFragments draw(relief::Method method, const ReliefView& view, const relief::WalkParams& params, DrawRecorder& recorder,
                   GLuint framebuffer = 0);

 private:
  struct Objects;
  std::unique_ptr<Objects> gl_;
  int width_, height_;
  CoveringSpec covering_;
  relief::BoxDepth box_depth_;
  int size_ = 0;
};

}  // namespace nbsim::capture

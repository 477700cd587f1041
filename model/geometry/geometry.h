// Geometry stage: clip-space triangles (gl_Position as the vertex shader wrote it) to window-space
// triangles for triangle setup (model/raster), the way Mesa's draw module does it in front of
// llvmpipe: frustum clipping without a guard band, perspective divide, viewport transform and,
// on batches that needed clipping, the draw module's floating-point face cull.
//
// What is matched, and where it comes from (Mesa 22.3, src/gallium/auxiliary/draw):
// - draw_llvm.c generate_clipmask: one outcode bit per plane, 0: x > w, 1: x + w < 0, 2: y > w,
//   3: y + w < 0, 4: z + w < 0 (z < 0 for clip control ZERO_TO_ONE), 5: z > w. Depth clamp turns
//   the two z planes off.
// - draw_llvm.c generate_viewport: every vertex gets 1/w = 1 / w and window = fmuladd(c * (1/w),
//   scale, translate); LLVM fuses fmuladd into one FMA on hosts that have it (this project's x86-64
//   hosts do: docs/architecture.md, "Platform facts"), so `fused_viewport` is on by default.
// - draw_pt_fetch_shade_pipeline_llvm.c: a batch of vertices in which any vertex has an outcode
//   runs through the draw pipeline (clip stage, then cull stage) as a whole; other batches go
//   straight to llvmpipe's setup, which culls by itself (model/raster/setup.h).
// - draw_pipe_clip.c: a triangle whose three outcodes share a bit is dropped, one with no
//   outcode passes; the others are clipped plane by plane in outcode-bit order (Sutherland-
//   Hodgman, with Mesa's choice of interpolation direction) and emitted as a fan (v[i-1], v[i],
//   v[0]); new vertices get their window position in plain float arithmetic (no FMA).
// - draw_pipe_cull.c: det = (v0 - v2) x (v1 - v2) in window coordinates, a culled face or a zero
//   determinant is dropped. (Later Mesa keeps zero-area triangles when only front faces are
//   culled; which rule 22.3.6 has is not verified, the traces only cull back faces.)
// The counters map onto GL's: prims_in is GL_CLIPPING_INPUT_PRIMITIVES and prims_out is
// GL_CLIPPING_OUTPUT_PRIMITIVES as llvmpipe counts it (each triangle that reaches its setup).
//
// Points (process_points), Mesa 22.3:
// - draw_pipe_clip.c clip_first_point picks clip_point unless draw->guard_band_points_lines_xy;
//   that flag is guard_band_xy || (driver.bypass_clip_points_lines && rasterizer
//   point_line_tri_clip) (draw_context.c draw_update_clip_flags; older trees call them
//   guard_band_points_xy, bypass_clip_points and point_tri_clip). llvmpipe calls
//   draw_set_driver_clipping(draw, false, false, false, true) (lp_context.c: clipping on, no guard
//   band) and the state tracker sets point_line_tri_clip only for GLES 2 (st_atom_rasterizer.c),
//   so desktop GL points are clipped by their centre: a point with any outcode bit (x, y, near,
//   far; the same generate_clipmask as triangles) is dropped whole, even when its square would
//   overlap the viewport; a point with none goes to setup unchanged. Batches without outcodes
//   skip the pipeline, which changes nothing for points.
// - llvmpipe never turns points into triangles: it sets draw_wide_point_threshold(10000),
//   draw_wide_point_sprites(false) and draw_enable_point_sprites(false) (lp_context.c), so
//   draw_need_pipeline (draw_pipe_validate.c) never inserts draw_pipe_wide_point.c; the point
//   reaches lp_setup_point.c as one vertex with its gl_PointSize (model/raster/point_setup.h).
// - The window position is the same viewport transform as a triangle vertex's (to_window).
// - GL_CLIPPING_INPUT_PRIMITIVES counts every point, GL_CLIPPING_OUTPUT_PRIMITIVES every point
//   that reaches try_setup_point (it counts c_primitives before its own draw-region test).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "model/geometry/primitive.h"

namespace nbsim::geometry {

// Depth convention of the clip volume. Fixed values, equal to scene::ClipControl.
enum class ClipControl : std::uint8_t { NegativeOneToOne = 0, ZeroToOne = 1 };

// A clip-space position x, y, z, w (the layout of scene::DrawRecord::clip_positions).
using ClipPosition = std::array<float, 4>;

struct GeometryConfig {
  int width_px = 0;   // viewport (and render target) width, 1 .. 16384
  int height_px = 0;  // viewport height, 1 .. 16384
  // Vertices per batch of the draw module: llvmpipe's vertex buffer is 4096 bytes and a vertex
  // with no fragment-shader input takes 16, so 256 vertices, cut to whole triangles (85). Only
  // matters for draws of more than 85 triangles. Tunable (1 .. 1 << 20), derived, not measured.
  int batch_triangles = 85;
  // Window coordinates of shaded vertices with one fused multiply-add (LLVM on FMA hosts) or a
  // separately rounded multiply and add (hosts without FMA).
  bool fused_viewport = true;
  // The viewport's y scale negated (rows counted from the top): how llvmpipe draws a window-system
  // framebuffer, relative to an FBO (the state tracker inverts the viewport for FBOs only). The clip
  // planes see the positions as given, so a triangle is clipped as GL clips it.
  bool flip_y = false;
};

// The per-draw state the stage reads.
struct GeometryState {
  ClipControl clip = ClipControl::NegativeOneToOne;
  FaceState face;
  bool depth_clamp = false;  // GL_DEPTH_CLAMP: no near/far clipping
};

// Per-draw counters of the stage (added to, never reset by the stage).
struct GeometryCounters {
  std::uint64_t prims_in = 0;            // triangles entering clipping (GL_CLIPPING_INPUT_PRIMITIVES)
  std::uint64_t trivially_rejected = 0;  // all three vertices outside one frustum plane
  std::uint64_t clipped = 0;             // triangles that crossed a plane and were clipped
  std::uint64_t clipped_away = 0;        // clipped triangles with nothing left (or a NaN distance)
  std::uint64_t draw_culled = 0;         // dropped by the draw module's float face cull (or all,
                                         // uncounted by llvmpipe, when both faces are culled)
  std::uint64_t prims_out = 0;           // triangles handed to setup (GL_CLIPPING_OUTPUT_PRIMITIVES)
  std::uint64_t batches = 0;             // vertex batches
  std::uint64_t pipeline_batches = 0;    // batches that went through the clip and cull stages

  GeometryCounters& operator+=(const GeometryCounters& o);
};

class GeometryStage {
 public:
  // Throws InputError for a viewport or batch size outside the limits above.
  explicit GeometryStage(const GeometryConfig& config);

  // Appends the window-space triangles of one draw to `out` (three clip positions a triangle;
  // a trailing incomplete triangle is ignored, as GL does) and adds to `counters`.
  void process(std::span<const ClipPosition> clip_positions, const GeometryState& state,
               std::vector<WindowTriangle>& out, GeometryCounters& counters) const;

  // Appends the points of one draw (one clip position and one gl_PointSize each) that survive
  // centre clipping to `out` and adds to `counters` (prims_in: points, trivially_rejected: centres
  // outside the clip volume, prims_out: points handed to setup). Throws InputError naming the
  // point when the counts differ or a position or size is NaN or infinite.
  void process_points(std::span<const ClipPosition> clip_positions, std::span<const float> point_sizes,
                      const GeometryState& state, std::vector<WindowPoint>& out, GeometryCounters& counters) const;

  const GeometryConfig& config() const noexcept { return config_; }

  // The window position of an unclipped vertex, as the draw module's shader epilogue computes it.
  WindowVertex to_window(const ClipPosition& p, ClipControl clip) const noexcept;
  // The outcode of a vertex (bit k set: outside plane k, see the header comment).
  static unsigned outcode(const ClipPosition& p, ClipControl clip, bool depth_clamp) noexcept;

 private:
  struct Viewport {
    std::array<float, 3> scale{}, translate{};
  };
  const Viewport& viewport(ClipControl clip) const noexcept { return viewports_[static_cast<int>(clip) & 1]; }
  void emit_batch(std::span<const ClipPosition> batch, const GeometryState& state, std::vector<WindowTriangle>& out,
                  GeometryCounters& counters) const;

  GeometryConfig config_;
  std::array<Viewport, 2> viewports_{};  // indexed by ClipControl
};

// The draw module's float face test on window positions: true when the triangle is dropped
// (zero determinant, or a culled face). Exposed for tests.
bool draw_module_culls(const WindowTriangle& t, const FaceState& face) noexcept;

}  // namespace nbsim::geometry

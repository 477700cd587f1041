// The draw recorder of the capture renderer: every draw a technique records gets a slot with its
// GL counters (GL_SAMPLES_PASSED and the clipper's input/output primitive queries, the fragment
// shader's atomic counter in an SSBO at binding 0, indexed by the slot) and, for geometry, its
// post-transform gl_Position captured with transform feedback. Results are read once, at the end of
// the frame (collect), except for samples_passed, which a technique may wait for at once.
// A shader that counts fragments declares `buffer Fragments { uint fragments[]; }` at binding 0
// and adds 1 at fragments[draw_slot] without early fragment tests, so that it counts every
// rasterized fragment (docs/architecture.md, "Platform facts").
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "model/scene/frame.h"
#include "traces/capture/gl_program.h"

namespace nbsim::capture {

// The depth state of the renderer's convention (LESS with [-1, 1] clip z, or reversed Z: GREATER
// with ZERO_TO_ONE), back faces culled, counter-clockwise front faces.
scene::DepthState depth_state(bool reversed, bool write, bool test);

class DrawRecorder {
 public:
  DrawRecorder();
  ~DrawRecorder();
  DrawRecorder(const DrawRecorder&) = delete;
  DrawRecorder& operator=(const DrawRecorder&) = delete;

  // Starts a frame: forgets the last frame's records, makes room for `expected_draws` slots (more
  // grow on demand) and zeroes the fragment counters.
  void begin_frame(std::size_t expected_draws);

  // Binds the fragment-counter SSBO at binding 0 and the transform feedback object.
  void bind() const;

  // A recorded GL draw: record.index becomes its slot, its queries begin and, when
  // `captured_vertices` > 0, transform feedback of that many vertices of `primitive` (GL_TRIANGLES,
  // GL_POINTS, ...) begins. The caller sets its shader's draw_slot to the returned slot, issues the
  // one draw and calls end_draw(). GL_POINTS captures gl_Position and gl_PointSize (the program is
  // linked with link_program(..., true, true)) into clip_positions and point_sizes, and sets the
  // record's topology to Points.
  std::size_t begin_draw(scene::DrawRecord record, std::size_t captured_vertices, GLenum primitive = GL_TRIANGLES);
  void end_draw();

  // A record that is not a GL draw (e.g. a bounds test done by a shader): no counters.
  std::size_t add_record(scene::DrawRecord record);

  scene::DrawRecord& record(std::size_t slot) { return draws_[slot]; }
  std::size_t size() const noexcept { return draws_.size(); }

  // GL_SAMPLES_PASSED of a slot's draw, waiting for it (the GPU-to-CPU round trip a query result costs).
  std::uint64_t samples_passed(std::size_t slot) const;

  // A counter slot past every recorded one, for passes whose counts are not recorded.
  std::uint32_t scratch_slot();

  // Every record of the frame with its GL counters and captured clip positions, in slot order;
  // the recorder is empty afterwards.
  std::vector<scene::DrawRecord> collect();

 private:
  struct Pending {
    bool gl_draw = false;
    bool capturing = false;
    std::size_t tf_offset = 0, tf_bytes = 0;
    std::size_t floats_per_vertex = 4;  // gl_Position, then gl_PointSize for points
  };
  void reserve(std::size_t draw_count, std::size_t tf_bytes);

  std::vector<scene::DrawRecord> draws_;
  std::vector<Pending> pending_;
  std::size_t tf_used_ = 0;
  GLuint counts_ssbo_ = 0, tf_buffer_ = 0, tf_object_ = 0;
  std::size_t counts_capacity_ = 0, tf_capacity_ = 0;  // slots, bytes
  std::vector<GLuint> q_samples_, q_clip_in_, q_clip_out_;
  // Query-wrapped draws since the last flush, times the viewport's 64x64 bins (begin_draw).
  static constexpr std::uint64_t kFlushBinDraws = 32768;
  std::uint64_t scene_bin_draws_ = 0;
};

}  // namespace nbsim::capture

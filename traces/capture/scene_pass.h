// Drawing a CaptureScene with the common scene shaders (shaders/common/scene.vert, count.frag):
// its objects' triangles and, for techniques that test bounds, the boxes of every object and BVH
// node (scene::kBoxIndices, the pattern the model uses too). Each draw is recorded by a
// DrawRecorder (clip positions captured, fragments counted); the fragment shader writes
// object id + 1, which the ID-buffer pass of the ground truth reads.
#pragma once

#include <glm/mat4x4.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "model/scene/frame.h"
#include "traces/capture/draw_recorder.h"
#include "traces/capture/gl_program.h"
#include "traces/capture/render_target.h"
#include "traces/capture/scenes.h"

namespace nbsim::capture {

class ScenePass {
 public:
  // with_boxes: also upload the 8 corners of every object's and BVH node's bounds.
  // `fragment_source` (named `fragment_name` in compile errors) replaces count.frag: a technique's
  // own fragment stage over the same draws. It must count fragments as count.frag does
  // (draw_recorder.h) and declare the uniforms draw_slot and object_id; its other uniforms are the
  // technique's, set on program() after begin().
  ScenePass(const CaptureScene& scene, bool with_boxes, const char* fragment_source = nullptr, const char* fragment_name = nullptr);
  ~ScenePass();
  ScenePass(const ScenePass&) = delete;
  ScenePass& operator=(const ScenePass&) = delete;

  // Binds the target, the program with `view_proj`, the recorder's buffers and the state of the
  // convention: depth test (LESS, or GREATER when reversed), back faces culled, CCW fronts, no
  // colour writes.
  void begin(const RenderTarget& target, const glm::mat4& view_proj, bool reversed, const DrawRecorder& recorder) const;

  // Recorded draws (after begin): object o's triangles, or the box of object `object` (node < 0)
  // or of BVH node `node`. `record` gives role, object, node and depth state; its depth write
  // decides the depth mask.
  std::size_t draw_object(DrawRecorder& recorder, scene::DrawRecord record, std::uint32_t o) const;
  std::size_t draw_box(DrawRecorder& recorder, scene::DrawRecord record) const;

  // Unrecorded draws of `objects`' triangles in that order, counters in `counter_slot`, each
  // writing its id (for the ID buffer).
  void draw_ids(const std::vector<std::uint32_t>& objects, std::uint32_t counter_slot) const;

  const CaptureScene& scene() const noexcept { return scene_; }
  // The scene's vertex array (positions at attribute 0, the indices bound), for a technique's own
  // programs over the same geometry.
  GLuint scene_vertex_array() const noexcept { return scene_vao_; }
  GLuint program() const noexcept { return program_; }

 private:
  std::size_t draw(DrawRecorder& recorder, scene::DrawRecord record, bool box, std::uint32_t index_count,
                   std::uint32_t first_index, GLint base_vertex) const;

  const CaptureScene& scene_;
  GLuint scene_vao_ = 0, scene_vbo_ = 0, scene_ebo_ = 0;
  GLuint box_vao_ = 0, box_vbo_ = 0, box_ebo_ = 0;
  GLuint program_ = 0;
  GLint u_view_proj_ = -1, u_draw_slot_ = -1, u_object_id_ = -1;
};

}  // namespace nbsim::capture

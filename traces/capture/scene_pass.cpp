// Scene and bounding-box draws; see scene_pass.h.
#include "traces/capture/scene_pass.h"

#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <array>

#include "model/common/error.h"
#include "model/scene/visibility.h"
#include "nbsim_shaders.h"

namespace nbsim::capture {

namespace {

GLuint make_vao(GLuint vbo, GLuint ebo) {
  GLuint vao = 0;
  glCreateVertexArrays(1, &vao);
  glVertexArrayVertexBuffer(vao, 0, vbo, 0, sizeof(glm::vec3));
  glVertexArrayElementBuffer(vao, ebo);
  glEnableVertexArrayAttrib(vao, 0);
  glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(vao, 0, 0);
  return vao;
}

}  // namespace

ScenePass::ScenePass(const CaptureScene& scene, bool with_boxes, const char* fragment_source, const char* fragment_name) : scene_(scene) {
  glCreateBuffers(1, &scene_vbo_);
  glCreateBuffers(1, &scene_ebo_);
  glNamedBufferStorage(scene_vbo_, static_cast<GLsizeiptr>(scene.vertices.size() * sizeof(glm::vec3)), scene.vertices.data(), 0);
  glNamedBufferStorage(scene_ebo_, static_cast<GLsizeiptr>(scene.indices.size() * 4), scene.indices.data(), 0);
  scene_vao_ = make_vao(scene_vbo_, scene_ebo_);

  if (with_boxes) {
    // Boxes of every object, then of every BVH node: 8 corners each.
    std::vector<glm::vec3> corners;
    auto add = [&](const scene::Aabb& b) {
      for (int i = 0; i < 8; ++i) corners.push_back({i & 1 ? b.hi[0] : b.lo[0], i & 2 ? b.hi[1] : b.lo[1], i & 4 ? b.hi[2] : b.lo[2]});
    };
    for (const auto& b : scene.scene.objects) add(b);
    for (const auto& b : scene.scene.node_bounds) add(b);
    glCreateBuffers(1, &box_vbo_);
    glCreateBuffers(1, &box_ebo_);
    glNamedBufferStorage(box_vbo_, static_cast<GLsizeiptr>(corners.size() * sizeof(glm::vec3)), corners.data(), 0);
    // The box pattern the model uses too (model/scene/visibility.h), widened to GL's index type.
    std::array<std::uint32_t, 36> box_indices{};
    std::copy(scene::kBoxIndices.begin(), scene::kBoxIndices.end(), box_indices.begin());
    glNamedBufferStorage(box_ebo_, sizeof box_indices, box_indices.data(), 0);
    box_vao_ = make_vao(box_vbo_, box_ebo_);
  }

  program_ = link_program({compile_shader(GL_VERTEX_SHADER, shaders::common_scene_vert, "common/scene.vert"),
                           fragment_source ? compile_shader(GL_FRAGMENT_SHADER, fragment_source, fragment_name ? fragment_name : "fragment")
                                           : compile_shader(GL_FRAGMENT_SHADER, shaders::common_count_frag, "common/count.frag")},
                          "scene", true);
  u_view_proj_ = glGetUniformLocation(program_, "view_proj");
  u_draw_slot_ = glGetUniformLocation(program_, "draw_slot");
  u_object_id_ = glGetUniformLocation(program_, "object_id");
}

ScenePass::~ScenePass() {
  const GLuint vaos[] = {scene_vao_, box_vao_};
  glDeleteVertexArrays(2, vaos);
  const GLuint buffers[] = {scene_vbo_, scene_ebo_, box_vbo_, box_ebo_};
  glDeleteBuffers(4, buffers);
  glDeleteProgram(program_);
}

void ScenePass::begin(const RenderTarget& target, const glm::mat4& view_proj, bool reversed, const DrawRecorder& recorder) const {
  target.bind();
  glUseProgram(program_);
  glUniformMatrix4fv(u_view_proj_, 1, GL_FALSE, glm::value_ptr(view_proj));
  recorder.bind();
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(reversed ? GL_GREATER : GL_LESS);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glFrontFace(GL_CCW);
  glColorMaski(0, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
}

std::size_t ScenePass::draw(DrawRecorder& recorder, scene::DrawRecord record, bool box, std::uint32_t index_count,
                            std::uint32_t first_index, GLint base_vertex) const {
  const GLuint object_id = static_cast<GLuint>(std::max(record.object, 0));
  const bool write = record.state.write;
  const std::size_t slot = recorder.begin_draw(std::move(record), index_count);
  glUniform1ui(u_draw_slot_, static_cast<GLuint>(slot));
  glUniform1ui(u_object_id_, object_id);
  glDepthMask(write ? GL_TRUE : GL_FALSE);
  glBindVertexArray(box ? box_vao_ : scene_vao_);
  glDrawElementsBaseVertex(GL_TRIANGLES, static_cast<GLsizei>(index_count), GL_UNSIGNED_INT,
                           reinterpret_cast<const void*>(static_cast<std::uintptr_t>(first_index) * 4), base_vertex);
  recorder.end_draw();
  return slot;
}

std::size_t ScenePass::draw_object(DrawRecorder& recorder, scene::DrawRecord record, std::uint32_t o) const {
  const MeshRange& m = scene_.objects[o];
  return draw(recorder, std::move(record), false, m.index_count, m.first_index, 0);
}

std::size_t ScenePass::draw_box(DrawRecorder& recorder, scene::DrawRecord record) const {
  NBSIM_CHECK(box_vao_ != 0, "draw_box() on a ScenePass made without boxes");
  const std::size_t box = record.node >= 0 ? scene_.scene.objects.size() + static_cast<std::size_t>(record.node)
                                           : static_cast<std::size_t>(record.object);
  return draw(recorder, std::move(record), true, 36, 0, static_cast<GLint>(box * 8));
}

void ScenePass::draw_ids(const std::vector<std::uint32_t>& objects, std::uint32_t counter_slot) const {
  glBindVertexArray(scene_vao_);
  glUniform1ui(u_draw_slot_, counter_slot);
  for (auto o : objects) {
    const MeshRange& m = scene_.objects[o];
    glUniform1ui(u_object_id_, o);
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(m.index_count), GL_UNSIGNED_INT,
                   reinterpret_cast<const void*>(static_cast<std::uintptr_t>(m.first_index) * 4));
  }
}

}  // namespace nbsim::capture

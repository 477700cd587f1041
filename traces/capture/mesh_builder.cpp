// Object-by-object scene geometry; see mesh_builder.h.
#include "traces/capture/mesh_builder.h"

#include <glm/common.hpp>

#include <cmath>

#include "model/common/error.h"
#include "traces/capture/city.h"

namespace nbsim::capture {

void MeshBuilder::begin(std::string_view cls) {
  scene_.objects.push_back({static_cast<std::uint32_t>(scene_.indices.size()), 0});
  scene_.object_class.push_back(scene_class(scene_, cls));
}

void MeshBuilder::end() {
  MeshRange& m = scene_.objects.back();
  m.index_count = static_cast<std::uint32_t>(scene_.indices.size()) - m.first_index;
  NBSIM_CHECK(m.index_count >= 3, "an object without triangles");
}

std::uint32_t MeshBuilder::vertex(glm::vec3 p) {
  scene_.vertices.push_back(p);
  return static_cast<std::uint32_t>(scene_.vertices.size() - 1);
}

void MeshBuilder::triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  scene_.indices.insert(scene_.indices.end(), {a, b, c});
}

void MeshBuilder::box(glm::vec3 lo, glm::vec3 hi) {
  const auto base = static_cast<std::uint32_t>(scene_.vertices.size());
  for (int i = 0; i < 8; ++i) vertex({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
  // Faces as corner indices (bit 0 = x, bit 1 = y, bit 2 = z), counter-clockwise seen from outside.
  static constexpr std::uint32_t faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                                {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces) {
    triangle(base + f[0], base + f[1], base + f[2]);
    triangle(base + f[0], base + f[2], base + f[3]);
  }
}

void MeshBuilder::finish() {
  std::vector<scene::Aabb> bounds;
  bounds.reserve(scene_.objects.size());
  scene_.scene.triangles.clear();
  for (const MeshRange& m : scene_.objects) {
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (std::uint32_t i = m.first_index; i < m.first_index + m.index_count; ++i) {
      lo = glm::min(lo, scene_.vertices[scene_.indices[i]]);
      hi = glm::max(hi, scene_.vertices[scene_.indices[i]]);
    }
    bounds.push_back({{lo.x, lo.y, lo.z}, {hi.x, hi.y, hi.z}});
    scene_.scene.triangles.push_back(m.index_count / 3);
  }
  scene_.scene.objects = bounds;
  build_bvh(bounds, scene_.scene);
}

}  // namespace nbsim::capture

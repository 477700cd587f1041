// The q3bsp scene; see q3bsp_scene.h.
#include "traces/capture/q3bsp_scene.h"

#include <glm/common.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <tuple>

#include "traces/capture/mesh_builder.h"

namespace nbsim::capture {

namespace {

const char* class_of(BspFaceType t) {
  switch (t) {
    case BspFaceType::Polygon: return "structure";
    case BspFaceType::Patch: return "patch";
    case BspFaceType::Mesh: return "mesh";
  }
  return "structure";
}

}  // namespace

CaptureScene make_q3bsp_scene(const BspMap& map, const std::string& name, const Q3BspSceneParams& params) {
  CaptureScene s;
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (std::uint32_t i : map.indices) lo = glm::min(lo, map.vertices[i]), hi = glm::max(hi, map.vertices[i]);
  s.vertices.reserve(map.vertices.size());
  for (const glm::vec3& v : map.vertices) s.vertices.push_back(v - lo);
  // Objects: the faces by (leaf, type, cell), in that order; a face's triangles stay together.
  using Key = std::tuple<std::uint32_t, BspFaceType, std::int64_t, std::int64_t, std::int64_t>;
  std::vector<Key> keys;
  keys.reserve(map.faces.size());
  for (const BspFace& f : map.faces) {
    glm::vec3 flo(INFINITY), fhi(-INFINITY);
    for (std::uint32_t i = f.first_index; i < f.first_index + f.index_count; ++i)
      flo = glm::min(flo, map.vertices[map.indices[i]]), fhi = glm::max(fhi, map.vertices[map.indices[i]]);
    std::array<std::int64_t, 3> cell{};
    if (params.object_cell_m > 0.0)
      for (int a = 0; a < 3; ++a) cell[a] = static_cast<std::int64_t>(std::floor((0.5 * (flo[a] + fhi[a]) - lo[a]) / params.object_cell_m));
    keys.emplace_back(f.leaf, f.type, cell[0], cell[1], cell[2]);
  }
  std::vector<std::uint32_t> order(map.faces.size());
  std::iota(order.begin(), order.end(), 0u);
  auto key = [&](std::uint32_t f) { return keys[f]; };
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
  MeshBuilder b(s);
  for (std::size_t k = 0; k < order.size(); ++k) {
    const BspFace& f = map.faces[order[k]];
    if (k == 0 || key(order[k - 1]) != key(order[k])) b.begin(class_of(f.type));
    for (std::uint32_t i = f.first_index; i < f.first_index + f.index_count; i += 3)
      b.triangle(map.indices[i], map.indices[i + 1], map.indices[i + 2]);
    if (k + 1 == order.size() || key(order[k + 1]) != key(order[k])) b.end();
  }
  b.finish();
  s.site.extent_m = std::max(hi.x - lo.x, hi.z - lo.z);
  s.site.enclosed = true;
  std::vector<glm::vec3> spots;
  for (const BspEntity& e : map.entities) spots.push_back(e.origin - lo);
  WaypointGraph g = link_waypoints(TriangleCaster(s.vertices, s.indices), spots, params.waypoints);
  s.site.waypoints = std::move(g.points);
  s.site.waypoint_links = std::move(g.links);
  s.properties = {{"bsp", std::filesystem::path(name).filename().string()},
                  {"objects", std::to_string(s.objects.size())},
                  {"triangles", std::to_string(s.indices.size() / 3)},
                  {"patch_segments", std::to_string(params.patch_segments)},
                  {"object_cell_m", fmt::format("{}", params.object_cell_m)},
                  {"waypoints", std::to_string(s.site.waypoints.size())},
                  {"waypoint_links", std::to_string(s.site.waypoint_links.size())}};
  return s;
}

}  // namespace nbsim::capture

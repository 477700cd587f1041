// Casters, silhouettes and shadow-volume geometry; see volumes.h.
#include "traces/capture/shadows/volumes.h"

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include <cmath>
#include <map>
#include <utility>

namespace nbsim::capture {

namespace {

glm::dvec3 vertex(const CaptureScene& s, std::uint32_t i) { return glm::dvec3(s.vertices[i]); }

bool faces_light(const CaptureScene& s, const std::array<std::uint32_t, 3>& t, const glm::dvec3& light) {
  const glm::dvec3 a = vertex(s, t[0]), b = vertex(s, t[1]), c = vertex(s, t[2]);
  return glm::dot(glm::cross(b - a, c - a), light - a) > 0.0;
}

bool finite(const glm::dmat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

}  // namespace

std::vector<CasterMesh> find_casters(const CaptureScene& scene) {
  std::vector<CasterMesh> out;
  for (std::uint32_t o = 0; o < scene.objects.size(); ++o) {
    const MeshRange& m = scene.objects[o];
    CasterMesh c;
    c.object = o;
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::int32_t> edge_owner;  // directed edge -> triangle
    bool closed = true;
    for (std::uint32_t i = m.first_index; i + 2 < m.first_index + m.index_count; i += 3) {
      const std::array<std::uint32_t, 3> t = {scene.indices[i], scene.indices[i + 1], scene.indices[i + 2]};
      for (int k = 0; k < 3; ++k)
        closed = edge_owner.emplace(std::pair{t[k], t[(k + 1) % 3]}, static_cast<std::int32_t>(c.triangles.size())).second && closed;
      c.triangles.push_back(t);
    }
    c.neighbour.resize(c.triangles.size());
    for (std::size_t t = 0; t < c.triangles.size() && closed; ++t)
      for (int k = 0; k < 3; ++k) {
        const auto it = edge_owner.find({c.triangles[t][(k + 1) % 3], c.triangles[t][k]});
        if (it == edge_owner.end()) closed = false;
        else c.neighbour[t][k] = it->second;
      }
    if (closed && !c.triangles.empty()) out.push_back(std::move(c));
  }
  return out;
}

bool LightCamera::make() {
  const glm::dvec3 dir = target - eye;
  if (!(glm::length(dir) > 1e-9) || !(near_m > 0.0) || !(far_m > near_m) || !(fov_y_deg > 0.0 && fov_y_deg < 180.0)) return false;
  const glm::dvec3 up = std::abs(glm::normalize(dir).y) > 0.99 ? glm::dvec3(0, 0, -1) : glm::dvec3(0, 1, 0);
  view = glm::lookAt(eye, target, up);
  proj = glm::perspective(glm::radians(fov_y_deg), 1.0, near_m, far_m);
  return finite(view) && finite(proj);
}

double LightCamera::window_depth(const glm::dvec3& p) const {
  const glm::dvec4 c = clip(p);
  return 0.5 * c.z / c.w + 0.5;
}

double LightCamera::depth_of_distance(double d) const {
  // GL's perspective: z_ndc = (f + n) / (f - n) - 2 f n / ((f - n) d) for a point at distance d.
  const double n = near_m, f = far_m;
  return 0.5 * ((f + n) / (f - n) - 2.0 * f * n / ((f - n) * d)) + 0.5;
}

double LightCamera::distance_of_depth(double depth) const {
  const double n = near_m, f = far_m, z_ndc = 2.0 * depth - 1.0;
  return 2.0 * f * n / ((f - n) * ((f + n) / (f - n) - z_ndc));
}

glm::dvec3 LightCamera::light_ray_point(const glm::dvec3& p, double depth) const {
  const double along = -(view * glm::dvec4(p, 1.0)).z;  // distance of p along the view axis
  return eye + (p - eye) * (distance_of_depth(depth) / along);
}

void append_volume(const CaptureScene& scene, const CasterMesh& caster, const LightCamera& light, const VolumeEnds& ends,
                   std::vector<glm::vec4>& out) {
  // The points of vertex i at each level of its light ray: the vertex, the near plane, the far
  // plane, infinity; `levels` lists the ones this volume uses, in order from the light.
  enum Level { Vertex, NearPlane, FarPlane, Infinity };
  auto point = [&](Level level, std::uint32_t i) -> glm::dvec4 {
    const glm::dvec3 p = vertex(scene, i);
    switch (level) {
      case Vertex: return glm::dvec4(p, 1.0);
      case NearPlane: return glm::dvec4(light.light_ray_point(p, ends.near_depth), 1.0);
      case FarPlane: {
        const double d = light.window_depth(p);
        return glm::dvec4(d >= ends.far_depth ? p : light.light_ray_point(p, ends.far_depth), 1.0);
      }
      case Infinity: break;
    }
    return glm::dvec4(p - light.eye, 0.0);
  };
  std::vector<Level> levels;
  if (!ends.clamped || !ends.near_plane) levels.push_back(Vertex);
  if (ends.near_plane) levels.push_back(NearPlane);
  if (ends.far_plane) levels.push_back(FarPlane);
  if (!ends.clamped || !ends.far_plane) levels.push_back(Infinity);
  auto emit = [&](const glm::dvec4& a, const glm::dvec4& b, const glm::dvec4& c) {
    out.emplace_back(glm::vec4(a));
    out.emplace_back(glm::vec4(b));
    out.emplace_back(glm::vec4(c));
  };
  std::vector<char> lit(caster.triangles.size());
  for (std::size_t t = 0; t < caster.triangles.size(); ++t) lit[t] = faces_light(scene, caster.triangles[t], light.eye);
  const Level first = levels.front(), last = levels.back();
  for (std::size_t t = 0; t < caster.triangles.size(); ++t) {
    if (!lit[t]) continue;
    const auto& v = caster.triangles[t];
    emit(point(first, v[0]), point(first, v[1]), point(first, v[2]));  // front cap
    emit(point(last, v[0]), point(last, v[2]), point(last, v[1]));     // back cap, reversed
    for (int k = 0; k < 3; ++k) {
      if (lit[static_cast<std::size_t>(caster.neighbour[t][k])]) continue;
      const std::uint32_t a = v[k], b = v[(k + 1) % 3];  // a silhouette edge, as the lit triangle winds it
      for (std::size_t l = 0; l + 1 < levels.size(); ++l) {
        const Level from = levels[l], to = levels[l + 1];
        emit(point(from, a), point(to, a), point(to, b));
        emit(point(from, a), point(to, b), point(from, b));
      }
    }
  }
}

std::size_t silhouette_edges(const CaptureScene& scene, const CasterMesh& caster, const glm::dvec3& light) {
  std::size_t n = 0;
  for (std::size_t t = 0; t < caster.triangles.size(); ++t) {
    if (!faces_light(scene, caster.triangles[t], light)) continue;
    for (int k = 0; k < 3; ++k) n += !faces_light(scene, caster.triangles[static_cast<std::size_t>(caster.neighbour[t][k])], light);
  }
  return n;
}

}  // namespace nbsim::capture

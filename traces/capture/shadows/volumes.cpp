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

namespace {

// A point of a lit triangle's cap polygon: a caster vertex, or the point where one of its edges
// crosses the near plane (on the plane, its own projection there).
struct CapPoint {
  glm::dvec3 p;
  bool front = false;  // nearer the light than the near plane (projected there by a clamped volume)
};

// Where edge a-b of the caster crosses the light's plane at view distance `plane_m`, computed from
// the edge's endpoints in index order so that both triangles sharing the edge get the same point.
glm::dvec3 crossing(const CaptureScene& scene, std::uint32_t a, std::uint32_t b, const LightCamera& light, double plane_m) {
  if (b < a) std::swap(a, b);
  const glm::dvec3 pa = vertex(scene, a), pb = vertex(scene, b);
  const double za = -(light.view * glm::dvec4(pa, 1.0)).z, zb = -(light.view * glm::dvec4(pb, 1.0)).z;
  return pa + (pb - pa) * ((plane_m - za) / (zb - za));
}

}  // namespace

void append_volume(const CaptureScene& scene, const CasterMesh& caster, const LightCamera& light, const VolumeEnds& ends,
                   std::vector<glm::vec4>& out) {
  // The points of a cap point at each level of its light ray: the point, the near plane, the far
  // plane, infinity. A point behind the near plane has no near-plane level (its volume starts at
  // the caster); a front point has both, and a clamped volume starts it at the near plane.
  enum Level { Vertex, NearPlane, FarPlane, Infinity };
  auto point = [&](Level level, const CapPoint& c) -> glm::dvec4 {
    switch (level) {
      case Vertex: return glm::dvec4(c.p, 1.0);
      case NearPlane: return glm::dvec4(c.front ? light.light_ray_point(c.p, ends.near_depth) : c.p, 1.0);
      case FarPlane: {
        const double d = light.window_depth(c.p);
        return glm::dvec4(d >= ends.far_depth ? c.p : light.light_ray_point(c.p, ends.far_depth), 1.0);
      }
      case Infinity: break;
    }
    return glm::dvec4(c.p - light.eye, 0.0);
  };
  auto levels_of = [&](bool front) {
    std::vector<Level> levels;
    if (!(ends.clamped && front)) levels.push_back(Vertex);
    if (front) levels.push_back(NearPlane);
    if (ends.far_plane) levels.push_back(FarPlane);
    if (!ends.clamped || !ends.far_plane) levels.push_back(Infinity);
    return levels;
  };
  auto emit = [&](const glm::dvec4& a, const glm::dvec4& b, const glm::dvec4& c) {
    const glm::vec4 fa(a), fb(b), fc(c);
    if (fa == fb || fb == fc || fc == fa) return;  // no area: a split point's piece of zero length
    out.push_back(fa);
    out.push_back(fb);
    out.push_back(fc);
  };
  const double plane_m = ends.near_plane ? light.distance_of_depth(ends.near_depth) : 0.0;
  auto is_front = [&](std::uint32_t i) { return ends.near_plane && light.window_depth(vertex(scene, i)) < ends.near_depth; };
  std::vector<char> lit(caster.triangles.size());
  for (std::size_t t = 0; t < caster.triangles.size(); ++t) lit[t] = faces_light(scene, caster.triangles[t], light.eye);
  const std::vector<Level> front_levels = levels_of(true), back_levels = levels_of(false);
  std::vector<CapPoint> parts[2];  // the triangle's piece in front of the near plane, and behind it
  for (std::size_t t = 0; t < caster.triangles.size(); ++t) {
    if (!lit[t]) continue;
    const auto& v = caster.triangles[t];
    const std::array<bool, 3> front = {is_front(v[0]), is_front(v[1]), is_front(v[2])};
    // The caps: each piece a convex polygon in the triangle's winding, fanned from its first point;
    // the front piece at its first level (the near plane when clamped), both at the last, reversed.
    parts[0].clear(), parts[1].clear();
    for (int k = 0; k < 3; ++k) {
      const int n = (k + 1) % 3;
      parts[front[k] ? 0 : 1].push_back({vertex(scene, v[k]), front[k]});
      if (front[k] != front[n]) {
        const CapPoint m{crossing(scene, v[k], v[n], light, plane_m), false};
        parts[0].push_back(m), parts[1].push_back(m);
      }
    }
    for (int side = 0; side < 2; ++side) {
      const std::vector<CapPoint>& poly = parts[side];
      const std::vector<Level>& levels = side == 0 ? front_levels : back_levels;
      for (std::size_t i = 1; i + 1 < poly.size(); ++i) {
        const CapPoint& f = poly[0];
        emit(point(levels.front(), f), point(levels.front(), poly[i]), point(levels.front(), poly[i + 1]));  // near cap
        emit(point(levels.back(), f), point(levels.back(), poly[i + 1]), point(levels.back(), poly[i]));    // far cap, reversed
      }
    }
    // The sides: one strip of quads per silhouette edge (as the lit triangle winds it), split where
    // it crosses the near plane.
    for (int k = 0; k < 3; ++k) {
      if (lit[static_cast<std::size_t>(caster.neighbour[t][k])]) continue;
      const int n = (k + 1) % 3;
      const CapPoint a{vertex(scene, v[k]), front[k]}, b{vertex(scene, v[n]), front[n]};
      std::array<std::pair<CapPoint, CapPoint>, 2> pieces{{{a, b}, {}}};
      std::size_t count = 1;
      if (front[k] != front[n]) {
        const CapPoint m{crossing(scene, v[k], v[n], light, plane_m), false};
        pieces = {{{a, m}, {m, b}}};
        count = 2;
      }
      for (std::size_t p = 0; p < count; ++p) {
        const auto& [pa, pb] = pieces[p];
        const std::vector<Level>& levels = pa.front || pb.front ? front_levels : back_levels;
        for (std::size_t l = 0; l + 1 < levels.size(); ++l) {
          const Level from = levels[l], to = levels[l + 1];
          emit(point(from, pa), point(to, pa), point(to, pb));
          emit(point(from, pa), point(to, pb), point(from, pb));
        }
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

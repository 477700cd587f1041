// Shadow-volume geometry shared by the capture and the model; see volume.h.
#include "model/shadows/volume.h"

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "model/common/error.h"
#include "model/scene/technique_record.h"
#include "model/shadows/roles.h"

namespace nbsim::shadows {

namespace {

glm::dvec3 vertex(std::span<const glm::vec3> v, std::uint32_t i) { return glm::dvec3(v[i]); }

bool faces_light(std::span<const glm::vec3> s, const std::array<std::uint32_t, 3>& t, const glm::dvec3& light) {
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

std::optional<CasterMesh> closed_mesh(std::uint32_t object, std::span<const std::uint32_t> triangles) {
  CasterMesh c;
  c.object = object;
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::int32_t> edge_owner;  // directed edge -> triangle
  bool closed = true;
  for (std::size_t i = 0; i + 2 < triangles.size(); i += 3) {
    const std::array<std::uint32_t, 3> t = {triangles[i], triangles[i + 1], triangles[i + 2]};
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
  if (!closed || c.triangles.empty()) return std::nullopt;
  return c;
}

bool LightFrustum::make() {
  const glm::dvec3 dir = target - eye;
  if (!(glm::length(dir) > 1e-9) || !(near_m > 0.0) || !(far_m > near_m) || !(fov_y_deg > 0.0 && fov_y_deg < 180.0)) return false;
  const glm::dvec3 up = std::abs(glm::normalize(dir).y) > 0.99 ? glm::dvec3(0, 0, -1) : glm::dvec3(0, 1, 0);
  view = glm::lookAt(eye, target, up);
  proj = glm::perspective(glm::radians(fov_y_deg), 1.0, near_m, far_m);
  return finite(view) && finite(proj);
}

double LightFrustum::window_depth(const glm::dvec3& p) const {
  const glm::dvec4 c = clip(p);
  return 0.5 * c.z / c.w + 0.5;
}

double LightFrustum::depth_of_distance(double d) const {
  // GL's perspective: z_ndc = (f + n) / (f - n) - 2 f n / ((f - n) d) for a point at distance d.
  const double n = near_m, f = far_m;
  return 0.5 * ((f + n) / (f - n) - 2.0 * f * n / ((f - n) * d)) + 0.5;
}

double LightFrustum::distance_of_depth(double depth) const {
  const double n = near_m, f = far_m, z_ndc = 2.0 * depth - 1.0;
  return 2.0 * f * n / ((f - n) * ((f + n) / (f - n) - z_ndc));
}

glm::dvec3 LightFrustum::light_ray_point(const glm::dvec3& p, double depth) const {
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
glm::dvec3 crossing(std::span<const glm::vec3> scene, std::uint32_t a, std::uint32_t b, const LightFrustum& light, double plane_m) {
  if (b < a) std::swap(a, b);
  const glm::dvec3 pa = vertex(scene, a), pb = vertex(scene, b);
  const double za = -(light.view * glm::dvec4(pa, 1.0)).z, zb = -(light.view * glm::dvec4(pb, 1.0)).z;
  return pa + (pb - pa) * ((plane_m - za) / (zb - za));
}

}  // namespace

void append_volume(std::span<const glm::vec3> scene, const CasterMesh& caster, const LightFrustum& light, const VolumeEnds& ends,
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

std::size_t silhouette_edges(std::span<const glm::vec3> scene, const CasterMesh& caster, const glm::dvec3& light) {
  std::size_t n = 0;
  for (std::size_t t = 0; t < caster.triangles.size(); ++t) {
    if (!faces_light(scene, caster.triangles[t], light)) continue;
    for (int k = 0; k < 3; ++k) n += !faces_light(scene, caster.triangles[static_cast<std::size_t>(caster.neighbour[t][k])], light);
  }
  return n;
}

CasterRect caster_rect(const scene::Aabb& b, const LightFrustum& light, int litmap) {
  CasterRect r;
  std::array<glm::dvec4, 8> corners;
  for (int k = 0; k < 8; ++k)
    corners[static_cast<std::size_t>(k)] = light.clip({k & 1 ? b.hi[0] : b.lo[0], k & 2 ? b.hi[1] : b.lo[1], k & 4 ? b.hi[2] : b.lo[2]});
  // Bounds wholly outside one side plane of the light's frustum (a plane through the light) or
  // beyond its far plane: every light ray through the caster stays outside the frustum, so its
  // volume holds no lit receiver, even when the bounds reach behind the near plane.
  const auto all = [&](auto outside) { return std::all_of(corners.begin(), corners.end(), outside); };
  if (all([](const glm::dvec4& q) { return q.x > q.w; }) || all([](const glm::dvec4& q) { return q.x < -q.w; }) ||
      all([](const glm::dvec4& q) { return q.y > q.w; }) || all([](const glm::dvec4& q) { return q.y < -q.w; }) ||
      all([](const glm::dvec4& q) { return q.z > q.w; })) {
    r.decision = Decision::OutsideLight;
    return r;
  }
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY, d0 = INFINITY, d1 = -INFINITY;
  for (const glm::dvec4& q : corners) {
    if (q.w < light.near_m) {  // behind the near plane: never culled or clamped
      r.decision = Decision::CrossesNear;
      r.caster_near = 0.0f, r.caster_far = 1.0f;
      return r;
    }
    const double s = litmap;
    x0 = std::min(x0, (q.x / q.w * 0.5 + 0.5) * s), x1 = std::max(x1, (q.x / q.w * 0.5 + 0.5) * s);
    y0 = std::min(y0, (q.y / q.w * 0.5 + 0.5) * s), y1 = std::max(y1, (q.y / q.w * 0.5 + 0.5) * s);
    d0 = std::min(d0, q.z / q.w * 0.5 + 0.5), d1 = std::max(d1, q.z / q.w * 0.5 + 0.5);
  }
  r.caster_near = static_cast<float>(d0), r.caster_far = static_cast<float>(d1);
  // The lexels the bounds touch, grown by one lexel (llvmpipe has no conservative rasterization),
  // clipped to the litmap.
  const int lx = std::max(0, static_cast<int>(std::floor(x0)) - 1), hx = std::min(litmap - 1, static_cast<int>(std::floor(x1)) + 1);
  const int ly = std::max(0, static_cast<int>(std::floor(y0)) - 1), hy = std::min(litmap - 1, static_cast<int>(std::floor(y1)) + 1);
  if (x1 < 0.0 || y1 < 0.0 || x0 >= litmap || y0 >= litmap || lx > hx || ly > hy || d0 > 1.0) {
    r.decision = Decision::OutsideLight;
    return r;
  }
  r.x = lx, r.y = ly, r.w = hx - lx + 1, r.h = hy - ly + 1;
  return r;
}

double slab_far_end(const LightFrustum& light, double slab_max, const ClampMargin& margin) {
  return light.depth_of_distance(light.distance_of_depth(slab_max) * (1.0 + margin.rel) + margin.metres);
}

Planes slab_planes(float caster_near, float caster_far, const LightFrustum& light, double slab_min, double slab_max,
                   const ClampMargin& margin, ClampRule rule) {
  Planes p;
  // The slab of visible receivers, widened: [near, far] in light window depth.
  const double far = slab_far_end(light, slab_max, margin);
  if (far < std::max(slab_min, static_cast<double>(caster_near))) {
    p.culled = true;
    return p;
  }
  // The planes: clamped mode ends its volume there, the others cut its sides there.
  p.clamp_far = static_cast<float>(far);
  const double near_m = light.distance_of_depth(slab_min) * (1.0 - margin.rel) - margin.metres;
  const double near = near_m > light.near_m ? light.depth_of_distance(near_m) : 0.0;
  // The paper's rule sets the plane whenever it is in front of some of the caster (the volume is
  // split where the caster crosses it); the other only when every receiver is behind the whole
  // caster.
  if (rule == ClampRule::Edge ? near > caster_near : near >= caster_far) p.clamp_near = static_cast<float>(near);
  return p;
}

VolumeEnds volume_ends(float clamp_near, float clamp_far, bool clamped) {
  VolumeEnds e;
  e.clamped = clamped;
  e.far_plane = std::isfinite(clamp_far), e.far_depth = clamp_far;
  e.near_plane = clamp_near > 0.0f, e.near_depth = clamp_near;
  return e;
}

scene::DrawRecord volume_draw(std::uint32_t object) {
  scene::DrawRecord d;
  d.role = kShadowVolumeRole;
  d.object = static_cast<std::int32_t>(object);
  d.state.func = scene::DepthFunc::Less;
  d.state.write = false;
  d.state.test = true;
  d.state.cull = scene::CullFace::None;
  d.state.front_ccw = true;
  d.state.clip = scene::ClipControl::NegativeOneToOne;
  d.state.depth_clamp = true;
  scene::StencilState& s = d.stencil;
  s.test = true;
  for (scene::StencilFace* f : {&s.front, &s.back}) {
    f->func = scene::DepthFunc::Always;
    f->ref = 0;
    f->value_mask = 0xFFu;
    f->write_mask = 0xFFu;
  }
  s.front.depth_fail = scene::StencilOp::DecrWrap;
  s.back.depth_fail = scene::StencilOp::IncrWrap;
  return d;
}

std::array<float, 4> clip_position(const glm::mat4& m, const glm::vec4& p) noexcept {
  std::array<float, 4> out{};
  for (int r = 0; r < 4; ++r) {
    float v = m[0][r] * p.x;
    v = v + m[1][r] * p.y;
    v = v + m[2][r] * p.z;
    v = v + m[3][r] * p.w;
    out[static_cast<std::size_t>(r)] = v;
  }
  return out;
}

glm::mat4 observer_view_proj(const scene::FrameBegin& begin) {
  glm::mat4 view, proj;
  std::memcpy(&view[0][0], begin.view.data(), 64);
  std::memcpy(&proj[0][0], begin.proj.data(), 64);
  return proj * view;
}

LightFrustum light_of(const FrameCasters& c, std::uint64_t frame) {
  LightFrustum l;
  const auto& v = c.light;
  l.eye = {v[0], v[1], v[2]};
  l.target = {v[3], v[4], v[5]};
  l.fov_y_deg = v[6], l.near_m = v[7], l.far_m = v[8];
  if (!l.make())
    throw InputError(fmt::format("frame {}: the ShadowCasters record's light camera is degenerate (at ({}, {}, {}) looking at ({}, {}, {}), "
                                 "field of view {} degrees, near {} m, far {} m)",
                                 frame, v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8]));
  return l;
}

std::optional<CasterMeshes> read_caster_meshes(const scene::Frame& f) {
  const scene::TechniqueRecord* rec = nullptr;
  for (const scene::TechniqueRecord& r : f.technique_records)
    if (r.type == kCasterMeshesRecordType) rec = &r;
  if (!rec) return std::nullopt;
  const std::uint64_t frame = f.begin.frame;
  const char* label = "ShadowCasterMeshes (SHDG)";
  const auto& object = scene::record_field<std::uint32_t>(*rec, "object", label, frame);
  const auto& bounds = scene::record_field<float>(*rec, "bounds", label, frame);
  const auto& first = scene::record_field<std::uint32_t>(*rec, "first_triangle", label, frame);
  const auto& count = scene::record_field<std::uint32_t>(*rec, "triangle_count", label, frame);
  const auto& vertices = scene::record_field<float>(*rec, "vertices", label, frame);
  const auto& triangles = scene::record_field<std::uint32_t>(*rec, "triangles", label, frame);
  if (bounds.size() != 6 * object.size() || first.size() != object.size() || count.size() != object.size() || vertices.size() % 3 ||
      triangles.size() % 3)
    throw InputError(fmt::format("frame {}: the {} record's fields do not agree in length", frame, label));
  CasterMeshes m;
  for (std::size_t i = 0; i + 2 < vertices.size(); i += 3) m.vertices.emplace_back(vertices[i], vertices[i + 1], vertices[i + 2]);
  for (std::size_t c = 0; c < object.size(); ++c) {
    if (std::uint64_t{first[c]} + count[c] > triangles.size() / 3)
      throw InputError(fmt::format("frame {}: caster {} (object {})'s triangles run past the {} record's", frame, c, object[c], label));
    const std::span<const std::uint32_t> t(triangles.data() + 3 * std::size_t{first[c]}, 3 * std::size_t{count[c]});
    for (std::uint32_t v : t)
      if (v >= m.vertices.size())
        throw InputError(fmt::format("frame {}: caster {} (object {}) names vertex {} of {}", frame, c, object[c], v, m.vertices.size()));
    std::optional<CasterMesh> mesh = closed_mesh(object[c], t);
    if (!mesh)
      throw InputError(fmt::format("frame {}: caster {} (object {})'s mesh in the {} record is not closed: its shadow volume would leak",
                                   frame, c, object[c], label));
    m.meshes.push_back(std::move(*mesh));
    scene::Aabb b;
    for (std::size_t k = 0; k < 3; ++k) b.lo[k] = bounds[6 * c + k], b.hi[k] = bounds[6 * c + 3 + k];
    m.bounds.push_back(b);
  }
  return m;
}

}  // namespace nbsim::shadows

// Waypoints and their clear links; see waypoints.h.
#include "traces/capture/waypoints.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "model/common/error.h"

namespace nbsim::capture {

namespace {

constexpr std::uint32_t kLeafTriangles = 4;  // tunable

// Slab test of the ray origin + t dir, t in [0, max_t], against the box; inv = 1 / dir.
bool ray_box(glm::vec3 origin, glm::vec3 inv, float max_t, glm::vec3 lo, glm::vec3 hi) {
  float t0 = 0.0f, t1 = max_t;
  for (int a = 0; a < 3; ++a) {
    float tn = (lo[a] - origin[a]) * inv[a], tf = (hi[a] - origin[a]) * inv[a];
    if (tn > tf) std::swap(tn, tf);
    // A NaN (0 * inf: the ray in the slab's plane) must not cull: fmax/fmin drop it.
    t0 = std::fmax(t0, tn);
    t1 = std::fmin(t1, tf);
    if (t0 > t1) return false;
  }
  return true;
}

// Möller-Trumbore, both sides: the distance along dir to the triangle, or a negative value.
float ray_triangle(glm::vec3 origin, glm::vec3 dir, const std::array<glm::vec3, 3>& t) {
  const glm::vec3 e1 = t[1] - t[0], e2 = t[2] - t[0], p = glm::cross(dir, e2);
  const float det = glm::dot(e1, p);
  if (std::fabs(det) < 1e-12f) return -1.0f;
  const float inv = 1.0f / det;
  const glm::vec3 s = origin - t[0];
  const float u = glm::dot(s, p) * inv;
  if (u < 0.0f || u > 1.0f) return -1.0f;
  const glm::vec3 q = glm::cross(s, e1);
  const float v = glm::dot(dir, q) * inv;
  if (v < 0.0f || u + v > 1.0f) return -1.0f;
  return glm::dot(e2, q) * inv;
}

}  // namespace

TriangleCaster::TriangleCaster(const std::vector<glm::vec3>& vertices, const std::vector<std::uint32_t>& indices) {
  NBSIM_CHECK(indices.size() % 3 == 0, "triangle indices not a multiple of 3");
  tris_.reserve(indices.size() / 3);
  for (std::size_t k = 0; k < indices.size(); k += 3)
    tris_.push_back({vertices.at(indices[k]), vertices.at(indices[k + 1]), vertices.at(indices[k + 2])});
  if (tris_.empty()) return;
  // Median split on the longest axis of the centroids' box, depth first.
  std::vector<glm::vec3> centre(tris_.size());
  for (std::size_t k = 0; k < tris_.size(); ++k) centre[k] = (tris_[k][0] + tris_[k][1] + tris_[k][2]) / 3.0f;
  std::vector<std::uint32_t> order(tris_.size());
  std::iota(order.begin(), order.end(), 0u);
  nodes_.reserve(2 * tris_.size() / kLeafTriangles + 1);
  struct Job {
    std::uint32_t node, first, count;
  };
  std::vector<Job> jobs{{0, 0, static_cast<std::uint32_t>(order.size())}};
  nodes_.emplace_back();
  while (!jobs.empty()) {
    const Job j = jobs.back();
    jobs.pop_back();
    glm::vec3 lo(INFINITY), hi(-INFINITY), clo(INFINITY), chi(-INFINITY);
    for (std::uint32_t k = j.first; k < j.first + j.count; ++k) {
      for (const glm::vec3& v : tris_[order[k]]) lo = glm::min(lo, v), hi = glm::max(hi, v);
      clo = glm::min(clo, centre[order[k]]), chi = glm::max(chi, centre[order[k]]);
    }
    nodes_[j.node].lo = lo;
    nodes_[j.node].hi = hi;
    if (j.count <= kLeafTriangles) {
      nodes_[j.node].first = j.first;
      nodes_[j.node].count = j.count;
      continue;
    }
    const glm::vec3 ext = chi - clo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
    const std::uint32_t half = j.count / 2;
    std::nth_element(order.begin() + j.first, order.begin() + j.first + half, order.begin() + j.first + j.count,
                     [&](std::uint32_t a, std::uint32_t b) { return centre[a][axis] < centre[b][axis]; });
    const auto child = static_cast<std::uint32_t>(nodes_.size());
    nodes_.emplace_back();
    nodes_.emplace_back();
    nodes_[j.node].first = child;
    nodes_[j.node].count = 0;
    jobs.push_back({child, j.first, half});
    jobs.push_back({child + 1, j.first + half, j.count - half});
  }
  std::vector<std::array<glm::vec3, 3>> sorted(tris_.size());
  for (std::size_t k = 0; k < order.size(); ++k) sorted[k] = tris_[order[k]];
  tris_ = std::move(sorted);
}

std::optional<float> TriangleCaster::first_hit(glm::vec3 origin, glm::vec3 dir, float max_m) const {
  if (nodes_.empty()) return std::nullopt;
  const glm::vec3 inv = 1.0f / dir;
  float best = max_m;
  bool hit = false;
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (!ray_box(origin, inv, best, n.lo, n.hi)) continue;
    if (n.count > 0) {
      for (std::uint32_t k = n.first; k < n.first + n.count; ++k) {
        const float t = ray_triangle(origin, dir, tris_[k]);
        if (t >= 0.0f && t <= best) best = t, hit = true;
      }
    } else {
      NBSIM_CHECK(top + 2 <= 128, "triangle BVH deeper than its traversal stack");
      stack[top++] = n.first;
      stack[top++] = n.first + 1;
    }
  }
  return hit ? std::optional<float>(best) : std::nullopt;
}

bool TriangleCaster::segment_clear(glm::vec3 a, glm::vec3 b) const {
  const float len = glm::length(b - a);
  if (len <= 0.0f) return true;
  return !first_hit(a, (b - a) / len, len).has_value();
}

WaypointGraph link_waypoints(const TriangleCaster& caster, const std::vector<glm::vec3>& spots, const WaypointParams& p) {
  WaypointGraph g;
  const glm::vec3 up(0.0f, 1.0f, 0.0f);
  for (const glm::vec3& s : spots) {
    glm::vec3 eye = s;
    if (const auto down = caster.first_hit(s, -up, p.floor_search_m)) {
      const glm::vec3 floor = s - up * *down;
      const float room = caster.first_hit(floor + up * 0.01f, up, p.eye_height_m + p.head_room_m).value_or(INFINITY);
      eye = floor + up * std::min(p.eye_height_m, std::max(room - p.head_room_m, 0.5f * room));
    }
    const bool near = std::any_of(g.points.begin(), g.points.end(), [&](glm::vec3 q) { return glm::length(q - eye) < p.merge_m; });
    if (!near) g.points.push_back(eye);
  }
  for (std::uint32_t i = 0; i < g.points.size(); ++i)
    for (std::uint32_t j = i + 1; j < g.points.size(); ++j) {
      const glm::vec3 a = g.points[i], b = g.points[j], d = b - a;
      if (!caster.segment_clear(a, b)) continue;
      glm::vec3 side = glm::cross(d, up);
      side = glm::length(side) > 1e-6f ? glm::normalize(side) : glm::vec3(1.0f, 0.0f, 0.0f);
      bool clear = true;
      for (const glm::vec3 off : {up, -up, side, -side}) {
        if (!caster.segment_clear(a + off * p.clearance_m, b + off * p.clearance_m)) {
          clear = false;
          break;
        }
      }
      if (clear) g.links.push_back({i, j});
    }
  return g;
}

}  // namespace nbsim::capture

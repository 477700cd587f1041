// ShadowVolumeTest: the shadow-volume geometry of traces/capture/shadows/volumes.h on the CPU, no
// GL. Every volume, clamped or not, cut at a near plane or not, is a closed surface in the floats
// GL receives (each directed edge has its reverse: the split points of an edge crossing the near
// plane are the same on both of its triangles), and a clamped volume starts where the paper's rule
// says: on each light ray through the caster, at the caster or at the min plane, whichever is
// farther from the light.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <tuple>
#include <vector>

#include "traces/capture/mesh_builder.h"
#include "traces/capture/shadows/volumes.h"

namespace nbsim::capture {
namespace {

// A tall box, and a tilted octahedron, so that the near planes below cross faces and edges at
// angles (the box's faces are square to the axes, the octahedron's are not).
CaptureScene two_casters() {
  CaptureScene s;
  MeshBuilder b(s);
  b.begin("box");
  b.box({0.0f, 0.0f, 0.0f}, {4.0f, 30.0f, 6.0f});
  b.end();
  b.begin("bird");
  const glm::vec3 c{12.0f, 10.0f, 3.0f};
  const std::array<glm::vec3, 6> corner = {glm::vec3(5.0f, 1.5f, 0.5f), glm::vec3(-5.0f, -1.5f, -0.5f), glm::vec3(-1.0f, 4.0f, 0.7f),
                                           glm::vec3(1.0f, -4.0f, -0.7f), glm::vec3(0.3f, -0.9f, 3.0f),  glm::vec3(-0.3f, 0.9f, -3.0f)};
  std::array<std::uint32_t, 6> v{};
  for (std::size_t k = 0; k < 6; ++k) v[k] = b.vertex(c + corner[k]);
  for (std::uint32_t sx = 0; sx < 2; ++sx)
    for (std::uint32_t sy = 0; sy < 2; ++sy)
      for (std::uint32_t sz = 0; sz < 2; ++sz) {
        const std::uint32_t a = v[sx], bb = v[2 + sy], cc = v[4 + sz];
        if ((sx + sy + sz) % 2 == 0) b.triangle(a, bb, cc);
        else b.triangle(a, cc, bb);
      }
  b.end();
  b.finish();
  return s;
}

LightCamera light_above() {
  LightCamera l;
  l.eye = {-20.0, 80.0, 10.0};
  l.target = {8.0, 0.0, 3.0};
  l.fov_y_deg = 60.0;
  l.near_m = 1.0;
  l.far_m = 200.0;
  EXPECT_TRUE(l.make());
  return l;
}

using Key = std::array<float, 4>;
Key key(const glm::vec4& p) { return {p.x, p.y, p.z, p.w}; }

// Directed edges without their reverse, in the floats as emitted.
std::size_t open_edges(const std::vector<glm::vec4>& tris) {
  std::map<std::pair<Key, Key>, int> edges;
  for (std::size_t t = 0; t + 2 < tris.size(); t += 3)
    for (int k = 0; k < 3; ++k) {
      const Key a = key(tris[t + static_cast<std::size_t>(k)]), b = key(tris[t + static_cast<std::size_t>((k + 1) % 3)]);
      auto rev = edges.find({b, a});
      if (rev != edges.end() && rev->second > 0) {
        if (--rev->second == 0) edges.erase(rev);
      } else {
        ++edges[{a, b}];
      }
    }
  std::size_t open = 0;
  for (const auto& [e, n] : edges) open += static_cast<std::size_t>(n);
  return open;
}

// The nearest hit of the ray eye + t dir (t > 0) on the finite triangles, or +inf.
double first_hit(const std::vector<glm::vec4>& tris, const glm::dvec3& eye, const glm::dvec3& dir) {
  double best = INFINITY;
  for (std::size_t t = 0; t + 2 < tris.size(); t += 3) {
    if (tris[t].w == 0.0f || tris[t + 1].w == 0.0f || tris[t + 2].w == 0.0f) continue;
    const glm::dvec3 a(tris[t]), b(tris[t + 1]), c(tris[t + 2]);
    const glm::dvec3 e1 = b - a, e2 = c - a, p = glm::cross(dir, e2);
    const double det = glm::dot(e1, p);
    if (std::abs(det) < 1e-12) continue;
    const glm::dvec3 s = eye - a;
    const double u = glm::dot(s, p) / det;
    const glm::dvec3 q = glm::cross(s, e1);
    const double v = glm::dot(dir, q) / det, h = glm::dot(e2, q) / det;
    if (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && h > 0.0) best = std::min(best, h);
  }
  return best;
}

TEST(ShadowVolumeTest, ClosedInEveryCutAndStartingAtTheCasterOrTheMinPlane) {
  const CaptureScene scene = two_casters();
  const std::vector<CasterMesh> casters = find_casters(scene);
  ASSERT_EQ(casters.size(), 2u);
  const LightCamera light = light_above();
  std::mt19937 rng(5);
  for (const CasterMesh& c : casters) {
    // The caster's light depth range, and near planes in front of it, across it and behind it.
    double lo = 1.0, hi = 0.0;
    for (const auto& t : c.triangles)
      for (std::uint32_t i : t) lo = std::min(lo, light.window_depth(glm::dvec3(scene.vertices[i]))), hi = std::max(hi, light.window_depth(glm::dvec3(scene.vertices[i])));
    const double far = light.depth_of_distance(light.distance_of_depth(hi) + 15.0);
    for (const double share : {-0.2, 0.15, 0.5, 0.85, 1.2}) {
      const double near = light.depth_of_distance(light.distance_of_depth(lo) +
                                                  share * (light.distance_of_depth(hi) - light.distance_of_depth(lo)));
      for (const bool clamped : {false, true}) {
        SCOPED_TRACE(::testing::Message() << "caster " << c.object << ", plane at share " << share << (clamped ? ", clamped" : ", cut"));
        VolumeEnds ends;
        ends.clamped = clamped, ends.near_plane = true, ends.far_plane = true, ends.near_depth = near, ends.far_depth = far;
        std::vector<glm::vec4> tris;
        append_volume(scene, c, light, ends, tris);
        ASSERT_FALSE(tris.empty());
        EXPECT_EQ(open_edges(tris), 0u) << "the volume is closed in the floats GL gets";
        if (!clamped) continue;
        // Light rays through the caster: the volume begins at max(caster, plane) along each.
        const double plane_m = light.distance_of_depth(near);
        std::vector<glm::vec4> caster_tris;  // the caster itself, for where a ray enters it
        for (const auto& ct : c.triangles)
          for (std::uint32_t i : ct) caster_tris.emplace_back(scene.vertices[i], 1.0f);
        int rays = 0;
        for (int k = 0; k < 400; ++k) {
          const auto& t = c.triangles[std::uniform_int_distribution<std::size_t>(0, c.triangles.size() - 1)(rng)];
          double u = std::uniform_real_distribution<double>(0.05, 0.9)(rng), v = std::uniform_real_distribution<double>(0.05, 0.9)(rng);
          if (u + v > 0.95) u = 0.95 - u * 0.5, v = 0.95 - v * 0.5 - u;
          if (v <= 0.0) continue;
          const glm::dvec3 p = glm::dvec3(scene.vertices[t[0]]) * (1.0 - u - v) + glm::dvec3(scene.vertices[t[1]]) * u +
                               glm::dvec3(scene.vertices[t[2]]) * v;
          const glm::dvec3 dir = glm::normalize(p - light.eye);
          // Where the ray enters the caster: the nearest hit on its triangles.
          const double enter = first_hit(caster_tris, light.eye, dir);
          const double axis = glm::dot(dir, glm::normalize(light.target - light.eye));  // distance along the view axis per metre
          const double expected = std::max(enter, plane_m / axis);
          const double got = first_hit(tris, light.eye, dir);
          EXPECT_NEAR(got, expected, 1e-3 * expected) << "ray " << k << ": enters the caster at " << enter << " m, the plane at "
                                                      << plane_m / axis << " m";
          ++rays;
        }
        EXPECT_GT(rays, 200);
      }
    }
  }
}

}  // namespace
}  // namespace nbsim::capture

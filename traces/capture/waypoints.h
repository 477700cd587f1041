// Waypoints an observer walks between inside an enclosed scene (a game level): points of interest
// lifted to eye height above the floor under them, and the straight segments between two of them
// that clear the scene's triangles, which the camera path `tour` walks (camera.h). Plain CPU
// geometry on a BVH over the triangles, so that a few hundred waypoints link in milliseconds.
#pragma once

#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

namespace nbsim::capture {

// Rays and segments against a triangle soup (both sides of every triangle hit), through a BVH of
// at most 4 triangles a leaf. Keeps a copy of the triangles.
class TriangleCaster {
 public:
  TriangleCaster(const std::vector<glm::vec3>& vertices, const std::vector<std::uint32_t>& indices);

  // Distance from `origin` along `dir` (unit length) to the nearest triangle within max_m.
  std::optional<float> first_hit(glm::vec3 origin, glm::vec3 dir, float max_m) const;
  // True when the segment [a, b] crosses no triangle.
  bool segment_clear(glm::vec3 a, glm::vec3 b) const;

 private:
  struct Node {
    glm::vec3 lo{0.0f}, hi{0.0f};
    std::uint32_t first = 0, count = 0;  // leaf: triangles [first, first + count); inner: count 0, children first, first + 1
  };
  std::vector<std::array<glm::vec3, 3>> tris_;
  std::vector<Node> nodes_;
};

struct WaypointParams {
  float eye_height_m = 1.7f;    // above the floor (tunable: a standing adult's eye)
  float head_room_m = 0.3f;     // kept under a ceiling lower than the eye height plus this (tunable)
  float floor_search_m = 8.0f;  // how far below a point its floor is looked for (tunable)
  float clearance_m = 0.25f;    // a link keeps this far from triangles, up, down and sideways (tunable; below the 0.5 m near plane)
  float merge_m = 0.5f;         // waypoints closer than this are one (tunable)
};

struct WaypointGraph {
  std::vector<glm::vec3> points;                         // at eye height
  std::vector<std::array<std::uint32_t, 2>> links;       // clear segments, first < second
};

// The waypoints of `spots` (points of interest, e.g. spawn points): each dropped onto the floor
// found straight below it within floor_search_m (kept where it is when there is none) and raised to
// eye height, lower under a low ceiling; then joined two by two where the segment between them,
// and four copies of it shifted by clearance_m up, down and sideways, cross no triangle.
WaypointGraph link_waypoints(const TriangleCaster& caster, const std::vector<glm::vec3>& spots, const WaypointParams& params = {});

}  // namespace nbsim::capture

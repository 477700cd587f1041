// Cameras of the capture: a pose per frame, the projection of the depth convention, and the
// camera paths over a scene's site: a street-level walkthrough that follows the street grid and
// turns at crossings, a flyover that circles the site looking down, an observer on foot, and a
// tour along the links between the site's waypoints (an enclosed scene such as a game level). The
// paths are chosen by name from the table in paths.cpp; this file computes them.
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <functional>
#include <string_view>
#include <vector>

namespace nbsim::capture {

// Where a camera path may go: the scene's ground square [0, extent_m] x [0, extent_m], at the
// height `ground` gives (y = 0 when it is empty) and, when the scene has streets, the grid of
// street crossings at multiples of street_pitch_m (crossings 0..blocks_per_side on x and on z).
// An enclosed site (a level's interior: walls everywhere, so a straight line across it or the
// ground's height mean nothing) has instead waypoints at eye height and the links between two of
// them that a camera can walk along without crossing a triangle.
struct PathSite {
  double extent_m = 0.0;
  double street_pitch_m = 0.0;  // distance between street centre lines; 0 when there are no streets
  int blocks_per_side = 0;
  std::function<float(float x, float z)> ground;  // the ground's height at (x, z), m
  bool enclosed = false;
  std::vector<glm::vec3> waypoints;                          // world space, at eye height
  std::vector<std::array<std::uint32_t, 2>> waypoint_links;  // indices into waypoints, clear segments
  bool has_streets() const noexcept { return street_pitch_m > 0.0 && blocks_per_side > 0; }
  bool has_waypoint_links() const noexcept { return !waypoint_links.empty(); }
  float ground_at(float x, float z) const { return ground ? ground(x, z) : 0.0f; }
};

struct CameraPose {
  glm::vec3 eye{0.0f};
  glm::vec3 target{0.0f, 0.0f, -1.0f};
};

struct Projection {
  double fov_y_deg = 60.0;
  double near_m = 0.5;
  double far_m = 4000.0;
  bool reversed_z = false;  // depth 1 at near, 0 at far (with ZERO_TO_ONE clip control, GREATER)
};

// `frames` poses. The walk moves 1.2 m a frame at eye height (a slow drive at 30 frames a second,
// so that 60 frames pass a few crossings), a random walk on the crossings from the site's centre
// (the site must have streets); the flyover circles the site once, looking at its centre.
std::vector<CameraPose> walk_path(const PathSite& site, int frames, std::uint32_t seed);
std::vector<CameraPose> fly_path(const PathSite& site, int frames);
// An observer on foot: eye height (1.7 m) above the ground, 1.2 m a frame along a straight line
// through the site's centre (its heading from the seed), looking ahead level, so that what flies
// or stands well above the eye is mostly out of view while the ground around is in it (the set-up
// the N-buffer paper's terrain experiment assumes: birds above the observer, the ground in view).
std::vector<CameraPose> ground_path(const PathSite& site, int frames, std::uint32_t seed);
// A tour of an enclosed site: a random walk on the waypoint links (the site must have some), 1.2 m
// a frame, from a waypoint of the largest connected group chosen by the seed; at each waypoint the
// next link is drawn among the others than the one it came by (back only at a dead end); the view
// looks ahead along the link, its heading and pitch turning a quarter of the way each frame.
std::vector<CameraPose> tour_path(const PathSite& site, int frames, std::uint32_t seed);

glm::mat4 view_matrix(const CameraPose& pose);
// GL projection for the depth convention: [-1, 1] clip z (LESS) or reversed Z in [0, 1] (GREATER).
glm::mat4 projection_matrix(const Projection& p, double aspect);

}  // namespace nbsim::capture

// Camera paths through the city: a street-level walkthrough that follows the street grid and turns
// at crossings, and a flyover that circles the city looking down. One pose per frame.
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <cstdint>
#include <string_view>
#include <vector>

#include "traces/capture/city.h"

namespace nbsim::capture {

enum class PathKind : std::uint8_t { Walk = 0, Fly = 1 };

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
// so that 60 frames pass a few crossings); the flyover circles the city once over the path.
std::vector<CameraPose> make_path(const City& city, PathKind kind, int frames, std::uint32_t seed);

glm::mat4 view_matrix(const CameraPose& pose);
// GL projection for the depth convention: [-1, 1] clip z (LESS) or reversed Z in [0, 1] (GREATER).
glm::mat4 projection_matrix(const Projection& p, double aspect);

}  // namespace nbsim::capture

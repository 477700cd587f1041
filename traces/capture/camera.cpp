// Camera paths and matrices; see camera.h.
#include "traces/capture/camera.h"

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/vec2.hpp>

#include <algorithm>
#include <cmath>
#include <random>

#include "model/common/error.h"

namespace nbsim::capture {

std::vector<CameraPose> fly_path(const PathSite& site, int frames) {
  std::vector<CameraPose> poses;
  poses.reserve(static_cast<std::size_t>(frames));
  const float c = 0.5f * static_cast<float>(site.extent_m), r = 0.55f * static_cast<float>(site.extent_m);
  for (int f = 0; f < frames; ++f) {
    const float a = glm::two_pi<float>() * static_cast<float>(f) / static_cast<float>(std::max(frames, 1));
    const glm::vec3 eye{c + r * std::cos(a), 120.0f + 0.05f * r, c + r * std::sin(a)};
    poses.push_back({eye, {c, 0.0f, c}});
  }
  return poses;
}

std::vector<CameraPose> walk_path(const PathSite& site, int frames, std::uint32_t seed) {
  NBSIM_CHECK(site.has_streets(), "walk_path() on a site without streets");
  std::vector<CameraPose> poses;
  poses.reserve(static_cast<std::size_t>(frames));
  const float pitch = static_cast<float>(site.street_pitch_m);
  const int n = site.blocks_per_side;
  // Walk: a random walk on the street-crossing grid at eye height, 1.2 m a frame, turning at
  // crossings; the view direction eases into each turn so frames stay coherent.
  std::mt19937 rng(seed ^ 0x5eedu);
  int gx = n / 2, gz = n / 2, dir = 0;  // crossing and heading (0 +x, 1 +z, 2 -x, 3 -z)
  static constexpr int dx[4] = {1, 0, -1, 0}, dz[4] = {0, 1, 0, -1};
  auto crossing = [&](int x, int z) { return glm::vec3(static_cast<float>(x) * pitch, 1.7f, static_cast<float>(z) * pitch); };
  glm::vec3 pos = crossing(gx, gz);
  glm::vec3 look = glm::vec3(dx[dir], 0, dz[dir]);
  const float step = 1.2f;
  for (int f = 0; f < frames; ++f) {
    const glm::vec3 goal = crossing(gx + dx[dir], gz + dz[dir]);
    const glm::vec3 to = goal - pos;
    const float dist = glm::length(to);
    if (dist <= step) {  // reached a crossing: choose the next street (no U-turn, stay in the city)
      pos = goal;
      gx += dx[dir], gz += dz[dir];
      for (int tries = 0; tries < 16; ++tries) {
        const int turn = std::uniform_int_distribution<int>(-1, 1)(rng);
        const int d = (dir + 4 + turn) % 4;
        const int nx = gx + dx[d], nz = gz + dz[d];
        if (nx >= 0 && nx <= n && nz >= 0 && nz <= n) { dir = d; break; }
        if (tries == 15) dir = (dir + 2) % 4;
      }
    } else {
      pos += to / dist * step;
    }
    const glm::vec3 want(dx[dir], 0, dz[dir]);
    look = glm::normalize(glm::mix(look, want, 0.2f) + glm::vec3(1e-6f));
    poses.push_back({pos, pos + glm::vec3(look.x, -0.02f, look.z)});
  }
  return poses;
}

std::vector<CameraPose> ground_path(const PathSite& site, int frames, std::uint32_t seed) {
  std::vector<CameraPose> poses;
  poses.reserve(static_cast<std::size_t>(frames));
  const float ext = static_cast<float>(site.extent_m), c = 0.5f * ext, step = 1.2f, eye_height = 1.7f;
  std::mt19937 rng(seed ^ 0x9a0d11u);
  const float heading = std::uniform_real_distribution<float>(0.0f, glm::two_pi<float>())(rng);
  const glm::vec2 dir(std::cos(heading), std::sin(heading));
  // Centred on the site's centre, the walk's middle frame passes it; the walk stays on the site.
  const float half = std::min(0.5f * step * static_cast<float>(std::max(frames - 1, 0)), 0.45f * ext);
  const float pace = frames > 1 ? 2.0f * half / static_cast<float>(frames - 1) : 0.0f;
  for (int f = 0; f < frames; ++f) {
    const glm::vec2 p = glm::vec2(c) + dir * (-half + pace * static_cast<float>(f));
    const glm::vec3 eye(p.x, site.ground_at(p.x, p.y) + eye_height, p.y);
    poses.push_back({eye, eye + glm::vec3(dir.x, 0.0f, dir.y)});
  }
  return poses;
}

glm::mat4 view_matrix(const CameraPose& pose) { return glm::lookAt(pose.eye, pose.target, glm::vec3(0, 1, 0)); }

glm::mat4 projection_matrix(const Projection& p, double aspect) {
  const float fov = glm::radians(static_cast<float>(p.fov_y_deg)), a = static_cast<float>(aspect);
  const float n = static_cast<float>(p.near_m), f = static_cast<float>(p.far_m);
  if (!p.reversed_z) return glm::perspectiveRH_NO(fov, a, n, f);
  // Reversed Z: a [0, 1] projection with near and far swapped maps near to 1 and far to 0.
  return glm::perspectiveRH_ZO(fov, a, f, n);
}

}  // namespace nbsim::capture

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

std::vector<CameraPose> tour_path(const PathSite& site, int frames, std::uint32_t seed) {
  NBSIM_CHECK(site.has_waypoint_links(), "tour_path() on a site without waypoint links");
  const std::size_t n = site.waypoints.size();
  std::vector<std::vector<std::uint32_t>> next(n);
  for (const auto& l : site.waypoint_links) {
    NBSIM_CHECK(l[0] < n && l[1] < n, "a waypoint link to no waypoint");
    next[l[0]].push_back(l[1]);
    next[l[1]].push_back(l[0]);
  }
  // The connected groups (by flood fill); the walk starts in the largest, at a seeded waypoint.
  std::vector<std::uint32_t> group(n, UINT32_MAX), size;
  for (std::uint32_t s = 0; s < n; ++s) {
    if (group[s] != UINT32_MAX || next[s].empty()) continue;
    const auto id = static_cast<std::uint32_t>(size.size());
    size.push_back(0);
    std::vector<std::uint32_t> todo{s};
    group[s] = id;
    while (!todo.empty()) {
      const std::uint32_t v = todo.back();
      todo.pop_back();
      ++size[id];
      for (std::uint32_t w : next[v])
        if (group[w] == UINT32_MAX) group[w] = id, todo.push_back(w);
    }
  }
  const auto largest = static_cast<std::uint32_t>(std::max_element(size.begin(), size.end()) - size.begin());
  std::vector<std::uint32_t> members;
  for (std::uint32_t v = 0; v < n; ++v)
    if (group[v] == largest) members.push_back(v);
  std::mt19937 rng(seed ^ 0x70a4u);
  auto pick = [&](std::size_t count) { return std::uniform_int_distribution<std::size_t>(0, count - 1)(rng); };
  std::uint32_t from = members[pick(members.size())], to = next[from][pick(next[from].size())];
  glm::vec3 pos = site.waypoints[from];
  // The view as heading and pitch, each turned a quarter of the way to the link ahead every frame,
  // so that a U-turn at a dead end turns round smoothly too. Pitched at most about 30 degrees; a
  // steep or vertical link keeps the heading.
  auto heading_of = [](glm::vec3 d, float current) { return glm::length(glm::vec2(d.x, d.z)) > 0.5f ? std::atan2(d.z, d.x) : current; };
  auto pitch_of = [](glm::vec3 d) { return std::asin(std::clamp(d.y, -0.5f, 0.5f)); };
  const glm::vec3 first = glm::normalize(site.waypoints[to] - pos);
  float heading = heading_of(first, 0.0f), pitch = pitch_of(first);
  const float step = 1.2f, ease = 0.25f;
  std::vector<CameraPose> poses;
  poses.reserve(static_cast<std::size_t>(frames));
  for (int f = 0; f < frames; ++f) {
    const glm::vec3 goal = site.waypoints[to], d = goal - pos;
    const float dist = glm::length(d);
    if (dist <= step) {  // reached a waypoint: the next link, not back unless it is a dead end
      pos = goal;
      std::vector<std::uint32_t> ways;
      for (std::uint32_t w : next[to])
        if (w != from) ways.push_back(w);
      if (ways.empty()) ways.push_back(from);
      from = to;
      to = ways[pick(ways.size())];
    } else {
      pos += d / dist * step;
    }
    const glm::vec3 want = glm::normalize(site.waypoints[to] - pos);
    const float turn = std::remainder(heading_of(want, heading) - heading, glm::two_pi<float>());
    heading += ease * turn;
    pitch += ease * (pitch_of(want) - pitch);
    const glm::vec3 look(std::cos(pitch) * std::cos(heading), std::sin(pitch), std::cos(pitch) * std::sin(heading));
    poses.push_back({pos, pos + look});
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

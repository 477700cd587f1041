// The particle systems of the particles technique (N-buffer paper, 4.3): emitters on the scene's
// ground (smoke, fire, sparks, birds) placed behind and between the buildings around the site's
// centre, where the camera paths start, and their particles' world positions at any frame, a pure
// function of the seed, the emitter and the frame (no state carried between frames, so a frame is
// the same whatever frames came before). World space is y up, metres; 30 frames a second.
#pragma once

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "traces/capture/camera.h"

namespace nbsim::capture {

enum class EmitterKind : std::uint8_t { Smoke = 0, Fire = 1, Sparks = 2, Birds = 3 };
std::string_view to_string(EmitterKind kind) noexcept;

struct Emitter {
  EmitterKind kind = EmitterKind::Smoke;
  glm::vec3 position{0.0f};  // on the ground, y = 0
  std::uint32_t first = 0, count = 0;  // its particles: [first, first + count) of the frame's
};

// Where emitters may stand: the site's ground square [0, extent_m] x [0, extent_m].
bool inside_site(const PathSite& site, double x_m, double z_m) noexcept;

// `emitters` emitters around the site's centre crossing (half of them in a 70-degree cone along +x,
// the walk's first street, the others all around; 15 to 250 m away, clamped into the site), kinds
// in turn smoke, fire, sparks, birds, `particles` shared out in turn. Deterministic for a seed.
std::vector<Emitter> place_emitters(const PathSite& site, int emitters, std::uint32_t particles, std::uint32_t seed);

// Emitters at the given ground positions (x, z metres), kinds in turn. Throws InputError naming
// the first emitter outside the site.
std::vector<Emitter> emitters_at(const PathSite& site, const std::vector<std::pair<double, double>>& positions,
                                 std::uint32_t particles);

// Every particle's world position at `frame` (xyz, w = 1), emitters in order.
std::vector<glm::vec4> particle_positions(const std::vector<Emitter>& emitters, std::uint32_t frame, std::uint32_t seed);

}  // namespace nbsim::capture

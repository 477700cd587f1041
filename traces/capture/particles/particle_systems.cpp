// Particle systems; see particle_systems.h.
#include "traces/capture/particles/particle_systems.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "model/common/error.h"

namespace nbsim::capture {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kFrameSeconds = 1.0 / 30.0;

// A uniform number in [0, 1) from (seed, emitter, particle, channel): a 64-bit mix (splitmix64),
// so each particle's constants need no stored state.
double unit(std::uint32_t seed, std::uint32_t emitter, std::uint32_t particle, std::uint32_t channel) {
  std::uint64_t z = (static_cast<std::uint64_t>(seed) << 32) ^ (static_cast<std::uint64_t>(emitter) << 40) ^
                    (static_cast<std::uint64_t>(particle) << 4) ^ channel;
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-53;
}

void share_out(std::vector<Emitter>& emitters, std::uint32_t particles) {
  const auto n = static_cast<std::uint32_t>(emitters.size());
  std::uint32_t first = 0;
  for (std::uint32_t e = 0; e < n; ++e) {
    emitters[e].first = first;
    emitters[e].count = particles / n + (e < particles % n ? 1u : 0u);
    first += emitters[e].count;
  }
}

}  // namespace

std::string_view to_string(EmitterKind kind) noexcept {
  static constexpr std::array<std::string_view, 4> names = {"smoke", "fire", "sparks", "birds"};
  const auto i = static_cast<std::size_t>(kind);
  return i < names.size() ? names[i] : "?";
}

bool inside_site(const PathSite& site, double x_m, double z_m) noexcept {
  return x_m >= 0.0 && z_m >= 0.0 && x_m <= site.extent_m && z_m <= site.extent_m;
}

std::vector<Emitter> place_emitters(const PathSite& site, int emitters, std::uint32_t particles, std::uint32_t seed) {
  NBSIM_CHECK(emitters >= 1, "place_emitters() needs at least one emitter");
  std::vector<Emitter> out(static_cast<std::size_t>(emitters));
  const double pitch = site.has_streets() ? site.street_pitch_m : site.extent_m / 8.0;
  const double centre = site.has_streets() ? (site.blocks_per_side / 2) * site.street_pitch_m : site.extent_m / 2.0;
  std::mt19937 rng(seed ^ 0xE5175u);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (std::size_t e = 0; e < out.size(); ++e) {
    const double angle = e % 2 == 0 ? (u(rng) - 0.5) * 70.0 * kPi / 180.0 : u(rng) * 2.0 * kPi;
    const double dist = 15.0 + u(rng) * std::min(235.0, 3.5 * pitch);
    const double x = std::clamp(centre + dist * std::cos(angle), 0.0, site.extent_m);
    const double z = std::clamp(centre + dist * std::sin(angle), 0.0, site.extent_m);
    out[e].kind = static_cast<EmitterKind>(e % 4);
    out[e].position = glm::vec3(static_cast<float>(x), 0.0f, static_cast<float>(z));
    NBSIM_CHECK(inside_site(site, x, z), "an emitter placed outside the site");
  }
  share_out(out, particles);
  return out;
}

std::vector<Emitter> emitters_at(const PathSite& site, const std::vector<std::pair<double, double>>& positions,
                                 std::uint32_t particles) {
  std::vector<Emitter> out;
  for (std::size_t e = 0; e < positions.size(); ++e) {
    const auto [x, z] = positions[e];
    if (!inside_site(site, x, z))
      throw InputError(fmt::format("--emitters: emitter {} at x {} m, z {} m is outside the scene (its ground is x and z in "
                                   "[0, {}] m)",
                                   e + 1, x, z, site.extent_m));
    Emitter em;
    em.kind = static_cast<EmitterKind>(e % 4);
    em.position = glm::vec3(static_cast<float>(x), 0.0f, static_cast<float>(z));
    out.push_back(em);
  }
  share_out(out, particles);
  return out;
}

std::vector<glm::vec4> particle_positions(const std::vector<Emitter>& emitters, std::uint32_t frame, std::uint32_t seed) {
  std::vector<glm::vec4> out;
  const double now = frame * kFrameSeconds;
  for (std::size_t e = 0; e < emitters.size(); ++e) {
    const Emitter& em = emitters[e];
    const auto ei = static_cast<std::uint32_t>(e);
    const glm::dvec3 base(em.position);
    for (std::uint32_t i = 0; i < em.count; ++i) {
      const double r0 = unit(seed, ei, i, 0), r1 = unit(seed, ei, i, 1), r2 = unit(seed, ei, i, 2), r3 = unit(seed, ei, i, 3);
      glm::dvec3 p = base;
      switch (em.kind) {
        case EmitterKind::Smoke: {  // rises 2 to 50 m in 8 s, widening and drifting with the wind
          const double life = 8.0, age = std::fmod(now + r0 * life, life), u = age / life;
          const double radius = (0.5 + 6.0 * u) * r1, a = r2 * 2.0 * kPi + age * 0.7;
          p += glm::dvec3(radius * std::cos(a) + 4.0 * u * u, 2.0 + 48.0 * u * (0.7 + 0.3 * r3), radius * std::sin(a));
          break;
        }
        case EmitterKind::Fire: {  // flickers 0 to 8 m in 1.5 s over a 5 m wide fire
          const double life = 1.5, age = std::fmod(now + r0 * life, life), u = age / life;
          p += glm::dvec3((r1 - 0.5) * 5.0 * (1.0 - 0.6 * u), 0.3 + 8.0 * u * r3, (r2 - 0.5) * 5.0 * (1.0 - 0.6 * u));
          break;
        }
        case EmitterKind::Sparks: {  // a fountain: ballistic, 2.5 s, up to about 20 m
          const double life = 2.5, age = std::fmod(now + r0 * life, life);
          const double a = r1 * 2.0 * kPi, out_v = 2.0 + 7.0 * r2, up_v = 10.0 + 10.0 * r3;
          p += glm::dvec3(out_v * age * std::cos(a), std::max(0.2, 1.0 + up_v * age - 4.9 * age * age), out_v * age * std::sin(a));
          break;
        }
        case EmitterKind::Birds: {  // a flock circling 20 to 60 m up, 10 to 40 m around the emitter
          const double a = r0 * 2.0 * kPi + now * (0.25 + 0.1 * r3), radius = 10.0 + 30.0 * r1;
          p += glm::dvec3(radius * std::cos(a), 20.0 + 40.0 * r2 + 2.0 * std::sin(now * 3.0 + r3 * 6.0), radius * std::sin(a));
          break;
        }
      }
      out.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z), 1.0f);
    }
  }
  return out;
}

}  // namespace nbsim::capture

// The terrain scene; see terrain.h.
#include "traces/capture/terrain.h"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "traces/capture/mesh_builder.h"

namespace nbsim::capture {

namespace {

// Rolling hills: four sine waves with random phases and directions, 14 m peak to peak at most
// (tunable).
struct Hills {
  std::array<glm::vec3, 4> waves{};  // direction x, z (1/m) and phase

  explicit Hills(std::mt19937& rng) {
    std::uniform_real_distribution<float> angle(0.0f, glm::two_pi<float>());
    for (std::size_t i = 0; i < waves.size(); ++i) {
      const float a = angle(rng), k = glm::two_pi<float>() / (90.0f + 70.0f * static_cast<float>(i));
      waves[i] = {k * std::cos(a), k * std::sin(a), angle(rng)};
    }
  }
  float height(float x, float z) const {
    float h = 0.0f;
    for (const glm::vec3& w : waves) h += 1.75f * std::sin(w.x * x + w.y * z + w.z);
    return h;
  }
};

}  // namespace

CaptureScene make_terrain(const TerrainParams& p) {
  CaptureScene s;
  std::mt19937 rng(p.seed ^ 0x7e44a1u);
  auto uni = [&](double a, double b) { return static_cast<float>(std::uniform_real_distribution<double>(a, b)(rng)); };
  const Hills hills(rng);
  const float ext = static_cast<float>(p.extent_m), cell = ext / static_cast<float>(p.cells);
  MeshBuilder b(s);

  // The ground: a (cells + 1)^2 grid of heights, two triangles a cell, open (a receiver only).
  b.begin("ground");
  const auto row = static_cast<std::uint32_t>(p.cells + 1);
  const std::uint32_t first = b.vertex({0.0f, hills.height(0.0f, 0.0f), 0.0f});
  for (std::uint32_t k = 1; k < row * row; ++k) {
    const float x = static_cast<float>(k % row) * cell, z = static_cast<float>(k / row) * cell;
    b.vertex({x, hills.height(x, z), z});
  }
  for (std::uint32_t j = 0; j + 1 < row; ++j)
    for (std::uint32_t i = 0; i + 1 < row; ++i) {
      const std::uint32_t v = first + j * row + i;
      b.triangle(v, v + row, v + row + 1);  // counter-clockwise seen from above (y up, z towards the viewer)
      b.triangle(v, v + row + 1, v + 1);
    }
  b.end();

  // Towers: square boxes sunk half a metre below the lowest ground point of their footprint.
  for (int t = 0; t < p.towers; ++t) {
    const float side = uni(5.0, 12.0), x = uni(0.1 * ext, 0.9 * ext - side), z = uni(0.1 * ext, 0.9 * ext - side);
    float low = INFINITY;
    for (float u : {0.0f, side})
      for (float v : {0.0f, side}) low = std::min(low, hills.height(x + u, z + v));
    low = std::min(low, hills.height(x + 0.5f * side, z + 0.5f * side)) - 0.5f;
    b.begin("tower");
    b.box({x, low, z}, {x + side, low + uni(25.0, 70.0), z + side});
    b.end();
  }

  // Birds: octahedra 0.6 to 1.6 m across, 15 to 60 m above the ground, over [-ext, 2 ext]^2.
  for (int k = 0; k < p.birds; ++k) {
    const float x = uni(-ext, 2.0 * ext), z = uni(-ext, 2.0 * ext);
    const glm::vec3 c{x, hills.height(x, z) + uni(15.0, 60.0), z};
    const float r = uni(0.3, 0.8);
    b.begin("bird");
    // Corners +x, -x, +y, -y, +z, -z; a face per octant, counter-clockwise seen from outside.
    const std::uint32_t v0 = b.vertex(c + glm::vec3(r, 0, 0));
    b.vertex(c - glm::vec3(r, 0, 0));
    b.vertex(c + glm::vec3(0, 0.4f * r, 0));
    b.vertex(c - glm::vec3(0, 0.4f * r, 0));
    b.vertex(c + glm::vec3(0, 0, 0.6f * r));
    b.vertex(c - glm::vec3(0, 0, 0.6f * r));
    for (std::uint32_t sx = 0; sx < 2; ++sx)
      for (std::uint32_t sy = 0; sy < 2; ++sy)
        for (std::uint32_t sz = 0; sz < 2; ++sz) {
          const std::uint32_t a = v0 + sx, bb = v0 + 2 + sy, cc = v0 + 4 + sz;
          if ((sx + sy + sz) % 2 == 0) b.triangle(a, bb, cc);
          else b.triangle(a, cc, bb);
        }
    b.end();
  }
  b.finish();
  s.site.extent_m = p.extent_m;
  s.site.ground = [hills](float x, float z) { return hills.height(x, z); };
  s.properties = {{"seed", std::to_string(p.seed)},
                  {"towers", std::to_string(p.towers)},
                  {"birds", std::to_string(p.birds)},
                  {"objects", std::to_string(s.objects.size())}};
  return s;
}

}  // namespace nbsim::capture

// Relief textures (Baboud & Decoret, "Rendering Geometry with Relief Textures", GI 2006), the
// model side's plain core (no SystemC): the heightfield, its procedural generators and checks.
// The ray walks are walk.h, the exact reference reference.h, the safety radius radius.h.
//
// Conventions, stated once for model/relief/ (the capture's shaders/relief/ follow them too):
// - A heightfield is N x N texels, N = size, y up, row-major: texel (i, j) is heights[j * N + i],
//   a height in [0, 1]. Its centre is at (i + 0.5, j + 0.5) in texel space.
// - Texel space: x, y in [0, N] across the box's top (texel units), z in [0, 1] up the box (height
//   units). The box is [0, N] x [0, N] x [0, 1] in texel space.
// - The surface is the bilinear interpolation of the texel centres, with virtual texels of height 0
//   all around the field (i or j = -1 or N): height 0 on the border. So a "cell" (ci, cj), ci and
//   cj in [-1, N - 1], is the square between the centres of texels (ci, cj) and (ci + 1, cj + 1),
//   i.e. x in [ci + 0.5, ci + 1.5], where the surface is one bilinear patch.
// - A point is below the surface (a hit) when z <= height(x, y).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace nbsim::relief {

// Supported sizes (a size outside is an InputError): 2 to 1024 texels a side.
inline constexpr int kMinSize = 2;
inline constexpr int kMaxSize = 1024;

struct Heightfield {
  int size = 0;                // N
  std::vector<float> heights;  // N * N, y up, row-major, each in [0, 1]

  // The texel's height, or 0 for a virtual border texel (i or j outside [0, N)).
  float at(int i, int j) const noexcept {
    return (i < 0 || j < 0 || i >= size || j >= size) ? 0.0f : heights[static_cast<std::size_t>(j) * size + i];
  }
};

// Why `field` is not a valid heightfield ("size 3000 is not supported (2 to 1024)", "texel (4, 7)
// is NaN", "texel (1, 2) is 1.5, outside [0, 1]", "has 10 heights, but 4 x 4 needs 16"), or empty.
std::string heightfield_problem(const Heightfield& field);
// Throws InputError with `what` ("the heightfield in f.exr") and the problem, if any.
void check_heightfield(const Heightfield& field, std::string_view what);

// The surface height at texel-space (x, y) in double precision (the reference's surface).
double surface_height(const Heightfield& field, double x, double y) noexcept;

// Procedural heightfields (every one valid, deterministic in its arguments; `param` as said):
// - fbm: fractal Brownian motion terrain: `param` octaves (1 to 12; 0 means 6) of smoothly
//   interpolated value noise from `seed`, scaled into [0, 0.9].
// - walls: a lattice of thin walls one texel thick, height 1, every `param` texels (2 or more; 0
//   means 8), on a floor of height 0.
// - spikes: single-texel spikes of height 1 at random texels (`param` of them; 0 means N / 4), on a
//   floor of height 0.1: each a peak whose safety radius is 0.
// - saddle: Figure 3's saddle: four texels of heights 0, 1 / 1, 0 in the middle of the field (at
//   texels N/2 - 1 and N/2), 0 elsewhere; `param` unused.
// - step: a 0 to 1 step: height 1 for x >= N / 2 (texel columns i >= N / 2), 0 before.
// Names: "fbm", "walls", "spikes", "saddle", "step". InputError for an unknown name or a bad param
// or size.
Heightfield make_heightfield(std::string_view kind, int size, int param, std::uint64_t seed);
const std::vector<std::string_view>& heightfield_kinds();

}  // namespace nbsim::relief

// The N-buffer paper's terrain scene (4.4): a heightfield ground (one
// open object, a receiver only) with towers standing on it and many small flying casters (birds,
// closed octahedra) at 15 to 60 m above it, scattered over an area nine times the terrain's, so
// most of them are out of the camera's and the light's view. Deterministic for a seed.
#pragma once

#include <cstdint>

#include "traces/capture/scenes.h"

namespace nbsim::capture {

struct TerrainParams {
  std::uint32_t seed = 1;
  int towers = 40;
  int birds = 2000;
  double extent_m = 600.0;  // side of the square ground (tunable)
  int cells = 96;           // heightfield cells a side (tunable)
};

// Object 0 is the ground, then the towers, then the birds.
CaptureScene make_terrain(const TerrainParams& params);

}  // namespace nbsim::capture

// A built-in depth scene for the demo and the command line, until captured GL traces replace it:
// a street seen in perspective, with building facades standing on the ground and sky at the far
// plane. Deterministic for a given size and seed.
#pragma once

#include <cstdint>

#include "model/common/depth.h"

namespace nbsim::scenes {

DepthImage city_depth(int width, int height, std::uint32_t seed = 1);

}  // namespace nbsim::scenes

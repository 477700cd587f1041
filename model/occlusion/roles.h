// Occlusion culling's draw roles: none of its own. Its draws (occluders, bounding-box queries, the
// GLSL N-buffer's build and query passes) use the core roles of model/scene/frame.h.
#pragma once

#include <array>

#include "model/scene/frame.h"

namespace nbsim::occlusion {

inline constexpr std::array<scene::RoleName, 0> kRoles = {};

}  // namespace nbsim::occlusion

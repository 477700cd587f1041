// The particles technique's draw roles (the N-buffer paper, 3.2), beside the core ones of
// model/scene/frame.h; listed in model/scene/technique_roles.h.
#pragma once

#include <array>

#include "model/scene/frame.h"

namespace nbsim::particles {

// Point sprites, depth test on, depth write off, culled in the vertex stage.
inline constexpr scene::DrawRole kParticlesRole{8};
// A full-screen pass building one level of a Hi-Z max/min mip pyramid (mode hiz).
inline constexpr scene::DrawRole kHiZBuildRole{9};

inline constexpr std::array<scene::RoleName, 2> kRoles = {{{kParticlesRole, "particles"}, {kHiZBuildRole, "hiz_build"}}};

}  // namespace nbsim::particles

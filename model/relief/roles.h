// The relief-texture technique's draw role, beside the core ones of model/scene/frame.h; listed
// in model/scene/technique_roles.h.
#pragma once

#include <array>

#include "model/scene/frame.h"

namespace nbsim::relief {

// A relief box drawn with one ray-walk method: early fragment tests, depth write off, every fragment casts its ray, a miss discards.
inline constexpr scene::DrawRole kReliefBoxRole{14};

inline constexpr std::array<scene::RoleName, 1> kRoles = {{{kReliefBoxRole, "relief_box"}}};

}  // namespace nbsim::relief

// The layered-depth-image technique's draw role, beside the core ones of model/scene/frame.h;
// listed in model/scene/technique_roles.h.
#pragma once

#include <array>

#include "model/scene/frame.h"

namespace nbsim::ldi {

// One depth-peeling pass of a shape into an LDI layer: orthographic, LEQUAL, strict test against the previous layer in the shader.
inline constexpr scene::DrawRole kLdiPeelRole{13};

inline constexpr std::array<scene::RoleName, 1> kRoles = {{{kLdiPeelRole, "ldi_peel"}}};

}  // namespace nbsim::ldi

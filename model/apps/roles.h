// The apps technique's draw role, beside the core ones of model/scene/frame.h; listed in
// model/scene/technique_roles.h.
#pragma once

#include <array>

#include "model/scene/frame.h"

namespace nbsim::apps {

// A draw call of a recorded program, with the GL state it ran with (the frame's AppDraws record).
inline constexpr scene::DrawRole kAppDrawRole{15};

inline constexpr std::array<scene::RoleName, 1> kRoles = {{{kAppDrawRole, "app_draw"}}};

}  // namespace nbsim::apps

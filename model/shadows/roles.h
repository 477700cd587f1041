// The shadow-volume technique's draw roles (the N-buffer paper, 3.3), beside the core ones of
// model/scene/frame.h; listed in model/scene/technique_roles.h.
#pragma once

#include <array>

#include "model/scene/frame.h"

namespace nbsim::shadows {

// A caster's stencil shadow volume: z-fail, two-sided, depth write off, depth clamp.
inline constexpr scene::DrawRole kShadowVolumeRole{10};
// A scene object drawn from the light into a litmap, observer-hidden fragments discarded.
inline constexpr scene::DrawRole kLitmapRole{11};
// The observer's receivers as one-pixel points from the light into a litmap.
inline constexpr scene::DrawRole kReceiverSplatRole{12};

inline constexpr std::array<scene::RoleName, 3> kRoles = {{{kShadowVolumeRole, "shadow_volume"}, {kLitmapRole, "litmap"}, {kReceiverSplatRole, "receiver_splat"}}};

}  // namespace nbsim::shadows

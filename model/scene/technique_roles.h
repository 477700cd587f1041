// The registration list of the techniques' draw roles (each declared in model/<name>/roles.h),
// after the core roles of frame.h: their names, and the largest role value a DRAW record may hold.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>

#include "model/ldi/roles.h"
#include "model/particles/roles.h"
#include "model/relief/roles.h"
#include "model/scene/frame.h"
#include "model/shadows/roles.h"

namespace nbsim::scene {

namespace detail {

template <std::size_t... N>
constexpr auto join_roles(const std::array<RoleName, N>&... lists) {
  std::array<RoleName, (N + ...)> out{};
  std::size_t at = 0;
  ((std::copy(lists.begin(), lists.end(), out.begin() + static_cast<std::ptrdiff_t>(at)), at += N), ...);
  return out;
}

}  // namespace detail

inline constexpr auto kTechniqueRoles = detail::join_roles(particles::kRoles, shadows::kRoles, ldi::kRoles, relief::kRoles);

// The technique roles take the values after the core ones, each once, in the list's order.
constexpr bool technique_roles_contiguous() {
  for (std::size_t i = 0; i < kTechniqueRoles.size(); ++i)
    if (static_cast<std::size_t>(kTechniqueRoles[i].role) != kFirstTechniqueRole + i) return false;
  return true;
}
static_assert(technique_roles_contiguous(), "technique draw roles must follow the core roles, one value each, in list order");

inline constexpr unsigned kMaxDrawRole = kFirstTechniqueRole + static_cast<unsigned>(kTechniqueRoles.size()) - 1;

}  // namespace nbsim::scene

// The techniques' draw roles (each declared in model/<name>/roles.h as kRoles), after the core
// roles of frame.h, in the registration list's order: their names, and the largest role value a
// DRAW record may hold.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>

#include "model/scene/frame.h"
#include "nbsim/technique_list.h"
#include "nbsim/technique_roles_list.h"

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

#define NBSIM_TECHNIQUE_ROLES(name) name::kRoles,
inline constexpr auto kTechniqueRoles = detail::join_roles(NBSIM_EACH_TECHNIQUE(NBSIM_TECHNIQUE_ROLES) std::array<RoleName, 0>{});
#undef NBSIM_TECHNIQUE_ROLES

// The technique roles take the values after the core ones, each once, in the list's order.
constexpr bool technique_roles_contiguous() {
  for (std::size_t i = 0; i < kTechniqueRoles.size(); ++i)
    if (static_cast<std::size_t>(kTechniqueRoles[i].role) != kFirstTechniqueRole + i) return false;
  return true;
}
static_assert(technique_roles_contiguous(), "technique draw roles must follow the core roles, one value each, in list order");

inline constexpr unsigned kMaxDrawRole = kFirstTechniqueRole + static_cast<unsigned>(kTechniqueRoles.size()) - 1;

}  // namespace nbsim::scene

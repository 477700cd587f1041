// The frame's look-ups and the names of its enums; see frame.h.
#include "model/scene/frame.h"

#include "model/common/names.h"
#include "model/scene/technique_roles.h"

namespace nbsim::scene {

namespace {

// One name table per enum, indexed by the enum's fixed value.
constexpr std::array<std::string_view, kFirstTechniqueRole> kRoleNames = {
    "occluder", "bounds_query", "node_query", "nbuffer_build", "nbuffer_query", "visible", "id_buffer", "scene"};
constexpr std::array<std::string_view, 2> kDepthWhichNames = {"after_occluders", "final"};
constexpr std::array<std::string_view, 8> kDepthFuncNames = {"never",   "less",     "equal",  "lequal",
                                                             "greater", "notequal", "gequal", "always"};
constexpr std::array<std::string_view, 4> kCullFaceNames = {"none", "back", "front", "front_and_back"};
constexpr std::array<std::string_view, 2> kClipControlNames = {"negative_one_to_one", "zero_to_one"};
constexpr std::array<std::string_view, 2> kTopologyNames = {"triangles", "points"};
constexpr std::array<std::string_view, 8> kStencilOpNames = {"keep", "zero",      "replace", "incr",
                                                             "incr_wrap", "decr", "decr_wrap", "invert"};

}  // namespace

const DepthSnapshot* Frame::depth(DepthWhich which) const noexcept { return depth(to_string(which)); }

const DepthSnapshot* Frame::depth(std::string_view name) const noexcept {
  for (const DepthSnapshot& d : depths)
    if (d.name == name) return &d;
  return nullptr;
}

const StencilSnapshot* Frame::stencil(std::string_view name) const noexcept {
  for (const StencilSnapshot& s : stencils)
    if (s.name == name) return &s;
  return nullptr;
}

const NBufferLevels* Frame::nbuffer(FarOp op) const noexcept {
  for (const NBufferLevels& l : levels)
    if (l.op == static_cast<std::uint8_t>(op)) return &l;
  return nullptr;
}

const NBufferLevels* Frame::nbuffer(std::string_view source, FarOp op) const noexcept {
  for (const NBufferLevels& l : levels)
    if (l.source == source && l.op == static_cast<std::uint8_t>(op)) return &l;
  return nullptr;
}

std::string_view to_string(DrawRole role) noexcept {
  if (static_cast<std::uint8_t>(role) < kFirstTechniqueRole) return enum_name(kRoleNames, role);
  for (const RoleName& r : kTechniqueRoles)
    if (r.role == role) return r.name;
  return "?";
}
std::string_view to_string(TestMode mode) noexcept { return enum_name(kTestModeNames, mode); }
std::optional<TestMode> parse_test_mode(std::string_view s) noexcept { return parse_enum_name<TestMode>(kTestModeNames, s); }
std::string_view to_string(DepthWhich which) noexcept { return enum_name(kDepthWhichNames, which); }
std::string_view to_string(DepthFunc func) noexcept { return enum_name(kDepthFuncNames, func); }
std::string_view to_string(CullFace cull) noexcept { return enum_name(kCullFaceNames, cull); }
std::string_view to_string(ClipControl clip) noexcept { return enum_name(kClipControlNames, clip); }
std::string_view to_string(Topology topology) noexcept { return enum_name(kTopologyNames, topology); }
std::string_view to_string(StencilOp op) noexcept { return enum_name(kStencilOpNames, op); }

}  // namespace nbsim::scene

// The cull stage's mode names; see report.h.
#include "model/cull/report.h"

#include "model/common/names.h"

namespace nbsim::cull {

namespace {

constexpr std::array<std::string_view, 8> kModeNames = {"trace", "none",    "oq",       "oq_hier",
                                                        "nb",    "nb_hier", "hiz_tile", "hiz_pyramid"};

}  // namespace

std::string_view to_string(CullMode m) noexcept { return enum_name(kModeNames, m); }

std::optional<CullMode> parse_cull_mode(std::string_view s) noexcept { return parse_enum_name<CullMode>(kModeNames, s); }

bool hierarchical(CullMode m) noexcept { return m == CullMode::OqHier || m == CullMode::NbHier; }

}  // namespace nbsim::cull

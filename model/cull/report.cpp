// The cull stage's mode names; see report.h.
#include "model/cull/report.h"

#include "model/common/names.h"

namespace nbsim::cull {

std::string_view to_string(CullMode m) noexcept { return enum_name(kCullModeNames, m); }

std::optional<CullMode> parse_cull_mode(std::string_view s) noexcept { return parse_enum_name<CullMode>(kCullModeNames, s); }

bool hierarchical(CullMode m) noexcept { return m == CullMode::OqHier || m == CullMode::NbHier; }

}  // namespace nbsim::cull

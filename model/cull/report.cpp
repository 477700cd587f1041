// The cull stage's mode names and bounds-test log; see report.h.
#include "model/cull/report.h"

#include <fmt/format.h>

#include <string>

#include "model/common/names.h"

namespace nbsim::cull {

std::string_view to_string(CullMode m) noexcept { return enum_name(kCullModeNames, m); }

std::optional<CullMode> parse_cull_mode(std::string_view s) noexcept { return parse_enum_name<CullMode>(kCullModeNames, s); }

bool hierarchical(CullMode m) noexcept { return m == CullMode::OqHier || m == CullMode::NbHier; }

void write_bounds_test(std::ostream& log, std::uint32_t frame, CullMode mode, const scene::TestItem& item,
                       const scene::BoundsTest& t, std::uint64_t depth_tests, const scene::GroundTruth* truth) {
  std::string pixels;
  bool false_cull = false;
  if (item.object >= 0 && truth && static_cast<std::size_t>(item.object) < truth->visible_pixels.size()) {
    const std::uint32_t px = truth->visible_pixels[static_cast<std::size_t>(item.object)];
    pixels = std::to_string(px);
    false_cull = px > 0 && !t.visible;
  }
  log << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", frame, to_string(mode), item.object, item.node, t.x, t.y,
                     t.w, t.h, t.nearest_depth, t.crosses_near ? 1 : 0, t.visible ? "visible" : "culled", depth_tests, pixels,
                     false_cull ? 1 : 0);
}

}  // namespace nbsim::cull

// The cull stage's modes and the log of its bounds tests (plain C++, no SystemC). The bounds tests
// and the traversal it runs are the scene's (model/scene/visibility.h); model/cull/unit.h wraps
// them with the query structures, timing and statistics.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <ostream>
#include <string_view>
#include <vector>

#include "model/scene/visibility.h"

namespace nbsim::cull {

// How a replay culls. Fixed values (they end up in run outputs).
enum class CullMode : std::uint8_t {
  Trace = 0,       // replay exactly the recorded draws (no culling by the model)
  None = 1,        // draw every candidate, test nothing
  Oq = 2,          // occlusion queries: rasterize each candidate's bounding box
  OqHier = 3,      // occlusion queries over the BVH
  Nb = 4,          // N-buffer unit: four lookups per candidate
  NbHier = 5,      // N-buffer unit over the BVH
  HizTile = 6,     // single-level tile Hi-Z
  HizPyramid = 7,  // Hi-Z pyramid, at most 2x2 texels per query
};

// Names of CullMode, indexed by its value (model/common/names.h); cull.mode takes them.
inline constexpr std::array<std::string_view, 8> kCullModeNames = {"trace", "none",    "oq",       "oq_hier",
                                                                   "nb",    "nb_hier", "hiz_tile", "hiz_pyramid"};
std::string_view to_string(CullMode m) noexcept;
std::optional<CullMode> parse_cull_mode(std::string_view s) noexcept;
bool hierarchical(CullMode m) noexcept;

// The log of every bounds test (culls.csv, when a replay writes its outputs): what was tested
// (an object, or a BVH node), its screen rectangle and nearest depth, the decision, what it cost
// (box fragments or texels compared) and, for objects, the ground truth's visible pixels.
inline constexpr std::string_view kBoundsTestLogHeader =
    "frame,mode,object,node,x,y,w,h,nearest_depth,crosses_near,decision,depth_tests,truth_visible_pixels,false_cull";
void write_bounds_test(std::ostream& log, std::uint32_t frame, CullMode mode, const scene::TestItem& item,
                       const scene::BoundsTest& test, std::uint64_t depth_tests, const scene::GroundTruth* truth);

}  // namespace nbsim::cull

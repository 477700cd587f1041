// The cull stage's modes and its per-frame report (plain C++, no SystemC). The bounds tests and the
// traversal it runs are the scene's (model/scene/visibility.h); model/cull/unit.h wraps them with
// the query units, timing and counters.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "model/cp/work.h"
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

// What the cull stage did in one frame (plain counters; the replay derives ratios).
struct CullReport : cp::FrameResult {
  CullMode mode = CullMode::Trace;
  std::uint64_t in_frustum = 0;       // objects in the view frustum
  std::uint64_t occluders = 0;        // of those, drawn first (recorded Occluder draws)
  std::uint64_t candidates = 0;       // in_frustum - occluders: the objects the stage decides on
  std::uint64_t bounds_tests = 0;     // object and node bounds tested
  std::uint64_t node_tests = 0;       // of those, BVH nodes
  std::uint64_t found_visible = 0;    // candidates found visible
  std::uint64_t culled = 0;           // candidates not found visible
  std::uint64_t undrawable = 0;       // found visible but the trace holds no geometry for them
  std::uint64_t box_depth_tests = 0;  // occlusion queries: depth tests of the rasterized boxes
  std::uint64_t lookups = 0;          // N-buffer / Hi-Z texels compared against
  std::uint64_t max_lookups = 0;      // most texels one bounds test compared against
  std::uint64_t update_texels = 0;    // N-buffer / Hi-Z texels recomputed from depth changes or rebuilt
  std::uint64_t clear_texels = 0;     // N-buffer texels filled by the frame's fast clear (not counted as work)
  bool has_truth = false;             // the frame has ground truth; the three below are meaningful
  std::uint64_t candidates_not_visible = 0;  // candidates with no visible pixel
  std::uint64_t false_culls = 0;             // culled candidates with visible pixels
  std::uint64_t crossing_near = 0;           // bounds tests that crossed the near plane (never culled)
  // cull.granularity=primitive (model/cull/primitive.h): the triangles of the drawn candidates,
  // tested between setup and the tile walk. The raster unit fills these in after run_frame returned
  // and before the frame's FrameEnd passes it (the pipeline is in order), so they are final when
  // the FrameEnd reaches the end of the pipeline.
  std::uint64_t primitive_tests = 0;             // triangles tested (accepted by setup, on screen)
  std::uint64_t primitives_culled = 0;           // of those, found hidden and dropped
  std::uint64_t primitive_lookups = 0;           // N-buffer / Hi-Z texels compared against for them
  std::uint64_t primitive_fragments_culled = 0;  // fragments the dropped triangles would have rasterized
  std::uint64_t primitive_false_culls = 0;       // dropped triangles with a fragment that passes against
                                                 // the occluders' depth (an upper bound on real ones)

  // Every bounds test of the frame, in order: what was tested, the decision and what it cost.
  struct Test {
    std::int32_t object = -1;  // object id, or -1 for a BVH node
    std::int32_t node = -1;    // BVH node id, or -1 for an object
    scene::BoundsTest bounds;  // rect, nearest depth, crosses_near, and the decision in .visible
    std::uint64_t depth_tests = 0;  // box fragments (occlusion queries) or texels compared (N-buffer, Hi-Z)
  };
  std::vector<Test> tests;

  // The depth tests spent on visibility queries (ARCHITECTURE.md: the paper-comparable count),
  // bounds and per-primitive queries alike.
  std::uint64_t query_depth_tests() const noexcept { return box_depth_tests + lookups + primitive_lookups; }
};

}  // namespace nbsim::cull

// Shadow volumes with litmaps (N-buffer paper 3.3/4.4), the model side's plain core (no SystemC):
// a frame's SHDC record (one entry per caster: its light-space rectangle, bounds depths, GL's
// z_min/z_max, decision and clamp planes), the capture's cull rule recomputed in double from the
// light camera (LGHT) and the header's clamp margin, and the comparison of a caster's queried
// [z_min, z_max] and decision with GL's. The unit (unit.h) does the queries, times and counts.
// Light window depth: GL's default (0 at the light, LESS), from the light's perspective frustum.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "model/common/rect.h"
#include "model/scene/frame.h"

namespace nbsim::shadows {

// The trace's shadow_mode. Fixed values (as the capture names them).
enum class Mode : std::uint8_t { Infinite = 0, Culled = 1, Clamped = 2 };
inline constexpr std::array<std::string_view, 3> kModeNames = {"infinite", "culled", "clamped"};
std::optional<Mode> parse_mode(std::string_view s) noexcept;

// SHDC's `decision`. Fixed values (they are in files; traces/FORMAT.md).
enum class Decision : std::uint8_t { Volume = 0, Culled = 1, OutsideLight = 2, CrossesNear = 3 };

// SHDC's `kept`: why a culled or clamped capture keeps a caster's volume (the same in every mode;
// fixed values, they are in files).
enum class KeptBy : std::uint8_t {
  Dropped = 0,      // culled, or outside the light's frustum: no volume in culled and clamped
  Receivers = 1,    // the litmaps' slab has a visible receiver behind it
  SeenCaster = 2,   // the observer sees the caster itself (its own bounds join its slab)
  Widened = 3,      // only the slab's widening keeps it (a seen caster crossing the light's near plane)
  CrossesNear = 4,  // it crosses the light's near plane: never culled or clamped
};
inline constexpr std::array<std::string_view, 5> kKeptNames = {"dropped", "receivers", "seen_caster", "widened", "crosses_near"};

// The clamp margin of the header ("0.01 + 0.1 m"): the slab's far end is pushed back by
// rel * distance + metres before the cull test (the capture's kClampRel, kClampM).
struct ClampMargin {
  double rel = 0.01, metres = 0.1;
};
// Parses "<rel> + <metres> m"; nullopt when malformed or out of [0, 1] x [0, 1000].
std::optional<ClampMargin> parse_clamp_margin(std::string_view s) noexcept;

// Light window depth <-> distance along the light's view axis, from its projection matrix
// (column-major, GL's [-1, 1] clip z): window = 0.5 (-A + B / dist) + 0.5 with A = proj[10],
// B = proj[14]. Valid for a perspective frustum with near < far (checked by make()).
struct LightDepth {
  double a = 0.0, b = 0.0;
  // nullopt when the matrix is not a perspective frustum (proj[11] != -1, a degenerate depth range).
  static std::optional<LightDepth> make(const scene::Camera& light) noexcept;
  double depth_of_distance(double distance_m) const noexcept { return 0.5 * (-a + b / distance_m) + 0.5; }
  double distance_of_depth(double depth) const noexcept { return b / (2.0 * depth - 1.0 + a); }
};

// The capture's cull rule on the litmaps' slab alone (FORMAT.md, SHDC `decision` 1): the farthest
// visible receiver z_max, pushed back by the clamp margin, is nearer than max(z_min, caster_near).
// (The capture widens the slab for receivers the litmaps cannot sample, from the scene's triangles,
// which the trace does not hold: it may keep casters this rule culls, never the other way round.)
bool litmap_rule_culls(float z_min, float z_max, float caster_near, const LightDepth& light, const ClampMargin& m) noexcept;

// One frame's SHDC record, decoded and checked (every vector `count` long, decisions 0..3, every
// measured rectangle inside the litmap, `draw` naming a ShadowVolume draw of the frame or -1).
struct FrameCasters {
  std::uint32_t litmap_size = 0;
  std::vector<std::uint32_t> object, lookups, decision;
  std::vector<std::int32_t> x, y, w, h, draw;
  std::vector<float> caster_near, caster_far, z_min, z_max, clamp_near, clamp_far;
  // GL's reference pass (every caster's infinite volume, not recorded as draws): its fill and the
  // pixels where the mode's mask differs from its mask; empty when the record does not hold them.
  std::optional<std::uint64_t> reference_fill, mask_diff_pixels;
  // Each caster's class (an index into class_names: "bird", "building"), why it is kept (KeptBy)
  // and the fill of its infinite volume (GL's reference pass, or its own draw in mode infinite).
  std::vector<std::string> class_names;
  std::vector<std::uint32_t> cls, kept, fill_infinite;
  // The light camera as the capture built it: eye x, y, z, target x, y, z, field of view (degrees),
  // near and far (metres); volume.h's light_of() makes it.
  std::array<double, 9> light{};
  std::size_t size() const noexcept { return object.size(); }
  Rect rect(std::size_t i) const noexcept { return Rect{x[i], y[i], w[i], h[i]}; }
};
inline constexpr std::uint32_t kShadowsRecordType = 0x43444853u;  // fourcc "SHDC" (traces/format/shadows/shadows_chunk.h)
// Throws InputError naming the frame and the field for a missing or damaged record.
FrameCasters read_casters(const scene::Frame& f);

// The exact depth range of the visible receivers in a rectangle: the min of `litmap_min` and the
// max of `litmap_max` over its lexels (the images as GL drew them). GL's N-buffer answers read the
// squares of the capture's covering (model/nbuffer/covering.h), which may reach past the rectangle,
// so they are this range or looser; the conservative checks compare with it, the equality checks
// with GL's.
struct DepthRange {
  float z_min = 1.0f, z_max = 0.0f;
};
DepthRange exact_range(const DepthImage& litmap_min, const DepthImage& litmap_max, const Rect& r) noexcept;

// What the model found for one measured caster (rectangle inside the litmap), against GL's record.
struct CasterCheck {
  bool model_culled = false;      // the litmap rule on the model's z_min/z_max
  bool decision_mismatch = false; // GL culled, yet the rule on GL's own recorded values keeps it
  bool kept_by_slab = false;      // GL kept a caster the rule culls on GL's values (its wider slab)
  bool zmin_mismatch = false, zmax_mismatch = false;  // the model's value differs from GL's
  bool not_conservative = false;  // z_min above the exact range's or z_max below it (no design may)
  bool unsafe_cull = false;       // the model culls a caster the rule on the exact range keeps
  bool cull_lost = false;         // GL culled, the model keeps (a conservative design's cost)
};
CasterCheck check_caster(const FrameCasters& c, std::size_t i, float model_z_min, float model_z_max, const DepthRange& exact,
                         const LightDepth& light, const ClampMargin& m) noexcept;

// The shadow mask from a stencil buffer: light_region && stencil != 0, per pixel; returns the
// pixels where it differs from `mask` (all three images W x H, y up).
std::uint64_t mask_pixels_differing(const std::vector<std::uint8_t>& stencil, const scene::StencilSnapshot& light_region,
                                    const scene::StencilSnapshot& mask, std::uint64_t* mask_pixels = nullptr) noexcept;

}  // namespace nbsim::shadows

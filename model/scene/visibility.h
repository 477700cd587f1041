// Visibility on the frame's scene (model/scene/frame.h), shared by the GL renderer (which records
// what its technique decided) and the model (which decides again): the frame's camera, an object's
// screen bounds test and box geometry as GL computes them, the view-frustum test and the flat or
// BVH-hierarchical traversal that decides which candidate objects to draw. One implementation, so
// that the renderer's and the model's decisions cannot drift apart.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include <glm/vec3.hpp>

#include "model/scene/frame.h"

namespace nbsim::scene {

// An AABB's box: 36 indices into its 8 corners (bit 0 = x, 1 = y, 2 = z), CCW seen from outside.
// The renderer's index buffer and the model's box geometry both use it, so that GL's and the
// model's triangles coincide. Fixed by the trace: changing it changes which box fragments count.
inline constexpr std::array<std::uint8_t, 36> kBoxIndices = {0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4,
                                                             2, 6, 7, 2, 7, 3, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6};

// One frame's camera as the renderer used it. view_proj = proj * view in float (as glm computes
// it on the host; the vertex shader receives it), and in double for the bounds tests.
struct FrameView {
  std::array<float, 16> view_proj{};     // column-major
  std::array<double, 16> view_proj_d{};  // the same values, widened
  int width_px = 0, height_px = 0;
  double near_m = 0.0;          // header property "near"
  double nearest_margin = 0.0;  // header property "nearest_margin": subtracted toward the eye
  bool zero_to_one = false;     // clip control ZERO_TO_ONE (reversed Z) vs NEGATIVE_ONE_TO_ONE
  bool reversed = false;        // depth func GREATER: nearer is larger

  static FrameView make(const FrameBegin& f, int width_px, int height_px, double near_m, double nearest_margin,
                        bool zero_to_one, bool reversed);
};

// The screen rectangle and nearest depth of an AABB: the 8 corners projected in double; bounds
// with a corner behind near * 0.999 cross the near plane (whole viewport, nearest possible depth,
// never culled); the rectangle is floor/ceil of the projected extent clipped to the viewport; the
// nearest depth moves `nearest_margin` toward the eye. `visible` is left true.
BoundsTest bounds_test(const Aabb& b, const FrameView& v);

// The AABB's box as GL's vertex shader computes it: 12 triangles (36 vertices, CCW outward, the
// renderer's 8-corner / 36-index pattern), clip position = view_proj * (corner, 1) in float.
void box_clip_positions(const Aabb& b, const FrameView& v, std::vector<std::array<float, 4>>& out);

// True when the AABB is entirely outside one of the six frustum planes (Gribb-Hartmann).
bool outside_frustum(const Aabb& b, const FrameView& v);

// Objects whose bounds meet the frustum (BVH traversal from node 0), sorted by id.
std::vector<std::uint32_t> frustum_objects(const SceneObjects& s, const FrameView& v);

// The distance from `p` to the nearest point of `b` (0 inside): the order an engine sorts its
// opaque draws in, front to back.
double distance_to(const Aabb& b, const glm::dvec3& p);

// One bounds test a traversal asks for: an object (node < 0) or a BVH node.
struct TestItem {
  std::int32_t object = -1;
  std::int32_t node = -1;
};

// Decides, for one batch of items with their bounds tests, which are visible (sets .visible).
using BatchTester = std::function<void(const std::vector<TestItem>& items, std::vector<BoundsTest>& tests)>;

// Which candidate objects are visible. Flat: every object in `in_frustum` that is not an occluder,
// in one batch. Hierarchical (the renderer's traversal): one batch per BVH depth, from node 0;
// items outside the frustum are skipped, a visible node opens its children (or its leaf's objects)
// for the next batch, occluders are never tested. Returns a flag per scene object.
std::vector<char> find_visible(const SceneObjects& s, const FrameView& v, const std::vector<std::uint32_t>& in_frustum,
                               const std::vector<char>& is_occluder, bool hierarchical, const BatchTester& tester);

}  // namespace nbsim::scene

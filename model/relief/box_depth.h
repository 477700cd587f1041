// What a relief box draw leaves in the depth buffer (the relief paper's section 4.4, "interaction
// with the Z-buffer"). The box is drawn in place of the relief surface, so the buffer can hold
//  - none:  nothing; the box tests with depth writes off (nbsim's first set-up, kept for comparison);
//  - box:   the box face's own depth, written only where the ray hit (a miss discards): the paper's
//           choice. The depth is conservative (never nearer than the face, never behind the surface
//           seen through it), and since the shader does not write gl_FragDepth the depth test runs
//           before the shader, so the walks of hidden fragments are never run; the write waits for
//           the shader's verdict (early test, late write);
//  - exact: the hit point's own depth (gl_FragDepth). The test then has to wait for the walk: every
//           rasterized box fragment walks, hidden or not, and the test uses the written depth.
// A frame with several box draws (one per method) starts each from the same depth: the depth as it
// was before the frame's first box draw (the capture restores it), so each method renders the
// frame as if it were the only one.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

#include "model/relief/walk.h"

namespace nbsim::relief {

// Fixed values (the trace header's relief_box_depth spells them).
enum class BoxDepth : std::uint8_t { None = 0, Box = 1, Exact = 2 };
inline constexpr std::array<std::string_view, 3> kBoxDepthNames = {"none", "box", "exact"};
std::optional<BoxDepth> parse_box_depth(std::string_view s) noexcept;

// The window depth relief.frag writes to gl_FragDepth for a hit at `t` on `ray`: the point
// o + t d of texel space through `texel_to_clip` (column-major, as the box's vertex shader takes
// it), z / w mapped from [-1, 1] to [0, 1]; float arithmetic in the shader's order, nothing fused.
// The depth test clamps it to [0, 1] (model/raster/depth_test.h).
float hit_depth(const std::array<float, 16>& texel_to_clip, const FragmentRay& ray, float t) noexcept;

}  // namespace nbsim::relief

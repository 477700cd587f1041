// Per-primitive culling (cull.granularity=primitive), plain C++ core (no SystemC): the depth query
// of one triangle that triangle setup accepted, as Décoret 2005 suggests for culling at finer grain
// than objects. model/cull/unit.h asks its query unit (N-buffer, tile Hi-Z, Hi-Z pyramid) whether
// the query's rectangle holds depth nearer than the triangle everywhere; the raster unit
// (model/raster/unit.h) then drops a hidden triangle before its tile walk and depth tests.
//
// Why after setup and not from the float vertices before it: the rasterizer covers pixel centres
// of the *snapped* triangle (1/256 px), and the depth unit evaluates llvmpipe's float depth plane
// there, which extrapolates past the vertices' depths (snapping moves edges by up to 1/512 px, and
// for slivers the float plane itself is far off the true plane). The minimum vertex depth is then
// not a bound on the fragments' depths, and a test built on it could cull a triangle with a visible
// fragment. Setup's pixel box and depth plane give bounds that hold for every fragment, bit for bit
// (tests/model/cull/cull_primitive_test.cpp checks them against brute force).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

#include "model/common/depth.h"
#include "model/common/rect.h"
#include "model/cull/report.h"
#include "model/geometry/primitive.h"
#include "model/raster/setup.h"

namespace nbsim::cull {

// What a culling mode tests. Fixed values (they end up in run outputs).
enum class Granularity : std::uint8_t {
  Object = 0,     // bounds of candidate objects (and BVH nodes) only
  Primitive = 1,  // also every triangle of the objects drawn as visible candidates
};

// Names of Granularity, indexed by its value (model/common/names.h); cull.granularity takes them.
inline constexpr std::array<std::string_view, 2> kGranularityNames = {"object", "primitive"};
std::string_view to_string(Granularity g) noexcept;
std::optional<Granularity> parse_granularity(std::string_view s) noexcept;
// The modes with a depth-query structure a triangle can be tested against: nb, nb_hier, hiz_tile,
// hiz_pyramid. (oq and oq_hier would need an occlusion query per triangle, i.e. rasterizing it.)
bool supports_primitive_granularity(CullMode m) noexcept;

// The depth query of one triangle.
struct PrimitiveQuery {
  Rect rect;             // every pixel the rasterizer may cover, inside the render target
  float nearest = 0.0f;  // no fragment depth of the triangle is nearer than this (under the FarOp)
  bool testable = false;  // false: empty rectangle or no finite depth bound; never cull it
};

// The query of a triangle that setup accepted (`s` is setup's output for `w`). The rectangle is
// setup's pixel box within the render target (the tile walk never leaves it). The nearest depth is
// the farther (tighter) of two bounds on every fragment depth the depth unit computes with
// `fused_interpolation` (model/raster/setup.h DepthPlane::at):
//  - exact: the float plane evaluation fmuladd(dzdy, y, fmuladd(dzdx, x, a0)), then the clamp, is
//    monotone in x and in y (each rounding is), so over the box's pixels its extremes sit at the
//    box's four corner pixels;
//  - tight: the exact plane's extreme over the snapped triangle (at a snapped vertex: every covered
//    pixel centre lies in that triangle), moved toward the eye by a bound on the float
//    evaluation's rounding (2^-20 of the largest term), then clamped to [0, 1].
// Under FarOp::Max (depth func LESS/LEQUAL) nearest is a lower bound, under FarOp::Min an upper one.
PrimitiveQuery primitive_query(const geometry::WindowTriangle& w, const raster::SetupTriangle& s, FarOp op,
                               bool fused_interpolation);

}  // namespace nbsim::cull

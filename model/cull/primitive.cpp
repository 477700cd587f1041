// Per-primitive culling core: the triangle's query rectangle and nearest depth; see primitive.h.
#include "model/cull/primitive.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "model/common/names.h"

namespace nbsim::cull {

namespace {

// Relative bound on the rounding of DepthPlane::raw_at against the exact plane: two roundings
// (fused) or four (unfused), each at most 2^-24 of a term no larger than the sum of the absolute
// terms. 2^-20 leaves a factor of four to spare; fixed by the analysis, not tunable.
constexpr double kPlaneRounding = 0x1p-20;

}  // namespace

std::string_view to_string(Granularity g) noexcept { return enum_name(kGranularityNames, g); }

std::optional<Granularity> parse_granularity(std::string_view s) noexcept {
  return parse_enum_name<Granularity>(kGranularityNames, s);
}

bool supports_primitive_granularity(CullMode m) noexcept {
  return m == CullMode::Nb || m == CullMode::NbHier || m == CullMode::HizTile || m == CullMode::HizPyramid;
}

PrimitiveQuery primitive_query(const geometry::WindowTriangle& w, const raster::SetupTriangle& s, FarOp op,
                               bool fused_interpolation) {
  PrimitiveQuery q;
  const raster::PixelBox& b = s.trimmed;
  if (b.empty()) return q;
  q.rect = Rect{b.x0, b.y0, b.x1 - b.x0 + 1, b.y1 - b.y0 + 1};
  const raster::DepthPlane& p = s.depth;
  if (!std::isfinite(p.a0) || !std::isfinite(p.dzdx) || !std::isfinite(p.dzdy)) return q;
  const bool lower = op == FarOp::Max;  // nearer is smaller: bound the fragments' depths from below

  // Exact bound: the evaluation at the box's corner pixels.
  float exact = lower ? 1.0f : 0.0f;
  for (const int x : {b.x0, b.x1})
    for (const int y : {b.y0, b.y1}) {
      const float z = p.at(x, y, fused_interpolation);
      if (std::isnan(z)) return q;
      exact = lower ? std::min(exact, z) : std::max(exact, z);
    }

  // Tight bound: the exact plane at the snapped vertices (pixel-index units: fixed / 256 is the
  // coordinate whose integer values are pixel centres, as DepthPlane's x and y), minus rounding.
  const double a0 = p.a0, dzdx = p.dzdx, dzdy = p.dzdy;
  double extreme = lower ? INFINITY : -INFINITY;
  for (const geometry::WindowVertex& v : w.v) {
    const double x = static_cast<double>(raster::snap_to_subpixel(v.x)) / raster::kSubpixelOne;
    const double y = static_cast<double>(raster::snap_to_subpixel(v.y)) / raster::kSubpixelOne;
    const double z = a0 + dzdx * x + dzdy * y;
    extreme = lower ? std::min(extreme, z) : std::max(extreme, z);
  }
  const double xmax = std::max(std::abs(static_cast<double>(b.x0)), std::abs(static_cast<double>(b.x1)));
  const double ymax = std::max(std::abs(static_cast<double>(b.y0)), std::abs(static_cast<double>(b.y1)));
  const double slack = kPlaneRounding * (std::abs(a0) + std::abs(dzdx) * xmax + std::abs(dzdy) * ymax);
  double tight = std::clamp(lower ? extreme - slack : extreme + slack, 0.0, 1.0);
  if (!std::isfinite(tight)) tight = lower ? 0.0 : 1.0;
  auto tight_f = static_cast<float>(tight);  // rounded to nearest: step back toward the eye if it moved away
  if (lower && static_cast<double>(tight_f) > tight) tight_f = std::nextafter(tight_f, 0.0f);
  if (!lower && static_cast<double>(tight_f) < tight) tight_f = std::nextafter(tight_f, 1.0f);

  q.nearest = lower ? std::max(exact, tight_f) : std::min(exact, tight_f);
  q.testable = true;
  return q;
}

}  // namespace nbsim::cull

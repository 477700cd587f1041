// RasterPath: geometry -> setup -> rasterizer -> stencil and early depth test for one draw; see raster_path.h.
#include "model/raster/raster_path.h"

#include <string>

#include "model/common/error.h"

namespace nbsim::raster {

namespace {

geometry::GeometryConfig geometry_config(const RasterPathConfig& c) {
  geometry::GeometryConfig g;
  g.width_px = c.width_px;
  g.height_px = c.height_px;
  g.batch_triangles = c.batch_triangles;
  g.fused_viewport = c.fused_viewport;
  return g;
}

DepthImage& check_size(const RasterPathConfig& config, DepthImage& depth) {
  if (depth.width != config.width_px || depth.height != config.height_px ||
      depth.texels.size() != static_cast<std::size_t>(depth.width) * static_cast<std::size_t>(depth.height))
    throw InputError("raster path: depth buffer " + std::to_string(depth.width) + "x" + std::to_string(depth.height) +
                     " does not match the render target " + std::to_string(config.width_px) + "x" +
                     std::to_string(config.height_px));
  return depth;
}

}  // namespace

DrawCounters& DrawCounters::operator+=(const DrawCounters& o) {
  geometry += o.geometry;
  setup += o.setup;
  tiles += o.tiles;
  depth += o.depth;
  stencil += o.stencil;
  return *this;
}

RasterPath::RasterPath(const RasterPathConfig& config, DepthImage& depth) : RasterPath(config, depth, nullptr) {}

RasterPath::RasterPath(const RasterPathConfig& config, DepthImage& depth, StencilImage& stencil)
    : RasterPath(config, depth, &stencil) {}

RasterPath::RasterPath(const RasterPathConfig& config, DepthImage& depth, StencilImage* stencil)
    : config_(config),
      geometry_(geometry_config(config)),
      setup_(SetupConfig{config.width_px, config.height_px}),
      point_setup_(SetupConfig{config.width_px, config.height_px}),
      rasterizer_(config.width_px, config.height_px),
      own_stencil_(stencil ? nullptr : std::make_unique<StencilImage>(check_size(config, depth).width, depth.height, 0)),
      test_(check_size(config, depth), stencil ? *stencil : *own_stencil_, config.fused_interpolation, config.depth_format) {}

DrawCounters RasterPath::draw(std::span<const geometry::ClipPosition> clip_positions, const DrawState& state) {
  DrawCounters k;
  triangles_.clear();
  geometry_.process(clip_positions, state.geometry, triangles_, k.geometry);
  SetupTriangle t;
  for (const geometry::WindowTriangle& w : triangles_) {
    if (setup_.setup(w, state.geometry.face, t, k.setup) != SetupResult::Accepted) continue;
    rasterizer_.rasterize(t, k.tiles, [&](int x, int y, std::uint16_t mask) {
      test_.test_block(t.depth, t.front_facing, x, y, mask, state.depth, state.stencil, k.depth, k.stencil);
    });
  }
  return k;
}

DrawCounters RasterPath::draw_points(std::span<const geometry::ClipPosition> clip_positions,
                                     std::span<const float> point_sizes, const DrawState& state) {
  DrawCounters k;
  points_.clear();
  geometry_.process_points(clip_positions, point_sizes, state.geometry, points_, k.geometry);
  SetupTriangle t;
  for (const geometry::WindowPoint& p : points_) {
    if (point_setup_.setup(p, t, k.setup) != SetupResult::Accepted) continue;
    rasterizer_.rasterize(t, k.tiles, [&](int x, int y, std::uint16_t mask) {
      test_.test_block(t.depth, t.front_facing, x, y, mask, state.depth, state.stencil, k.depth, k.stencil);
    });
  }
  return k;
}

}  // namespace nbsim::raster

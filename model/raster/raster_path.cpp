// RasterPath: geometry -> setup -> rasterizer -> stencil and early depth test for one draw; see raster_path.h.
#include "model/raster/raster_path.h"

#include <algorithm>
#include <cstring>
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
  g.flip_y = c.window_framebuffer;
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
      setup_(SetupConfig{config.width_px, config.height_px, config.window_framebuffer}),
      point_setup_(SetupConfig{config.width_px, config.height_px}),
      rasterizer_(config.width_px, config.height_px),
      own_stencil_(stencil ? nullptr : std::make_unique<StencilImage>(check_size(config, depth).width, depth.height, 0)),
      test_(check_size(config, depth), stencil ? *stencil : *own_stencil_, config.fused_interpolation, config.depth_format) {}

namespace {

bool same_state(const geometry::GeometryState& a, const geometry::GeometryState& b) noexcept {
  return a.clip == b.clip && a.face.cull == b.face.cull && a.face.front_ccw == b.face.front_ccw && a.depth_clamp == b.depth_clamp;
}

bool same_config(const RasterPathConfig& a, const RasterPathConfig& b) noexcept {
  return a.width_px == b.width_px && a.height_px == b.height_px && a.batch_triangles == b.batch_triangles &&
         a.fused_viewport == b.fused_viewport && a.fused_interpolation == b.fused_interpolation && a.depth_format == b.depth_format;
}

bool same_positions(std::span<const geometry::ClipPosition> a, const std::vector<geometry::ClipPosition>& b) noexcept {
  // Bit-identical (a NaN equals itself here, -0.0 differs from +0.0): memcmp of the floats.
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(geometry::ClipPosition)) == 0);
}

}  // namespace

DrawState draw_state(const scene::DepthState& t) {
  DrawState s;
  s.geometry.clip = static_cast<geometry::ClipControl>(t.clip);
  s.geometry.face.cull = static_cast<geometry::CullFace>(t.cull);
  s.geometry.face.front_ccw = t.front_ccw;
  s.geometry.depth_clamp = t.depth_clamp;
  s.depth.func = static_cast<DepthFunc>(t.func);
  s.depth.test = t.test;
  s.depth.write = t.write;
  return s;
}

DrawCounters RasterPath::draw(std::span<const geometry::ClipPosition> clip_positions, const DrawState& state) {
  return draw(clip_positions, state, {});
}

DrawCounters RasterPath::draw(std::span<const geometry::ClipPosition> clip_positions, const DrawState& state, std::span<const char> skip) {
  DrawCounters k;
  int x0 = config_.width_px, y0 = config_.height_px, x1 = 0, y1 = 0;
  const auto test = [&](const DepthPlane& plane, bool front, int x, int y, std::uint16_t mask) {
    const std::uint64_t before = k.depth.written;
    test_.test_block(plane, front, x, y, mask, state.depth, state.stencil, k.depth, k.stencil);
    if (k.depth.written != before) x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x + 4), y1 = std::max(y1, y + 4);
  };
  const auto finish = [&] {
    x1 = std::min(x1, config_.width_px), y1 = std::min(y1, config_.height_px);
    written_box_ = x1 > x0 && y1 > y0 ? Rect{x0, y0, x1 - x0, y1 - y0} : Rect{};
  };
  const bool reusable = reuse_ && skip.empty();
  if (reusable && cached_ && same_state(state.geometry, cached_state_) && same_positions(clip_positions, cached_positions_)) {
    k.geometry = cached_geometry_, k.setup = cached_setup_, k.tiles = cached_tiles_;
    for (const CachedBlock& b : cached_blocks_) test(cached_planes_[b.triangle], cached_front_[b.triangle] != 0, b.x, b.y, b.mask);
    finish();
    return k;
  }
  cached_ = false;
  triangles_.clear();
  geometry_.process(clip_positions, state.geometry, triangles_, k.geometry);
  if (reusable) {
    cached_planes_.clear(), cached_front_.clear(), cached_blocks_.clear();
  }
  SetupTriangle t;
  std::size_t accepted = 0;
  for (const geometry::WindowTriangle& w : triangles_) {
    if (setup_.setup(w, state.geometry.face, t, k.setup) != SetupResult::Accepted) continue;
    if (const std::size_t i = accepted++; i < skip.size() && skip[i]) continue;
    const auto triangle = static_cast<std::uint32_t>(cached_planes_.size());
    if (reusable) cached_planes_.push_back(t.depth), cached_front_.push_back(t.front_facing ? 1 : 0);
    rasterizer_.rasterize(t, k.tiles, [&](int x, int y, std::uint16_t mask) {
      if (reusable) cached_blocks_.push_back({x, y, mask, triangle});
      test(t.depth, t.front_facing, x, y, mask);
    });
  }
  if (reusable) {
    cached_ = true;
    cached_positions_.assign(clip_positions.begin(), clip_positions.end());
    cached_state_ = state.geometry;
    cached_geometry_ = k.geometry, cached_setup_ = k.setup, cached_tiles_ = k.tiles;
  }
  finish();
  return k;
}

void RasterPath::setup_only(std::span<const geometry::ClipPosition> clip_positions, const DrawState& state,
                            const std::function<void(const geometry::WindowTriangle&, const SetupTriangle&)>& each) {
  DrawCounters k;  // not reported: draw() counts the same work when the draw runs
  triangles_.clear();
  geometry_.process(clip_positions, state.geometry, triangles_, k.geometry);
  SetupTriangle t;
  for (const geometry::WindowTriangle& w : triangles_)
    if (setup_.setup(w, state.geometry.face, t, k.setup) == SetupResult::Accepted) each(w, t);
}

DrawCounters RasterPath::draw_points(std::span<const geometry::ClipPosition> clip_positions,
                                     std::span<const float> point_sizes, const DrawState& state, PointRaster* shared) {
  DrawCounters k;
  cached_ = false;
  if (shared && shared->valid && same_config(shared->config, config_) && same_state(state.geometry, shared->state) &&
      same_positions(clip_positions, shared->positions) && point_sizes.size() == shared->sizes.size() &&
      (point_sizes.empty() || std::memcmp(point_sizes.data(), shared->sizes.data(), point_sizes.size() * sizeof(float)) == 0)) {
    k.geometry = shared->geometry, k.setup = shared->setup, k.tiles = shared->tiles;
    for (const PointRaster::Block& b : shared->blocks)
      test_.test_block(shared->planes[b.point], shared->front[b.point] != 0, b.x, b.y, b.mask, state.depth, state.stencil, k.depth,
                       k.stencil);
    return k;
  }
  if (shared) {
    shared->valid = false;
    shared->planes.clear(), shared->front.clear(), shared->blocks.clear();
  }
  points_.clear();
  geometry_.process_points(clip_positions, point_sizes, state.geometry, points_, k.geometry);
  SetupTriangle t;
  for (const geometry::WindowPoint& p : points_) {
    if (point_setup_.setup(p, t, k.setup) != SetupResult::Accepted) continue;
    const auto point = static_cast<std::uint32_t>(shared ? shared->planes.size() : 0);
    if (shared) shared->planes.push_back(t.depth), shared->front.push_back(t.front_facing ? 1 : 0);
    rasterizer_.rasterize(t, k.tiles, [&](int x, int y, std::uint16_t mask) {
      if (shared) shared->blocks.push_back({x, y, mask, point});
      test_.test_block(t.depth, t.front_facing, x, y, mask, state.depth, state.stencil, k.depth, k.stencil);
    });
  }
  if (shared) {
    shared->valid = true;
    shared->config = config_;
    shared->state = state.geometry;
    shared->positions.assign(clip_positions.begin(), clip_positions.end());
    shared->sizes.assign(point_sizes.begin(), point_sizes.end());
    shared->geometry = k.geometry, shared->setup = k.setup, shared->tiles = k.tiles;
  }
  return k;
}

}  // namespace nbsim::raster

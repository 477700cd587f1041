// RasterPath: one draw from clip space to depth-tested fragments through the plain C++ cores,
// geometry (model/geometry) -> setup -> rasterizer -> stencil and early depth test (model/raster); triangle
// draws through triangle setup, point-sprite draws through point setup (point_setup.h). It is what
// the SystemC units wrap one stage at a time, and what the counter comparison replays against GL.
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "model/common/depth.h"
#include "model/common/rect.h"
#include "model/geometry/geometry.h"
#include "model/raster/depth_test.h"
#include "model/raster/point_setup.h"
#include "model/raster/rasterizer.h"
#include "model/raster/setup.h"
#include "model/raster/stencil_test.h"
#include "model/scene/frame.h"

namespace nbsim::raster {

struct RasterPathConfig {
  int width_px = 0;  // render target and viewport, 1 .. 16384
  int height_px = 0;
  int batch_triangles = 85;         // geometry::GeometryConfig::batch_triangles
  bool fused_viewport = true;       // geometry::GeometryConfig::fused_viewport
  bool fused_interpolation = true;  // EarlyDepthTest: depth plane evaluated with FMA
  DepthFormat depth_format = DepthFormat::Float32;  // Unorm24: the buffer holds llvmpipe's 24-bit depths
  // A window-system framebuffer as llvmpipe draws it (model/apps/replay.h): rows flipped in the
  // viewport transform (geometry::GeometryConfig::flip_y) and the bottom-edge fill rule
  // (SetupConfig::bottom_edge_rule). Off: an FBO, as every other technique draws into.
  bool window_framebuffer = false;
};

// The GL state of one draw that the path reads.
struct DrawState {
  geometry::GeometryState geometry;
  DepthState depth;
  StencilState stencil;  // test off: the stencil buffer is not touched
};

// The path's state for a recorded draw (its depth func, test, write, cull, winding, clip control
// and depth clamp; the stencil test off).
DrawState draw_state(const scene::DepthState& recorded);

// Everything counted for one draw (or summed over many).
struct DrawCounters {
  geometry::GeometryCounters geometry;
  SetupCounters setup;
  TileCounters tiles;
  DepthCounters depth;
  StencilCounters stencil;
  DrawCounters& operator+=(const DrawCounters& o);
};

class RasterPath {
 public:
  // `depth` is the depth buffer the draws test and write; it must be width x height and outlive
  // the path. Throws InputError for a bad size. The path owns a stencil buffer cleared to 0.
  RasterPath(const RasterPathConfig& config, DepthImage& depth);
  // The same with the caller's stencil buffer (width x height, outliving the path).
  RasterPath(const RasterPathConfig& config, DepthImage& depth, StencilImage& stencil);

  // Runs one draw (three clip positions a triangle) and returns its counters.
  DrawCounters draw(std::span<const geometry::ClipPosition> clip_positions, const DrawState& state);
  // The same, leaving out the triangles that setup accepts whose index among the accepted ones (in
  // the order setup_only() gives them) has skip[i] != 0: a per-primitive cull before the tile walk.
  // Indices past skip's end are drawn. The skipped triangles count in geometry and setup, not after.
  DrawCounters draw(std::span<const geometry::ClipPosition> clip_positions, const DrawState& state, std::span<const char> skip);
  // Geometry and setup only (no tile walk, no test, nothing written): calls `each` with every
  // triangle setup accepts, in the order draw() rasterizes them, and its window triangle. What a
  // depth query of a draw, or of each of its triangles, is built from before it is drawn.
  void setup_only(std::span<const geometry::ClipPosition> clip_positions, const DrawState& state,
                  const std::function<void(const geometry::WindowTriangle&, const SetupTriangle&)>& each);
  // The 4x4 blocks the last triangle draw wrote depth in, as one rectangle clipped to the target
  // (empty: it wrote none): what the depth unit reports as the draw's dirty rectangle.
  const Rect& written_box() const noexcept { return written_box_; }
  // A point draw's rasterization kept to be tested again into another path of the same
  // configuration (two render targets drawn with the same points): its inputs, counters, each
  // accepted point's depth plane and its blocks in rasterization order. Filled by draw_points.
  struct PointRaster {
    bool valid = false;
    RasterPathConfig config;
    geometry::GeometryState state;
    std::vector<geometry::ClipPosition> positions;
    std::vector<float> sizes;
    geometry::GeometryCounters geometry;
    SetupCounters setup;
    TileCounters tiles;
    std::vector<DepthPlane> planes;
    std::vector<std::uint8_t> front;
    struct Block {
      std::int32_t x, y;
      std::uint16_t mask;
      std::uint32_t point;
    };
    std::vector<Block> blocks;
  };

  // Runs one point-sprite draw (one clip position and one gl_PointSize a point). Throws
  // InputError when the counts differ or a position or size is NaN or infinite.
  // With `shared` (a host-speed option, counts never depend on it): when it holds the
  // rasterization of bit-identical points, sizes and geometry state by a path of the same
  // configuration, only the depth (and stencil) tests run, over its blocks in the same order, with
  // its geometry, setup and tile counters; otherwise the draw runs in full and fills it.
  DrawCounters draw_points(std::span<const geometry::ClipPosition> clip_positions, std::span<const float> point_sizes,
                           const DrawState& state, PointRaster* shared = nullptr);

  // Rasterization reuse, a host-speed option (counts never depend on it): when on, a triangle draw
  // whose clip positions and geometry state are bit-identical to the previous triangle draw's skips
  // clipping, setup and the tile walk and runs the depth (and stencil) tests over the previous
  // draw's blocks again, in the same order, with the same geometry, setup and tile counters. The
  // depth passes of a peel draw one mesh per pass. Off by default; a points draw forgets the cache.
  void set_reuse_rasterization(bool on) noexcept {
    reuse_ = on;
    cached_ = false;
  }

  const RasterPathConfig& config() const noexcept { return config_; }
  DepthImage& depth() noexcept { return test_.depth(); }
  StencilImage& stencil() noexcept { return test_.stencil(); }

 private:
  RasterPath(const RasterPathConfig& config, DepthImage& depth, StencilImage* stencil);
  RasterPathConfig config_;
  geometry::GeometryStage geometry_;
  TriangleSetup setup_;
  PointSetup point_setup_;
  Rasterizer rasterizer_;
  std::unique_ptr<StencilImage> own_stencil_;  // when the caller gave none
  DepthStencilTest test_;
  std::vector<geometry::WindowTriangle> triangles_;  // reused from draw to draw
  Rect written_box_;
  std::vector<geometry::WindowPoint> points_;        // likewise
  // The previous triangle draw's rasterization (set_reuse_rasterization): its inputs, counters,
  // each accepted triangle's depth plane and facing, and its blocks in rasterization order.
  struct CachedBlock {
    std::int32_t x, y;
    std::uint16_t mask;
    std::uint32_t triangle;
  };
  bool reuse_ = false, cached_ = false;
  std::vector<geometry::ClipPosition> cached_positions_;
  geometry::GeometryState cached_state_;
  geometry::GeometryCounters cached_geometry_;
  SetupCounters cached_setup_;
  TileCounters cached_tiles_;
  std::vector<DepthPlane> cached_planes_;
  std::vector<std::uint8_t> cached_front_;
  std::vector<CachedBlock> cached_blocks_;
};

}  // namespace nbsim::raster

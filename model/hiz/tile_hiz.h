// Single-level tile Hi-Z, the culling structure shipped GPUs have: one farthest depth per
// tile_px x tile_px screen tile (8x8 by default), kept up to date from depth-buffer changes and
// queried for a rectangle by reading every tile it touches. Plain C++ core of a baseline; no
// SystemC. Edge tiles hold the farthest of their pixels inside the image, so answers stay
// conservative at any image size; values are stored in the storage format, rounded toward far.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "model/common/depth.h"
#include "model/common/rect.h"
#include "model/common/storage.h"
#include "model/nbuffer/nbuffer.h"  // PixelWrite

namespace nbsim {

struct TileHiZConfig {
  FarOp op = FarOp::Max;
  StorageFormat format = StorageFormat::F32;
  int tile_px = 8;  // tile side in pixels, 1 .. 256; tunable (8x8 as on shipped GPUs)
};

// Work of one update.
struct TileHiZUpdate {
  std::uint64_t tiles_recomputed = 0;  // tiles whose farthest depth was recomputed
  std::uint64_t tiles_changed = 0;     // of those, tiles whose stored value changed
  std::uint64_t pixels_read = 0;       // depth pixels read to recompute them
};

struct TileHiZAnswer {
  float value = 0.0f;     // farthest depth over the tiles read (far limit when offscreen)
  bool hidden = false;    // nearest depth strictly farther than value
  bool offscreen = true;  // empty rectangle or none of it inside the image: nothing read
  int lookups = 0;        // tiles read: every tile the rectangle touches
  Rect tiles;             // those tiles, in tile coordinates
};

class TileHiZ {
 public:
  // A tile Hi-Z for a width_px x height_px depth buffer cleared to the far limit. Throws
  // InputError for a size below 1x1 or a tile size outside 1 .. 256.
  TileHiZ(int width_px, int height_px, TileHiZConfig config = {});

  // Recomputes every tile from `depth` (same size as the depth buffer).
  TileHiZUpdate build(const DepthImage& depth);
  // The pixels of `depth` inside `dirty` changed: recomputes the tiles they touch.
  TileHiZUpdate update(const DepthImage& depth, const Rect& dirty);
  // `depth` already holds the writes: recomputes the tiles they touch (each once). Throws
  // InputError (and changes nothing) when a write lies outside the image.
  TileHiZUpdate update(const DepthImage& depth, std::span<const PixelWrite> writes);
  // The whole depth buffer was cleared to `depth`.
  TileHiZUpdate clear(float depth);

  // Reads every tile the rectangle (clipped to the image) touches.
  TileHiZAnswer query(const Rect& r, float nearest_depth) const;

  int tiles_x() const noexcept { return tiles_x_; }
  int tiles_y() const noexcept { return tiles_y_; }
  float tile(int tx, int ty) const noexcept {
    return tiles_[static_cast<std::size_t>(ty) * static_cast<std::size_t>(tiles_x_) + static_cast<std::size_t>(tx)];
  }
  int width_px() const noexcept { return width_; }
  int height_px() const noexcept { return height_; }
  const TileHiZConfig& config() const noexcept { return config_; }
  long long storage_bytes() const noexcept;

 private:
  // Recomputes tile (tx, ty); returns whether its value changed.
  bool recompute(const DepthImage& depth, int tx, int ty, TileHiZUpdate& u);

  TileHiZConfig config_;
  int width_ = 0, height_ = 0, tiles_x_ = 0, tiles_y_ = 0;
  std::vector<float> tiles_;
  std::vector<std::uint32_t> stamp_;  // per tile, dedups the tiles of one write batch
  std::uint32_t epoch_ = 0;
};

}  // namespace nbsim

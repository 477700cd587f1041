// Single-level tile Hi-Z: tile maintenance and rectangle queries; see tile_hiz.h.
#include "model/hiz/tile_hiz.h"

#include <fmt/format.h>

#include <algorithm>

#include "model/common/error.h"

namespace nbsim {

TileHiZ::TileHiZ(int width_px, int height_px, TileHiZConfig config)
    : config_(config), width_(width_px), height_(height_px) {
  if (width_px < 1 || height_px < 1)
    throw InputError(fmt::format("tile Hi-Z needs a depth buffer of at least 1x1, got {}x{}", width_px, height_px));
  if (config.tile_px < 1 || config.tile_px > 256)
    throw InputError(fmt::format("hiz.tile_px must be 1 to 256, got {}", config.tile_px));
  tiles_x_ = (width_px + config.tile_px - 1) / config.tile_px;
  tiles_y_ = (height_px + config.tile_px - 1) / config.tile_px;
  tiles_.assign(static_cast<std::size_t>(tiles_x_) * static_cast<std::size_t>(tiles_y_), far_limit(config.op));
  stamp_.assign(tiles_.size(), 0);
}

bool TileHiZ::recompute(const DepthImage& depth, int tx, int ty, TileHiZUpdate& u) {
  const int t = config_.tile_px;
  const int x1 = std::min((tx + 1) * t, width_), y1 = std::min((ty + 1) * t, height_);
  float v = neutral_depth(config_.op);
  for (int y = ty * t; y < y1; ++y)
    for (int x = tx * t; x < x1; ++x) v = farther(config_.op, v, depth.at(x, y));
  v = quantize_toward_far(v, config_.format, config_.op);
  u.pixels_read += static_cast<std::uint64_t>(x1 - tx * t) * static_cast<std::uint64_t>(y1 - ty * t);
  ++u.tiles_recomputed;
  float& stored =
      tiles_[static_cast<std::size_t>(ty) * static_cast<std::size_t>(tiles_x_) + static_cast<std::size_t>(tx)];
  if (stored == v) return false;
  stored = v;
  ++u.tiles_changed;
  return true;
}

TileHiZUpdate TileHiZ::build(const DepthImage& depth) { return update(depth, Rect{0, 0, width_, height_}); }

TileHiZUpdate TileHiZ::update(const DepthImage& depth, const Rect& dirty) {
  NBSIM_CHECK(depth.width == width_ && depth.height == height_, "depth image size differs from the tile Hi-Z's");
  TileHiZUpdate u;
  const Rect c = clip(dirty, width_, height_);
  if (c.empty()) return u;
  const int t = config_.tile_px;
  for (int ty = c.y / t; ty <= (c.y1() - 1) / t; ++ty)
    for (int tx = c.x / t; tx <= (c.x1() - 1) / t; ++tx) recompute(depth, tx, ty, u);
  return u;
}

TileHiZUpdate TileHiZ::update(const DepthImage& depth, std::span<const PixelWrite> writes) {
  NBSIM_CHECK(depth.width == width_ && depth.height == height_, "depth image size differs from the tile Hi-Z's");
  for (const PixelWrite& w : writes)
    if (w.x < 0 || w.y < 0 || w.x >= width_ || w.y >= height_)
      throw InputError(
          fmt::format("tile Hi-Z: pixel write at ({}, {}) outside the {}x{} image", w.x, w.y, width_, height_));
  TileHiZUpdate u;
  if (++epoch_ == 0) std::fill(stamp_.begin(), stamp_.end(), 0u), epoch_ = 1;
  const int t = config_.tile_px;
  for (const PixelWrite& w : writes) {
    const int tx = w.x / t, ty = w.y / t;
    std::uint32_t& s =
        stamp_[static_cast<std::size_t>(ty) * static_cast<std::size_t>(tiles_x_) + static_cast<std::size_t>(tx)];
    if (s == epoch_) continue;
    s = epoch_;
    recompute(depth, tx, ty, u);
  }
  return u;
}

TileHiZUpdate TileHiZ::clear(float depth) {
  const float v = quantize_toward_far(depth, config_.format, config_.op);
  TileHiZUpdate u;
  for (float& tile : tiles_) {
    u.tiles_changed += tile != v ? 1 : 0;
    tile = v;
  }
  u.tiles_recomputed = tiles_.size();
  return u;
}

TileHiZAnswer TileHiZ::query(const Rect& r, float nearest_depth) const {
  TileHiZAnswer a;
  a.value = far_limit(config_.op);
  const Rect c = clip(r, width_, height_);
  if (c.empty()) return a;
  a.offscreen = false;
  const int t = config_.tile_px;
  const int tx0 = c.x / t, ty0 = c.y / t, tx1 = (c.x1() - 1) / t, ty1 = (c.y1() - 1) / t;
  a.tiles = {tx0, ty0, tx1 - tx0 + 1, ty1 - ty0 + 1};
  a.value = neutral_depth(config_.op);
  for (int ty = ty0; ty <= ty1; ++ty)
    for (int tx = tx0; tx <= tx1; ++tx) a.value = farther(config_.op, a.value, tile(tx, ty));
  a.lookups = static_cast<int>(a.tiles.area());
  a.hidden = config_.op == FarOp::Max ? nearest_depth > a.value : nearest_depth < a.value;
  return a;
}

long long TileHiZ::storage_bytes() const noexcept {
  return static_cast<long long>(tiles_.size()) * nbsim::storage_bytes(config_.format);
}

}  // namespace nbsim

// Rasterizer: the tile-based traversal of a set-up triangle (model/raster/setup.h) into 4x4
// blocks of covered pixels for the depth test (model/raster/depth_test.h), with llvmpipe's
// hierarchy and its per-level block classes.
//
// Traversal (lp_setup_tri.c lp_setup_bin_triangle, lp_rast_tri.c, lp_rast_tri_tmp.h):
// - a triangle whose box stays inside one 64x64 tile is rasterized in that tile: as a single
//   4x4 stamp when the box fits one (TRI_3_4), as a 16x16 block of 4x4 stamps when it fits one
//   (TRI_3_16, TRI_4_16), otherwise by the 16x16 -> 4x4 hierarchy below;
// - a larger triangle is binned over the 64x64 tiles of its box: a tile is empty when one plane
//   rejects it (c + 64 eo < 0), full when every plane accepts it (c + 64 ei - 1 >= 0), else
//   partial; along a row, the first empty tile after a covered one ends the row;
// - a partial tile is split into 16 blocks of 16x16 and those into 4x4 blocks with the same
//   three classes; a partial 4x4 block is tested pixel by pixel (E > 0 for every plane).
// The pixel set is exactly {pixels of the visited tiles : E > 0 for all planes}; the classes
// only decide where the work goes, and they are what TileCounters counts.
#pragma once

#include <bit>
#include <cstdint>

#include "model/raster/setup.h"

namespace nbsim::raster {

// Blocks and triangles per class, as llvmpipe's LP_COUNT counters name them (nr_empty_64,
// nr_partially_covered_16, ...). Added to, never reset, by the rasterizer.
struct TileCounters {
  std::uint64_t tiles_empty = 0;  // 64x64 tiles of a binned triangle's box
  std::uint64_t tiles_partial = 0;
  std::uint64_t tiles_full = 0;
  std::uint64_t blocks16_empty = 0;  // 16x16 blocks of partial tiles
  std::uint64_t blocks16_partial = 0;
  std::uint64_t blocks16_full = 0;
  std::uint64_t blocks4_empty = 0;    // 4x4 blocks of partial 16x16 blocks and of TRI_16 commands
  std::uint64_t blocks4_partial = 0;  // tested pixel by pixel
  std::uint64_t blocks4_full = 0;
  std::uint64_t tri_stamp4 = 0;   // triangles inside one 4x4 stamp
  std::uint64_t tri_block16 = 0;  // inside one 16x16 block
  std::uint64_t tri_tile = 0;     // inside one tile
  std::uint64_t tri_binned = 0;   // over several tiles
  TileCounters& operator+=(const TileCounters& o);
};

class Rasterizer {
 public:
  // Throws InputError for a render target outside 1x1 .. 16384x16384.
  Rasterizer(int width_px, int height_px);

  // Calls visit(x, y, mask) for every 4x4 block with covered pixels: (x, y) is the block's
  // lower-left pixel, bit (i + 4 j) of the 16-bit mask is pixel (x + i, y + j). Every covered
  // pixel is reported exactly once; none lies outside the render target.
  template <class Visit>
  void rasterize(const SetupTriangle& t, TileCounters& counters, Visit&& visit) const;

  int width_px() const noexcept { return width_; }
  int height_px() const noexcept { return height_; }

  // The coverage mask of the 4x4 block at (x, y) against planes[0 .. n).
  static std::uint16_t block_mask(const EdgePlane* planes, int n, int x, int y) noexcept;

 private:
  template <class Visit>
  void tile(const SetupTriangle& t, unsigned plane_mask, int x, int y, TileCounters& k, Visit& visit) const;
  template <class Visit>
  void block16(const EdgePlane* planes, int n, int x, int y, TileCounters& k, Visit& visit) const;
  template <class Visit>
  void stamps16(const SetupTriangle& t, int x, int y, TileCounters& k, Visit& visit) const;

  int width_;
  int height_;
};

// ---- implementation ---------------------------------------------------------------------------

// 1 when v < 0, else 0: the sign bit, without a branch (which side of an edge a pixel falls on
// follows the triangle, not a pattern a branch predictor could learn).
constexpr unsigned negative(std::int64_t v) noexcept { return static_cast<unsigned>(static_cast<std::uint64_t>(v) >> 63); }

inline std::uint16_t Rasterizer::block_mask(const EdgePlane* planes, int n, int x, int y) noexcept {
  std::uint32_t mask = 0xffff;
  for (int j = 0; j < n; ++j) {
    const EdgePlane& p = planes[j];
    const std::int64_t c0 = p.at(x, y) - 1;  // inside: c - 1 >= 0
    std::uint32_t out = 0;
    for (int row = 0; row < 4; ++row) {
      const std::int64_t cr = c0 + static_cast<std::int64_t>(p.dcdy) * row;
      for (int col = 0; col < 4; ++col) out |= negative(cr - static_cast<std::int64_t>(p.dcdx) * col) << (row * 4 + col);
    }
    mask &= ~out;
  }
  return static_cast<std::uint16_t>(mask);
}

// Classifies the 16 sub-blocks (a 4x4 grid, each `sub` pixels wide) of the block at (x, y)
// against the planes: bits of `out` are rejected by some plane, bits of `in` accepted by all.
namespace detail {
inline void classify16(const EdgePlane* planes, int n, int x, int y, int sub, unsigned& out, unsigned& in) {
  unsigned outmask = 0, partmask = 0;
  for (int j = 0; j < n; ++j) {
    const EdgePlane& p = planes[j];
    const std::int64_t c = p.at(x, y);
    const std::int64_t cox = p.eo * sub;
    const std::int64_t cio = p.ei() * sub - 1;
    const std::int64_t stepx = -static_cast<std::int64_t>(p.dcdx) * sub;
    const std::int64_t stepy = static_cast<std::int64_t>(p.dcdy) * sub;
    for (int i = 0; i < 16; ++i) {
      const std::int64_t ci = c + stepx * (i & 3) + stepy * (i >> 2);
      outmask |= negative(ci + cox) << i;
      partmask |= negative(ci + cio) << i;
    }
  }
  out = outmask;
  in = ~partmask & 0xffffu;
}
}  // namespace detail

template <class Visit>
void Rasterizer::block16(const EdgePlane* planes, int n, int x, int y, TileCounters& k, Visit& visit) const {
  unsigned out = 0, in = 0;
  detail::classify16(planes, n, x, y, 4, out, in);
  if (out == 0xffffu) return;
  unsigned partial = ~in & ~out & 0xffffu;
  k.blocks4_empty += static_cast<std::uint64_t>(std::popcount(0xffffu & ~(partial | in)));
  while (partial != 0) {
    const int i = std::countr_zero(partial);
    partial &= partial - 1;
    k.blocks4_partial += 1;
    const int px = x + (i & 3) * 4, py = y + (i >> 2) * 4;
    const std::uint16_t m = block_mask(planes, n, px, py);
    if (m != 0) visit(px, py, m);
  }
  while (in != 0) {
    const int i = std::countr_zero(in);
    in &= in - 1;
    k.blocks4_full += 1;
    visit(x + (i & 3) * 4, y + (i >> 2) * 4, std::uint16_t{0xffff});
  }
}

template <class Visit>
void Rasterizer::tile(const SetupTriangle& t, unsigned plane_mask, int x, int y, TileCounters& k, Visit& visit) const {
  EdgePlane planes[kMaxPlanes];
  int n = 0;
  for (unsigned m = plane_mask; m != 0; m &= m - 1)
    planes[n++] = t.planes[static_cast<std::size_t>(std::countr_zero(m))];
  unsigned out = 0, in = 0;
  detail::classify16(planes, n, x, y, 16, out, in);
  if (out == 0xffffu) return;
  unsigned partial = ~in & ~out & 0xffffu;
  k.blocks16_empty += static_cast<std::uint64_t>(std::popcount(0xffffu & ~(partial | in)));
  while (partial != 0) {
    const int i = std::countr_zero(partial);
    partial &= partial - 1;
    k.blocks16_partial += 1;
    block16(planes, n, x + (i & 3) * 16, y + (i >> 2) * 16, k, visit);
  }
  while (in != 0) {
    const int i = std::countr_zero(in);
    in &= in - 1;
    k.blocks16_full += 1;
    const int bx = x + (i & 3) * 16, by = y + (i >> 2) * 16;
    for (int j = 0; j < 16; ++j) visit(bx + (j & 3) * 4, by + (j >> 2) * 4, std::uint16_t{0xffff});
  }
}

template <class Visit>
void Rasterizer::stamps16(const SetupTriangle& t, int x, int y, TileCounters& k, Visit& visit) const {
  // TRI_16: reject 4x4 stamps with c + 4 eo < 0, test the others pixel by pixel.
  const int n = t.num_planes;
  for (int i = 0; i < 16; ++i) {
    const int px = x + (i & 3) * 4, py = y + (i >> 2) * 4;
    bool rejected = false;
    for (int j = 0; j < n && !rejected; ++j) {
      const EdgePlane& p = t.planes[static_cast<std::size_t>(j)];
      rejected = p.at(px, py) + p.eo * 4 < 0;
    }
    if (rejected) {
      k.blocks4_empty += 1;
      continue;
    }
    k.blocks4_partial += 1;
    const std::uint16_t m = block_mask(t.planes.data(), n, px, py);
    if (m != 0) visit(px, py, m);
  }
}

template <class Visit>
void Rasterizer::rasterize(const SetupTriangle& t, TileCounters& k, Visit&& visit) const {
  const PixelBox& b = t.bbox;
  const auto floor_pot = [](unsigned v) { return v == 0 ? 0u : std::bit_floor(v); };
  const unsigned dx = floor_pot(static_cast<unsigned>((b.x0 ^ b.x1) | (b.y0 ^ b.y1)));
  const unsigned sz = floor_pot(static_cast<unsigned>((b.x1 - (b.x0 & ~3)) | (b.y1 - (b.y0 & ~3))));
  const unsigned all_planes = (1u << t.num_planes) - 1;

  if (dx < static_cast<unsigned>(kTilePx)) {
    const int tx = (b.x0 / kTilePx) * kTilePx, ty = (b.y0 / kTilePx) * kTilePx;
    int px = b.x0 & (kTilePx - 1) & ~3, py = b.y0 & (kTilePx - 1) & ~3;
    if (t.num_planes == 3 && sz < 4) {
      k.tri_stamp4 += 1;
      const std::uint16_t m = block_mask(t.planes.data(), 3, tx + px, ty + py);
      if (m != 0) visit(tx + px, ty + py, m);
      return;
    }
    if ((t.num_planes == 3 || t.num_planes == 4) && sz < 16) {
      k.tri_block16 += 1;
      px = std::min(px, kTilePx - 16);
      py = std::min(py, kTilePx - 16);
      stamps16(t, tx + px, ty + py, k, visit);
      return;
    }
    k.tri_tile += 1;
    tile(t, all_planes, tx, ty, k, visit);
    return;
  }

  k.tri_binned += 1;
  const PixelBox& tb = t.trimmed;
  const int ix0 = tb.x0 / kTilePx, iy0 = tb.y0 / kTilePx, ix1 = tb.x1 / kTilePx, iy1 = tb.y1 / kTilePx;
  const int n = t.num_planes;
  for (int iy = iy0; iy <= iy1; ++iy) {
    bool in_row = false;
    for (int ix = ix0; ix <= ix1; ++ix) {
      const int x = ix * kTilePx, y = iy * kTilePx;
      bool out = false;
      unsigned partial = 0;
      for (int j = 0; j < n; ++j) {
        const EdgePlane& p = t.planes[static_cast<std::size_t>(j)];
        const std::int64_t c = p.at(x, y);
        if (c + p.eo * kTilePx < 0) out = true;
        if (c + p.ei() * kTilePx - 1 < 0) partial |= 1u << j;
      }
      if (out) {
        if (in_row) break;  // leaving the triangle: the rest of the row is empty
        k.tiles_empty += 1;
      } else if (partial != 0) {
        in_row = true;
        k.tiles_partial += 1;
        tile(t, partial, x, y, k, visit);
      } else {
        in_row = true;
        k.tiles_full += 1;
        for (int j = 0; j < (kTilePx / 4) * (kTilePx / 4); ++j)
          visit(x + (j % (kTilePx / 4)) * 4, y + (j / (kTilePx / 4)) * 4, std::uint16_t{0xffff});
      }
    }
  }
}

}  // namespace nbsim::raster

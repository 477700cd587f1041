// Rasterizer: construction and counters; the traversal itself is a template in rasterizer.h so
// that the per-block consumer (the depth test) inlines into it.
#include "model/raster/rasterizer.h"

#include <string>

#include "model/common/error.h"

namespace nbsim::raster {

TileCounters& TileCounters::operator+=(const TileCounters& o) {
  tiles_empty += o.tiles_empty;
  tiles_partial += o.tiles_partial;
  tiles_full += o.tiles_full;
  blocks16_empty += o.blocks16_empty;
  blocks16_partial += o.blocks16_partial;
  blocks16_full += o.blocks16_full;
  blocks4_empty += o.blocks4_empty;
  blocks4_partial += o.blocks4_partial;
  blocks4_full += o.blocks4_full;
  tri_stamp4 += o.tri_stamp4;
  tri_block16 += o.tri_block16;
  tri_tile += o.tri_tile;
  tri_binned += o.tri_binned;
  return *this;
}

Rasterizer::Rasterizer(int width_px, int height_px) : width_(width_px), height_(height_px) {
  if (width_px < 1 || width_px > 16384 || height_px < 1 || height_px > 16384)
    throw InputError("rasterizer: render target " + std::to_string(width_px) + "x" + std::to_string(height_px) +
                     " is outside 1x1 .. 16384x16384");
}

}  // namespace nbsim::raster

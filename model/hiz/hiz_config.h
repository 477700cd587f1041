// Configuration of the Hi-Z baselines (config keys "hiz.<field>"): the single-level tile Hi-Z
// (tile_hiz.h) and the Hi-Z pyramid (pyramid.h). A run uses one of them, so they share one group.
// The depth convention (FarOp) comes from the trace, not from the config.
#pragma once

#include <string>

#include "model/common/depth.h"
#include "model/config/schema.h"
#include "model/hiz/pyramid.h"
#include "model/hiz/tile_hiz.h"

namespace nbsim {

struct HiZUnitConfig {
  int tile_px = 8;             // tile Hi-Z: tile side in pixels, 1 .. 256 (8x8 as on shipped GPUs)
  std::string format = "f32";  // storage of both baselines: f32, u24 (as D24X8) or u16, rounded toward far

  // Declares "hiz.tile_px" and "hiz.format", bound to `c`.
  static void describe(config::Schema& schema, HiZUnitConfig& c);
  // Throws InputError naming the key when a value is outside its limits.
  void validate() const;
  // The cores' configs (call after validate()).
  TileHiZConfig tile(FarOp op) const;
  HiZConfig pyramid(FarOp op) const;
};

}  // namespace nbsim

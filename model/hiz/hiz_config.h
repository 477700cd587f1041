// Configuration of the Hi-Z baselines (config keys "<instance>.<field>", "hiz.<field>" for
// occlusion culling's): the single-level tile Hi-Z (tile_hiz.h) and the Hi-Z pyramid (pyramid.h).
// A run uses one of them, so they share one group.
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
  // Timing of the Hi-Z units (model/query/units.h); design guesses, tunable.
  double lookups_per_cycle = 4.0;       // texels compared a cycle (as the N-buffer's four)
  int lookup_latency_cycles = 8;        // per query, or per batch of per-triangle queries
  double build_texels_per_cycle = 16.0; // texels recomputed a cycle (tile updates, pyramid rebuild)
  int build_latency_cycles = 16;        // per tile update batch or pyramid rebuild

  // The keys' prefix: the instance's name (pipeline/sim/programs.h), "hiz" for occlusion
  // culling's. Set by describe(); messages name the keys with it.
  std::string key_prefix = "hiz";

  // Declares "<prefix>.<field>", bound to `c`; for prefix "hiz", setting "cull.hiz_<field>" is
  // refused with a message naming "hiz.<field>".
  static void describe(config::Schema& schema, HiZUnitConfig& c, const std::string& prefix = "hiz");
  // Throws InputError naming the key when a value is outside its limits.
  void validate() const;
  // The cores' configs (call after validate()).
  TileHiZConfig tile(FarOp op) const;
  HiZConfig pyramid(FarOp op) const;
};

}  // namespace nbsim

// Configuration of the Hi-Z baselines; see hiz_config.h.
#include "model/hiz/hiz_config.h"

#include <fmt/format.h>

#include "model/common/error.h"
#include "model/common/names.h"

namespace nbsim {

namespace {
constexpr int kMaxTilePx = 256;
}

void HiZUnitConfig::describe(config::Schema& s, HiZUnitConfig& c, const std::string& prefix) {
  c.key_prefix = prefix;
  const auto key = [&prefix](const char* field) { return prefix + "." + field; };
  s.add(key("tile_px"), c.tile_px, "pixels", "tile Hi-Z: side of the square screen tile holding one farthest depth", 1,
        kMaxTilePx);
  s.add(key("format"), c.format,
        "storage of the Hi-Z baselines' depths, rounded toward far (u24 stored as 32-bit D24X8)",
        name_list(kStorageFormatNames));
  s.add(key("lookups_per_cycle"), c.lookups_per_cycle, "texels/cycle", "Hi-Z texels compared a cycle", 0.01, 1024.0);
  s.add(key("lookup_latency_cycles"), c.lookup_latency_cycles, "cycles", "latency of one Hi-Z query", 0, 100000);
  s.add(key("build_texels_per_cycle"), c.build_texels_per_cycle, "texels/cycle",
        "Hi-Z texels recomputed a cycle (tile updates, pyramid rebuild)", 0.01, 1024.0);
  s.add(key("build_latency_cycles"), c.build_latency_cycles, "cycles", "latency of one Hi-Z update or rebuild", 0, 100000);
  if (prefix == "hiz")  // occlusion culling's instance: the cull stage's spellings name these keys
    for (const char* field : {"lookups_per_cycle", "lookup_latency_cycles", "build_texels_per_cycle", "build_latency_cycles"})
      s.renamed(std::string("cull.hiz_") + field, key(field));
}

void HiZUnitConfig::validate() const {
  if (tile_px < 1 || tile_px > kMaxTilePx)
    throw InputError(fmt::format("{}.tile_px must be 1 to {}, got {}", key_prefix, kMaxTilePx, tile_px));
  if (!parse_storage_format(format))
    throw InputError(fmt::format("{}.format must be one of f32, u24, u16, got '{}'", key_prefix, format));
}

TileHiZConfig HiZUnitConfig::tile(FarOp op) const {
  const auto f = parse_storage_format(format);
  NBSIM_CHECK(f.has_value(), "hiz config used before validate()");
  return {op, *f, tile_px};
}

HiZConfig HiZUnitConfig::pyramid(FarOp op) const {
  const auto f = parse_storage_format(format);
  NBSIM_CHECK(f.has_value(), "hiz config used before validate()");
  return {op, *f};
}

}  // namespace nbsim

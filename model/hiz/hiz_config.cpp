// Configuration of the Hi-Z baselines; see hiz_config.h.
#include "model/hiz/hiz_config.h"

#include <fmt/format.h>

#include "model/common/error.h"
#include "model/common/names.h"

namespace nbsim {

namespace {
constexpr int kMaxTilePx = 256;
}

void HiZUnitConfig::describe(config::Schema& s, HiZUnitConfig& c) {
  s.add("hiz.tile_px", c.tile_px, "pixels", "tile Hi-Z: side of the square screen tile holding one farthest depth", 1,
        kMaxTilePx);
  s.add("hiz.format", c.format,
        "storage of the Hi-Z baselines' depths, rounded toward far (u24 stored as 32-bit D24X8)",
        name_list(kStorageFormatNames));
}

void HiZUnitConfig::validate() const {
  if (tile_px < 1 || tile_px > kMaxTilePx)
    throw InputError(fmt::format("hiz.tile_px must be 1 to {}, got {}", kMaxTilePx, tile_px));
  if (!parse_storage_format(format))
    throw InputError(fmt::format("hiz.format must be one of f32, u24, u16, got '{}'", format));
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

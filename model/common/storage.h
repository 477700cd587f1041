// Storage formats for depth-like levels (N-buffer, Hi-Z) and their conservative quantization.
// A stored "farthest" value must never be nearer than the true one, so quantization rounds toward
// far: up under FarOp::Max, down under FarOp::Min. Values are kept as floats holding exactly the
// representable codes (code / (2^bits - 1)); the timing model charges bytes by format.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string_view>

#include "model/common/depth.h"

namespace nbsim {

// Fixed values: they end up in configs and trace files.
enum class StorageFormat : std::uint8_t { F32 = 0, U24 = 1, U16 = 2 };

constexpr int storage_bits(StorageFormat f) noexcept {
  return f == StorageFormat::F32 ? 32 : f == StorageFormat::U24 ? 24 : 16;
}

// Bytes one texel occupies in memory. U24 is stored as D24X8 (a 32-bit word), as GPUs store it.
constexpr int storage_bytes(StorageFormat f) noexcept { return f == StorageFormat::U16 ? 2 : 4; }

// Names of StorageFormat, indexed by its value (model/common/names.h).
inline constexpr std::array<std::string_view, 3> kStorageFormatNames = {"f32", "u24", "u16"};
std::string_view to_string(StorageFormat f) noexcept;
std::optional<StorageFormat> parse_storage_format(std::string_view s) noexcept;

// Rounds d (in [0, 1]) to the format, toward far. Exact for F32. Monotone in d, so it commutes
// with max/min reductions: quantizing level 0 then reducing equals reducing then quantizing.
inline float quantize_toward_far(float d, StorageFormat f, FarOp op) noexcept {
  if (f == StorageFormat::F32) return d;
  const double scale = f == StorageFormat::U24 ? 16777215.0 : 65535.0;
  const double v = static_cast<double>(d) * scale;  // exact: 24 + 24 bits fit a double
  auto stored = [scale](double code) { return static_cast<float>(code / scale); };
  // code / scale is on the far side of d in the reals; both roundings in stored() are monotone
  // and d is representable, so the float result stays on the far side of d. A stored value read
  // back may lie a hair past its code in the reals, so step back one code when the nearer code's
  // float still is on the far side of d: then quantizing a stored value returns it unchanged.
  if (op == FarOp::Max) {
    double code = std::ceil(v);
    if (code > 0 && stored(code - 1) >= d) code -= 1;
    return stored(code);
  }
  double code = std::floor(v);
  if (code < scale && stored(code + 1) <= d) code += 1;
  return stored(code);
}

}  // namespace nbsim

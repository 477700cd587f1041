// Depth conventions shared by every unit of nbsim. They are stated once, here.
//
// - Depth is GL window depth in [0, 1]; the clear value is 1.0 and the default depth func is LESS.
// - Images are y up: pixel (x, y) has its centre at (x + 0.5, y + 0.5) and row 0 is the bottom row.
//   Files on disk are top-down; io/ flips rows on the way in and out.
// - "Farthest" is max under LESS/LEQUAL (FarOp::Max) and min under reversed Z, GREATER/GEQUAL
//   (FarOp::Min). Min-litmaps for shadow clamping use FarOp::Min too.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

namespace nbsim {

// Which way is "far". Fixed values: they end up in trace files.
enum class FarOp : std::uint8_t { Max = 0, Min = 1 };

// The farther of two depths under `op`.
constexpr float farther(FarOp op, float a, float b) noexcept {
  return op == FarOp::Max ? (a > b ? a : b) : (a < b ? a : b);
}

// True when a is at least as far as b under `op` (a conservative answer for b).
constexpr bool at_least_as_far(FarOp op, float a, float b) noexcept {
  return op == FarOp::Max ? a >= b : a <= b;
}

// The value that never raises the farthest depth: pixels outside an image act as this.
constexpr float neutral_depth(FarOp op) noexcept { return op == FarOp::Max ? 0.0f : 1.0f; }

// The farthest possible depth: a conservative answer when nothing better is known.
constexpr float far_limit(FarOp op) noexcept { return op == FarOp::Max ? 1.0f : 0.0f; }

// Names of FarOp, indexed by its value (model/common/names.h).
inline constexpr std::array<std::string_view, 2> kFarOpNames = {"max", "min"};
std::string_view to_string(FarOp op) noexcept;

// A single-channel float image, y up, row-major (index = y * width + x).
struct DepthImage {
  int width = 0;
  int height = 0;
  std::vector<float> texels;

  DepthImage() = default;
  DepthImage(int w, int h, float fill);

  float at(int x, int y) const { return texels[static_cast<std::size_t>(y) * width + x]; }
  float& at(int x, int y) { return texels[static_cast<std::size_t>(y) * width + x]; }
  std::size_t size() const noexcept { return texels.size(); }
};

}  // namespace nbsim

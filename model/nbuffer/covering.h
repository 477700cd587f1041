// The covering of a screen rectangle by N-buffer squares (Décoret 2005, section 3.2 and Fig. 3).
// Pure arithmetic, no storage: the N-buffer query, the coverage report (Fig. 4) and the hardware
// model's query port all use it.
//
// Four-square covering: n = floor(log2(max(w, h))), clamped to the top level; squares of side
// S = 2^n anchored at the rectangle's corners. Along an axis where the rectangle is longer than S
// the two anchors are x and x + w - S (they overlap or touch because w <= 2S); where it is not, one
// anchor x suffices. So a query reads 1, 2 or 4 texels, and the squares lie inside the rectangle
// exactly when both sides are at least S, i.e. when floor(log2 w) == floor(log2 h).
// One-square covering: a single square of side 2^ceil(log2(max(w, h))) at (x, y), or the
// four-square covering of the top level when no level is that large.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

#include "model/common/rect.h"

namespace nbsim {

enum class CoveringKind : std::uint8_t { Four = 0, One = 1 };

// The five cases of Fig. 3, named by what the squares do to the rectangle.
enum class CoveringCase : std::uint8_t {
  Exact = 0,       // the rectangle is one square (w == h == S)
  SideBySide = 1,  // h == S < w: two squares next to each other
  Stacked = 2,     // w == S < h: two squares on top of each other
  Four = 3,        // both sides longer than S: four overlapping squares, still exact
  Overhang = 4,    // a side shorter than S: the squares stick out, extra pixels are read
};

std::string_view to_string(CoveringKind k) noexcept;
std::string_view to_string(CoveringCase c) noexcept;
std::optional<CoveringKind> parse_covering_kind(std::string_view s) noexcept;

struct Square {
  int x = 0;  // lower-left corner, level-0 pixels
  int y = 0;
};

struct Covering {
  int level = 0;  // level whose texels the squares are; side = 2^level
  CoveringCase kase = CoveringCase::Exact;
  int count = 0;  // 1, 2 or 4
  std::array<Square, 4> squares{};

  int side() const noexcept { return 1 << level; }
};

constexpr int floor_log2(unsigned v) noexcept {
  int n = -1;
  while (v) { v >>= 1; ++n; }
  return n;
}
constexpr int ceil_log2(unsigned v) noexcept { return v <= 1 ? 0 : floor_log2(v - 1) + 1; }

// Number of N-buffer levels for an image: ceil(log2(max(W, H))), at least 1.
constexpr int nbuffer_level_count(int width, int height) noexcept {
  const int m = width > height ? width : height;
  const int l = ceil_log2(static_cast<unsigned>(m));
  return l < 1 ? 1 : l;
}

// Coverings of a non-empty rectangle. top_level is the highest level that may be used; the
// rectangle's sides must be at most 2^(top_level + 1) (true for any rectangle clipped to an image
// whose N-buffer has top_level + 1 = nbuffer_level_count levels).
Covering cover_four(const Rect& r, int top_level);
Covering cover_one(const Rect& r, int top_level);
Covering cover(const Rect& r, CoveringKind kind, int top_level);

// The level a covering of r needs when no level cap applies.
int level_needed(const Rect& r, CoveringKind kind) noexcept;

// Area of the union of the covering's squares (not clipped to any image), in pixels.
long long covered_area(const Covering& c) noexcept;

}  // namespace nbsim

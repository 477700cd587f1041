// The covering of a screen rectangle by N-buffer squares (Décoret 2005, section 2, Figs. 3 and 4):
// which texels of which level a query reads. Pure arithmetic, no storage: the N-buffer query, the
// unit's query port, the coverage report (Fig. 4) and, through shaders/common/covering.glsl (its
// GLSL twin, tested box for box against this file), every GL shader that queries an N-buffer.
//
// The paper's covering (CoveringKind::Paper, the default). With S the smallest power of two at
// least max(w, h) and q = S / 2 (a quadrant of the rectangle's bounding power-of-two square), the
// rectangle falls in one of five cases (Fig. 3):
//   four_quadrants    w > q and h > q: four squares of side q at its corners (exact);
//   two_side_by_side  w > q >= h > q/2: two squares of side q side by side;
//   four_in_a_row     w > q, h <= q/2: four squares of side q/2 in a row;
//   two_stacked, four_in_a_column: the same turned (h > q >= w).
// (A 1x1 rectangle is four_quadrants with its four corners in one texel of level 0.) The squares
// of a row are aligned with the rectangle's TOP (CoveringAlign::Top), so that the overhang runs
// down into what an object stands on (the paper's choice); a column's squares start at its left
// edge. A top-aligned square that would start below the image (y < 0) starts at y = 0 instead: it
// still holds the rectangle, which then reaches no higher than the square's side, and the query
// stays complete (a square that reaches past the image's top or right edge is fine: pixels outside
// the image are neutral). Along each axis the squares are placed at the start, one side apart, and
// the last one flush with the far end, and squares that would repeat a texel are not read: a
// query reads 1 to 4 texels, and on each axis the squares' union is exactly the rectangle's span
// except along the overhanging axis of a row or column.
//
// The corner covering (CoveringKind::Corners; with bottom alignment, the covering of a trace whose
// header names none): squares of side 2^floor(log2(max(w, h))) at the rectangle's corners, one or
// two anchors per axis; exact when floor(log2 w) == floor(log2 h), otherwise the short side
// overhangs by up to a whole square.
// The one-square covering (CoveringKind::One): a single square of side S (or the corner covering
// of the top level when no level is that large).
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <optional>
#include <string_view>

#include "model/common/rect.h"

namespace nbsim {

// Which squares answer a rectangle. Fixed values (they end up in configs and trace headers).
enum class CoveringKind : std::uint8_t { Paper = 0, Corners = 1, One = 2 };
inline constexpr std::array<std::string_view, 3> kCoveringKindNames = {"paper", "corners", "one"};

// Which edge an overhanging square is flush with, where the rectangle is shorter than the squares
// vertically: the top (the paper's) or the bottom. Fixed values.
enum class CoveringAlign : std::uint8_t { Top = 0, Bottom = 1 };
inline constexpr std::array<std::string_view, 2> kCoveringAlignNames = {"top", "bottom"};

// The five cases of Fig. 3, a property of the rectangle's shape (not of the covering that answers
// it). Fixed values: statistics buckets are in this order.
enum class CoveringCase : std::uint8_t {
  FourQuadrants = 0,
  TwoSideBySide = 1,
  TwoStacked = 2,
  FourInARow = 3,
  FourInAColumn = 4,
};
inline constexpr std::array<std::string_view, 5> kCoveringCaseNames = {"four_quadrants", "two_side_by_side", "two_stacked",
                                                                       "four_in_a_row", "four_in_a_column"};

std::string_view to_string(CoveringKind k) noexcept;
std::string_view to_string(CoveringAlign a) noexcept;
std::string_view to_string(CoveringCase c) noexcept;
std::optional<CoveringKind> parse_covering_kind(std::string_view s) noexcept;
std::optional<CoveringAlign> parse_covering_align(std::string_view s) noexcept;

// A covering scheme: the kind and the alignment (the paper's: paper, top). direct_squares: a
// rectangle that is a power-of-two square is read with one lookup of the level of its side (the
// paper's direct covering of point sprites, 3.2; the particles program sets it); no other.
struct CoveringSpec {
  CoveringKind kind = CoveringKind::Paper;
  CoveringAlign align = CoveringAlign::Top;
  bool direct_squares = false;
  friend bool operator==(const CoveringSpec&, const CoveringSpec&) = default;
};
// "paper/top", "corners/bottom", ... (direct_squares is not named); and back (nothing when either
// half is unknown).
std::string covering_name(const CoveringSpec& s);
std::optional<CoveringSpec> parse_covering_name(std::string_view s) noexcept;

struct Square {
  int x = 0;  // lower-left corner, level-0 pixels
  int y = 0;
};

struct Covering {
  int level = 0;  // level whose texels the squares are (square levels: side = 2^level)
  // The squares' sides are 2^log2_w x 2^log2_h: both `level` for square levels; rectangle levels
  // (cover_rect) read rectangles, and their level is the N-buffer's plane of that size.
  int log2_w = 0, log2_h = 0;
  CoveringCase kase = CoveringCase::FourQuadrants;
  int count = 0;  // 1 to 4 distinct texels
  std::array<Square, 4> squares{};  // lower-left corners (of rectangles, for rectangle levels)

  int side() const noexcept { return 1 << log2_w; }  // square levels
  int width_px() const noexcept { return 1 << log2_w; }
  int height_px() const noexcept { return 1 << log2_h; }
};

// floor(log2 v) (-1 for 0) and ceil(log2 v) (0 for 0 and 1).
constexpr int floor_log2(unsigned v) noexcept { return static_cast<int>(std::bit_width(v)) - 1; }
constexpr int ceil_log2(unsigned v) noexcept { return v <= 1 ? 0 : static_cast<int>(std::bit_width(v - 1)); }

// Number of N-buffer levels for an image: ceil(log2(max(W, H))), at least 1.
constexpr int nbuffer_level_count(int width, int height) noexcept {
  const int m = width > height ? width : height;
  const int l = ceil_log2(static_cast<unsigned>(m));
  return l < 1 ? 1 : l;
}

// The case of Fig. 3 a non-empty w x h rectangle falls in.
CoveringCase covering_case(int w, int h) noexcept;

// The covering of a non-empty rectangle. top_level is the highest level that may be used; the
// rectangle's sides must be at most 2^(top_level + 1) (true for any rectangle clipped to an image
// whose N-buffer has top_level + 1 = nbuffer_level_count levels). A rectangle inside an image
// (x, y >= 0) gets squares inside it too (x, y >= 0).
Covering cover(const Rect& r, CoveringSpec spec, int top_level);

// The header property naming the covering of a capture's GL queries ("paper/top"); a trace without
// it was captured with corners/bottom.
inline constexpr std::string_view kCoveringProperty = "nbuffer_covering";

// The covering of rectangle levels (the paper's future work, like RIP-maps: NBufferConfig::shape
// rect), where level (i, j) holds the farthest of 2^i x 2^j neighbourhoods: rectangles of
// 2^i x 2^j with i = ceil(log2 w) - 1 (0 for w = 1) and j likewise, at most two per axis, so every
// rectangle is read exactly with at most four lookups. With max_aspect_log2 = k >= 1 the levels
// have |i - j| <= k (and the last row and column of levels, which every rectangle needs, are
// whole): a thinner rectangle reads rectangles whose short exponent is raised to the long one's
// minus k (at most the axis's last), one flush with the top (per `align`) or two on that axis.
// levels_x and levels_y: the exponents' counts (ceil(log2 W), ceil(log2 H), at least 1). `level`
// is -1: the N-buffer gives the plane.
Covering cover_rect(const Rect& r, int levels_x, int levels_y, int max_aspect_log2, CoveringAlign align);

// The level a covering of r reads when no level cap applies.
int level_needed(const Rect& r, CoveringKind kind) noexcept;

// Area of the union of the covering's squares (not clipped to any image), in pixels.
long long covered_area(const Covering& c) noexcept;

}  // namespace nbsim

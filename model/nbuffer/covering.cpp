// Coverings of rectangles by N-buffer squares; see covering.h.
#include "model/nbuffer/covering.h"

#include <algorithm>
#include <string>

#include "model/common/error.h"
#include "model/common/names.h"

namespace nbsim {

std::string_view to_string(CoveringKind k) noexcept { return enum_name(kCoveringKindNames, k); }
std::string_view to_string(CoveringAlign a) noexcept { return enum_name(kCoveringAlignNames, a); }
std::string_view to_string(CoveringCase c) noexcept { return enum_name(kCoveringCaseNames, c); }
std::optional<CoveringKind> parse_covering_kind(std::string_view s) noexcept { return parse_enum_name<CoveringKind>(kCoveringKindNames, s); }
std::optional<CoveringAlign> parse_covering_align(std::string_view s) noexcept {
  return parse_enum_name<CoveringAlign>(kCoveringAlignNames, s);
}

std::string covering_name(const CoveringSpec& s) {
  return std::string(to_string(s.kind)) + "/" + std::string(to_string(s.align));
}

std::optional<CoveringSpec> parse_covering_name(std::string_view s) noexcept {
  const auto slash = s.find('/');
  if (slash == std::string_view::npos) return std::nullopt;
  const auto kind = parse_covering_kind(s.substr(0, slash));
  const auto align = parse_covering_align(s.substr(slash + 1));
  if (!kind || !align) return std::nullopt;
  return CoveringSpec{*kind, *align};
}

CoveringCase covering_case(int w, int h) noexcept {
  const int s = 1 << ceil_log2(static_cast<unsigned>(std::max(w, h)));
  const int q = s / 2;
  if (w > q && h > q) return CoveringCase::FourQuadrants;  // also 1x1 (q = 0)
  if (w > q) return 2 * h <= q ? CoveringCase::FourInARow : CoveringCase::TwoSideBySide;
  return 2 * w <= q ? CoveringCase::FourInAColumn : CoveringCase::TwoStacked;
}

namespace {

// The squares' starts along one axis for a span [start, start + len) and squares of `side`: when
// the span is longer, one every `side` from the start and the last flush with the end (at most
// four: len <= 4 side); when it is not longer, one square flush with the start, or with the end
// when `at_end` (moved to 0 when that would start below 0 while the span does not).
[[gnu::always_inline]] inline int anchors(int start, int len, int log2_side, bool at_end, std::array<int, 4>& out) {
  const int side = 1 << log2_side;
  if (len <= side) {
    int a = at_end ? start + len - side : start;
    if (a < 0 && start >= 0) a = 0;
    out[0] = a;
    return 1;
  }
  const int n = (len + side - 1) >> log2_side;
  NBSIM_CHECK(n <= 4, "a covering's span needs more than four squares");
  for (int k = 0; k + 1 < n; ++k) out[static_cast<std::size_t>(k)] = start + k * side;
  out[static_cast<std::size_t>(n - 1)] = start + len - side;
  return n;
}

// Rectangles of 2^lw x 2^lh over r, at most four.
[[gnu::always_inline]] inline Covering grid(const Rect& r, int lw, int lh, bool top, CoveringCase kase) {
  Covering c;
  c.level = lw;
  c.log2_w = lw, c.log2_h = lh;
  c.kase = kase;
  std::array<int, 4> xs{}, ys{};
  const int nx = anchors(r.x, r.w, lw, false, xs), ny = anchors(r.y, r.h, lh, top, ys);
  NBSIM_CHECK(nx * ny <= 4, "a covering with more than four squares");
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) c.squares[static_cast<std::size_t>(c.count++)] = {xs[static_cast<std::size_t>(i)], ys[static_cast<std::size_t>(j)]};
  return c;
}

Covering paper(const Rect& r, bool top, int top_level) {
  // covering_case() and the level from one ceil(log2): squares of side q (a quadrant), or q/2 in a
  // row or a column; a 1x1 rectangle: level 0.
  const int s_log = ceil_log2(static_cast<unsigned>(std::max(r.w, r.h)));
  const int q = (1 << s_log) >> 1;
  CoveringCase kase = CoveringCase::FourQuadrants;
  if (!(r.w > q && r.h > q))
    kase = r.w > q ? (2 * r.h <= q ? CoveringCase::FourInARow : CoveringCase::TwoSideBySide)
                   : (2 * r.w <= q ? CoveringCase::FourInAColumn : CoveringCase::TwoStacked);
  const int level = s_log == 0 ? 0 : (kase == CoveringCase::FourInARow || kase == CoveringCase::FourInAColumn ? s_log - 2 : s_log - 1);
  NBSIM_CHECK(level <= top_level, "rectangle larger than the top level's covering");
  return grid(r, level, level, top, kase);
}

Covering corners(const Rect& r, bool top, int top_level) {
  const int level = std::min(floor_log2(static_cast<unsigned>(std::max(r.w, r.h))), top_level);
  NBSIM_CHECK(r.w <= 2 << level && r.h <= 2 << level, "rectangle larger than four squares of the top level");
  return grid(r, level, level, top, covering_case(r.w, r.h));
}

bool power_of_two_square(const Rect& r) noexcept { return r.w == r.h && (r.w & (r.w - 1)) == 0; }

// The direct covering of a power-of-two square: one texel of the level of its side.
Covering direct(const Rect& r) {
  {
    Covering c;
    c.level = floor_log2(static_cast<unsigned>(r.w));
    c.log2_w = c.log2_h = c.level;
    c.kase = covering_case(r.w, r.h);
    c.count = 1;
    c.squares[0] = {r.x, r.y};
    return c;
  }
}

}  // namespace

int level_needed(const Rect& r, CoveringKind kind) noexcept {
  const auto m = static_cast<unsigned>(std::max(r.w, r.h));
  switch (kind) {
    case CoveringKind::Paper: {
      const CoveringCase kase = covering_case(r.w, r.h);
      const int s_log = ceil_log2(m);
      return s_log == 0 ? 0 : (kase == CoveringCase::FourInARow || kase == CoveringCase::FourInAColumn ? s_log - 2 : s_log - 1);
    }
    case CoveringKind::Corners: return floor_log2(m);
    case CoveringKind::One: return ceil_log2(m);
  }
  return ceil_log2(m);
}

Covering cover(const Rect& r, CoveringSpec spec, int top_level) {
  NBSIM_CHECK(!r.empty(), "covering an empty rectangle");
  if (spec.direct_squares && power_of_two_square(r) && floor_log2(static_cast<unsigned>(r.w)) <= top_level) return direct(r);
  const bool top = spec.align == CoveringAlign::Top;
  switch (spec.kind) {
    case CoveringKind::Paper: return paper(r, top, top_level);
    case CoveringKind::Corners: return corners(r, top, top_level);
    case CoveringKind::One: {
      const int n = level_needed(r, CoveringKind::One);
      return n > top_level ? corners(r, top, top_level) : grid(r, n, n, top, covering_case(r.w, r.h));
    }
  }
  NBSIM_CHECK(false, "unknown covering kind");
  return {};
}


Covering cover_rect(const Rect& r, int levels_x, int levels_y, int max_aspect_log2, CoveringAlign align) {
  NBSIM_CHECK(!r.empty(), "covering an empty rectangle");
  NBSIM_CHECK(max_aspect_log2 == -1 || max_aspect_log2 >= 1, "rectangle levels: max_aspect_log2 is -1 or at least 1");
  const auto exponent = [](int len) { return len <= 1 ? 0 : ceil_log2(static_cast<unsigned>(len)) - 1; };
  int i = exponent(r.w), j = exponent(r.h);
  NBSIM_CHECK(i < levels_x && j < levels_y, "rectangle larger than the rectangle levels");
  if (max_aspect_log2 >= 1) {
    if (i - j > max_aspect_log2) j = std::min(i - max_aspect_log2, levels_y - 1);
    if (j - i > max_aspect_log2) i = std::min(j - max_aspect_log2, levels_x - 1);
  }
  Covering c = grid(r, i, j, align == CoveringAlign::Top, covering_case(r.w, r.h));
  c.level = -1;
  return c;
}

long long covered_area(const Covering& c) noexcept {
  // The squares form a grid (one to four starts per axis) whose intervals overlap or touch, so the
  // union is a rectangle: the span of the starts plus one side, on each axis.
  const int sw = c.width_px(), sh = c.height_px();
  int x0 = c.squares[0].x, x1 = x0, y0 = c.squares[0].y, y1 = y0;
  for (int i = 1; i < c.count; ++i) {
    x0 = std::min(x0, c.squares[static_cast<std::size_t>(i)].x), x1 = std::max(x1, c.squares[static_cast<std::size_t>(i)].x);
    y0 = std::min(y0, c.squares[static_cast<std::size_t>(i)].y), y1 = std::max(y1, c.squares[static_cast<std::size_t>(i)].y);
  }
  return static_cast<long long>(x1 - x0 + sw) * (y1 - y0 + sh);
}

}  // namespace nbsim

// Coverings of rectangles by N-buffer squares; see covering.h.
#include "model/nbuffer/covering.h"

#include <algorithm>

#include "model/common/error.h"

namespace nbsim {

std::string_view to_string(CoveringKind k) noexcept { return k == CoveringKind::Four ? "four" : "one"; }

std::string_view to_string(CoveringCase c) noexcept {
  switch (c) {
    case CoveringCase::Exact: return "exact";
    case CoveringCase::SideBySide: return "side_by_side";
    case CoveringCase::Stacked: return "stacked";
    case CoveringCase::Four: return "four";
    case CoveringCase::Overhang: return "overhang";
  }
  return "?";
}

std::optional<CoveringKind> parse_covering_kind(std::string_view s) noexcept {
  if (s == "four") return CoveringKind::Four;
  if (s == "one") return CoveringKind::One;
  return std::nullopt;
}

namespace {

CoveringCase classify(int w, int h, int side) noexcept {
  if (w < side || h < side) return CoveringCase::Overhang;
  if (w == side && h == side) return CoveringCase::Exact;
  if (w == side) return CoveringCase::Stacked;
  if (h == side) return CoveringCase::SideBySide;
  return CoveringCase::Four;
}

Covering corners(const Rect& r, int level) {
  Covering c;
  c.level = level;
  const int s = 1 << level;
  NBSIM_CHECK(r.w <= 2 * s && r.h <= 2 * s, "rectangle larger than four squares of the top level");
  c.kase = classify(r.w, r.h, s);
  const int nx = r.w > s ? 2 : 1, ny = r.h > s ? 2 : 1;
  const int xs[2] = {r.x, r.x + r.w - s}, ys[2] = {r.y, r.y + r.h - s};
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) c.squares[static_cast<std::size_t>(c.count++)] = {xs[i], ys[j]};
  return c;
}

}  // namespace

int level_needed(const Rect& r, CoveringKind kind) noexcept {
  const auto m = static_cast<unsigned>(std::max(r.w, r.h));
  return kind == CoveringKind::Four ? floor_log2(m) : ceil_log2(m);
}

Covering cover_four(const Rect& r, int top_level) {
  NBSIM_CHECK(!r.empty(), "covering an empty rectangle");
  return corners(r, std::min(level_needed(r, CoveringKind::Four), top_level));
}

Covering cover_one(const Rect& r, int top_level) {
  NBSIM_CHECK(!r.empty(), "covering an empty rectangle");
  const int n = level_needed(r, CoveringKind::One);
  if (n > top_level) return cover_four(r, top_level);
  Covering c;
  c.level = n;
  c.kase = classify(r.w, r.h, 1 << n);
  c.count = 1;
  c.squares[0] = {r.x, r.y};
  return c;
}

Covering cover(const Rect& r, CoveringKind kind, int top_level) {
  return kind == CoveringKind::Four ? cover_four(r, top_level) : cover_one(r, top_level);
}

long long covered_area(const Covering& c) noexcept {
  // The squares form a grid (one or two anchors per axis) whose intervals overlap or touch, so
  // the union is a rectangle: the span of the anchors plus one side, on each axis.
  const int s = c.side();
  int x0 = c.squares[0].x, x1 = x0, y0 = c.squares[0].y, y1 = y0;
  for (int i = 1; i < c.count; ++i) {
    x0 = std::min(x0, c.squares[i].x), x1 = std::max(x1, c.squares[i].x);
    y0 = std::min(y0, c.squares[i].y), y1 = std::max(y1, c.squares[i].y);
  }
  return static_cast<long long>(x1 - x0 + s) * (y1 - y0 + s);
}

}  // namespace nbsim

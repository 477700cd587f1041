// Screen rectangles in pixels, y up: [x, x + w) x [y, y + h). Used by every query in the model.
#pragma once

#include <algorithm>
#include <ostream>

namespace nbsim {

struct Rect {
  int x = 0;
  int y = 0;
  int w = 0;
  int h = 0;

  bool empty() const noexcept { return w <= 0 || h <= 0; }
  long long area() const noexcept { return empty() ? 0 : static_cast<long long>(w) * h; }
  int x1() const noexcept { return x + w; }
  int y1() const noexcept { return y + h; }
  bool contains(int px, int py) const noexcept { return px >= x && px < x1() && py >= y && py < y1(); }
  friend bool operator==(const Rect&, const Rect&) = default;
};

// The part of r inside [0, width) x [0, height); empty when they do not overlap.
inline Rect clip(const Rect& r, int width, int height) noexcept {
  const long long x0 = std::max<long long>(r.x, 0), y0 = std::max<long long>(r.y, 0);
  const long long x1 = std::min<long long>(static_cast<long long>(r.x) + r.w, width);
  const long long y1 = std::min<long long>(static_cast<long long>(r.y) + r.h, height);
  if (x1 <= x0 || y1 <= y0) return {};
  return {static_cast<int>(x0), static_cast<int>(y0), static_cast<int>(x1 - x0), static_cast<int>(y1 - y0)};
}

inline std::ostream& operator<<(std::ostream& os, const Rect& r) {
  return os << "[" << r.x << "," << r.y << " " << r.w << "x" << r.h << "]";
}

}  // namespace nbsim

// The exact reference of a relief ray (reference.h; heightfield.h's conventions), in double: the
// ground truth the walks (walk.h) and the capture's hits are scored against.
//
// The ray's horizontal projection is cut at every cell boundary it crosses (x or y = k + 0.5, k in
// [-1, N]); between two consecutive cuts it stays in one cell, found from the piece's midpoint, so
// corners, axis-parallel rays (even one running along a boundary: the surface is continuous there)
// and vertical rays (one piece) need no special case. In a cell, with s = t - ta from the piece's
// start, the height above the bilinear patch is the quadratic f(s) = a s^2 + b s + c. Its first
// root on [0, L] is searched on the monotone pieces of f (split at its vertex), in order: a piece
// whose end is <= 0 holds a root, found with the cancellation-free formula (q = -(b + sign(b)
// sqrt(b^2 - 4ac)) / 2, roots q / a and c / q) and checked to lie in the piece (else bisection);
// an end value within kTouch above 0 is a touch (a tangent, or a graze on a cell boundary).
#include "model/relief/reference.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "model/common/error.h"

namespace nbsim::relief {
namespace {

// Tunable: an end or vertex of f this close above the surface (height units) is a touch, a hit.
// Far above double rounding of heights in [0, 1] (~1e-16), far below anything a walk resolves.
constexpr double kTouch = 1e-12;
// How far above a cell's highest corner the ray must be at both ends of a piece for the piece to be
// skipped unsolved (reference_hit): heights are in [0, 1], so few pieces under a hit are this close.
constexpr double kClear = 1e-6;

struct Quadratic {
  double a, b, c;
  double operator()(double s) const noexcept { return (a * s + b) * s + c; }
};

// The root of q in [lo, hi], where q(lo) > 0 >= q(hi) and q is monotone on [lo, hi].
double root_in(const Quadratic& q, double lo, double hi) noexcept {
  const double slack = 1e-12 * (1.0 + std::abs(hi));
  auto inside = [&](double s) { return std::isfinite(s) && s >= lo - slack && s <= hi + slack; };
  double best = std::numeric_limits<double>::quiet_NaN();
  if (q.a == 0.0) {
    if (q.b != 0.0) best = -q.c / q.b;
  } else {
    const double disc = std::max(0.0, q.b * q.b - 4.0 * q.a * q.c);
    const double w = -0.5 * (q.b + std::copysign(std::sqrt(disc), q.b));
    const double r1 = w / q.a;
    const double r2 = w != 0.0 ? q.c / w : std::numeric_limits<double>::quiet_NaN();
    if (inside(r1)) best = r1;
    if (inside(r2) && (!inside(best) || r2 < best)) best = r2;
  }
  if (inside(best)) return std::clamp(best, lo, hi);
  // Rounding put the formula's roots outside the bracket: bisect it down to adjacent doubles.
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (q(mid) > 0.0 ? lo : hi) = mid;
  }
  return hi;
}

// The first s in [0, length] where q <= 0 or touches 0 (q(0) > 0 is known), or NaN.
double first_root(const Quadratic& q, double length) noexcept {
  double cuts[3] = {0.0, length, length};
  int count = 2;
  if (q.a != 0.0) {
    const double vertex = -q.b / (2.0 * q.a);
    if (vertex > 0.0 && vertex < length) {
      cuts[1] = vertex;
      count = 3;
    }
  }
  for (int k = 0; k + 1 < count; ++k) {
    const double lo = cuts[k], hi = cuts[k + 1];
    const double fhi = q(hi);
    if (fhi <= 0.0) return q(lo) <= 0.0 ? lo : root_in(q, lo, hi);
    if (fhi <= kTouch) return hi;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

// One axis's cell-boundary crossings t = (k + 0.5 - o) / d strictly inside (t_enter, t_exit), k in
// [-1, N], in increasing t: k runs up for d > 0 and down for d < 0, and the rounded quotient is
// monotone in k, so the ones at or before t_enter lead and the ones at or after t_exit trail.
class AxisCuts {
 public:
  AxisCuts(double o, double d, double t_enter, double t_exit, int n) : o_(o), d_(d), t_enter_(t_enter), t_exit_(t_exit) {
    if (d == 0.0) return;
    const double a = o + t_enter * d - 0.5, b = o + t_exit * d - 0.5;
    const double first = std::max(std::ceil(std::min(a, b)), -1.0), last = std::min(std::floor(std::max(a, b)), static_cast<double>(n));
    if (first > last) return;
    k_ = d > 0.0 ? first : last;
    end_ = d > 0.0 ? last : first;
    step_ = d > 0.0 ? 1.0 : -1.0;
    live_ = true;
    advance();
  }
  // The next crossing, +inf when there is none.
  double peek() const noexcept { return live_ ? t_ : std::numeric_limits<double>::infinity(); }
  double take() noexcept {
    const double t = t_;
    k_ += step_;
    advance();
    return t;
  }

 private:
  // Moves to the first k from k_ whose crossing lies inside the interval, or ends.
  void advance() noexcept {
    for (; live_; k_ += step_) {
      if (step_ > 0.0 ? k_ > end_ : k_ < end_) break;
      t_ = (k_ + 0.5 - o_) / d_;
      if (t_ >= t_exit_) break;
      if (t_ > t_enter_) return;
    }
    live_ = false;
  }
  double o_, d_, t_enter_, t_exit_;
  double k_ = 0.0, end_ = 0.0, step_ = 1.0, t_ = 0.0;
  bool live_ = false;
};

// The t where the ray leaves the cell range [first, last] along one axis (+inf when it never does):
// the boundary x - 0.5 = last + 1 going up, = first going down.
double leave_range(double o, double d, int first, int last) noexcept {
  if (d > 0.0) return (last + 1 + 0.5 - o) / d;
  if (d < 0.0) return (first + 0.5 - o) / d;
  return std::numeric_limits<double>::infinity();
}

}  // namespace

ReferenceBlocks::ReferenceBlocks(const Heightfield& field) {
  const int n = field.size, cells = n + 4;  // cell indices -2 .. n + 1
  blocks_ = (cells + kBlock - 1) / kBlock;
  // Each cell's highest corner, then each block's maximum over its cells and their neighbours.
  std::vector<double> cell(static_cast<std::size_t>(cells) * cells);
  for (int cj = -2; cj <= n + 1; ++cj)
    for (int ci = -2; ci <= n + 1; ++ci)
      cell[static_cast<std::size_t>(cj + 2) * cells + static_cast<std::size_t>(ci + 2)] =
          std::max(std::max(field.at(ci, cj), field.at(ci + 1, cj)), std::max(field.at(ci, cj + 1), field.at(ci + 1, cj + 1)));
  max_.assign(static_cast<std::size_t>(blocks_) * blocks_, 0.0);
  for (int bj = 0; bj < blocks_; ++bj)
    for (int bi = 0; bi < blocks_; ++bi) {
      double m = 0.0;  // heights are in [0, 1]
      for (int cj = std::max(-2, first_cell(bj) - 1); cj <= std::min(n + 1, last_cell(bj) + 1); ++cj)
        for (int ci = std::max(-2, first_cell(bi) - 1); ci <= std::min(n + 1, last_cell(bi) + 1); ++ci)
          m = std::max(m, cell[static_cast<std::size_t>(cj + 2) * cells + static_cast<std::size_t>(ci + 2)]);
      max_[static_cast<std::size_t>(bj) * blocks_ + static_cast<std::size_t>(bi)] = m;
    }
}

ReferenceHit reference_hit(const Heightfield& field, const std::array<double, 3>& origin, const std::array<double, 3>& direction,
                           double t_enter, double t_exit, const ReferenceBlocks* blocks) {
  NBSIM_CHECK(std::isfinite(t_enter) && std::isfinite(t_exit) && t_enter <= t_exit,
              fmt::format("reference_hit needs a finite interval with t_enter <= t_exit, got [{}, {}]", t_enter, t_exit));
  const auto [ox, oy, oz] = origin;
  const auto [dx, dy, dz] = direction;
  if (oz + t_enter * dz - surface_height(field, ox + t_enter * dx, oy + t_enter * dy) <= 0.0) return {true, t_enter};

  // The cuts: every t in (t_enter, t_exit) where x or y crosses a cell boundary k + 0.5, k in
  // [-1, N] (beyond the outermost boundaries every texel is virtual and the surface is 0), in
  // increasing order: each axis's crossings come in order, so the two are merged as the walk goes
  // (the same sequence a sort of all of them gives), and the walk stops at the first hit.
  const int n = field.size;
  AxisCuts xs(ox, dx, t_enter, t_exit, n), ys(oy, dy, t_enter, t_exit, n);
  double ta = t_enter;
  // Every piece ending at or before clear_until lies in a block (with its ring) the ray crosses
  // clearly above, from a t at or after which the pieces start: skipped like the per-cell test
  // below would skip each (z = oz + t dz rounds monotonically in t, so z at the piece's ends is
  // no lower than at the block stretch's ends, and each piece's cell is in the block or its ring).
  double clear_until = -std::numeric_limits<double>::infinity();
  int near_bi = -1, near_bj = -1;  // the block last found not clear (blocks are >= 0): its cells go one by one
  for (;;) {
    const double tx = xs.peek(), ty = ys.peek();
    const bool last = !(tx < t_exit) && !(ty < t_exit);
    const double tb = last ? t_exit : tx <= ty ? xs.take() : ys.take();
    if (tb > ta && tb <= clear_until) {
      if (last) break;
      ta = tb;
      continue;
    }
    if (tb > ta) {  // else a corner (its neighbours cover it), or t_enter == t_exit (checked above)
      const double tm = 0.5 * (ta + tb);
      const double cx = std::clamp(ox + tm * dx - 0.5, -2.0, n + 1.0), cy = std::clamp(oy + tm * dy - 0.5, -2.0, n + 1.0);
      const int ci = static_cast<int>(std::floor(cx)), cj = static_cast<int>(std::floor(cy));
      if (const int bi = ReferenceBlocks::block_of(ci), bj = ReferenceBlocks::block_of(cj); blocks && (bi != near_bi || bj != near_bj)) {
        const double tl = std::min({leave_range(ox, dx, ReferenceBlocks::first_cell(bi), ReferenceBlocks::last_cell(bi)),
                                    leave_range(oy, dy, ReferenceBlocks::first_cell(bj), ReferenceBlocks::last_cell(bj)), t_exit});
        if (tl >= tb && std::min(oz + ta * dz, oz + tl * dz) > blocks->max(bi, bj) + kClear) {
          clear_until = tl;
          if (last) break;
          ta = tb;
          continue;
        }
        near_bi = bi, near_bj = bj;
      }
      const double h00 = field.at(ci, cj), h10 = field.at(ci + 1, cj), h01 = field.at(ci, cj + 1), h11 = field.at(ci + 1, cj + 1);
      // A piece the ray crosses clearly above the patch's highest corner (the bilinear patch is no
      // higher inside the cell, the ray is straight) can hold no root nor touch: most of a ray's
      // pieces. kClear dwarfs the rounding of everything below (about 1e-13 at texel coordinates
      // of 1e3), so every value that would decide a hit there is far above 0 and kTouch: skipping
      // the piece gives the same result.
      if (std::min(oz + ta * dz, oz + tb * dz) > std::max(std::max(h00, h10), std::max(h01, h11)) + kClear) {
        if (last) break;
        ta = tb;
        continue;
      }
      const double A = h10 - h00, B = h01 - h00, C = h00 - h10 - h01 + h11;
      // The patch h(u, v) = h00 + A u + B v + C u v along u = ua + s dx, v = va + s dy.
      const double ua = ox + ta * dx - (ci + 0.5), va = oy + ta * dy - (cj + 0.5);
      const Quadratic f{-C * dx * dy, dz - (A * dx + B * dy + C * (ua * dy + va * dx)), oz + ta * dz - (h00 + A * ua + B * va + C * ua * va)};
      if (f.c <= 0.0) return {true, ta};  // only by rounding: the previous piece ended a hair above
      if (const double s = first_root(f, tb - ta); !std::isnan(s)) return {true, std::min(ta + s, tb)};
    }
    if (last) break;
    ta = tb;
  }
  return {};
}

}  // namespace nbsim::relief

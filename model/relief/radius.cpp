// The safety radius (radius.h; heightfield.h's conventions): the robust walk's step length per
// texel, computed once per heightfield on the host side, and the check of a radius map against it.
//
// Exact per profile, not sampled: along a horizontal line from the start p, inside one cell the
// surface is g(s) = alpha + beta s + gamma s^2 (a bilinear patch along a line, s the distance from
// p). The slope from the start m(s) = (g(s) - g(0)) / s has m'(s) = phi(s) / s^2 with
// phi(s) = s g'(s) - (g(s) - g(0)) = gamma s^2 + g(0) - alpha, which is monotone in s inside the
// cell. So the first s where m starts to decrease is found per cell in closed form: at the cell's
// entry when phi < 0 there and gamma >= 0, else where gamma s^2 = alpha - g(0). The cells come
// from a walk over the cell grid (Amanatides & Woo) that crosses planar ground in jumps (CellMap
// below), so that a flat floor costs a few steps instead of 2 per texel, and a start point inside
// a wide plane needs no walk at all. A concave start (gamma < 0
// in the first cell; every cell with a twist, C != 0, has concave directions) gives r = 0: a ray
// just under the patch's tangent enters and leaves it within any distance. So on a twisted field
// (fbm: almost every cell) the radius is 0 almost everywhere.
//
// Start points: the samples x samples grid of each texel's square (corners included); a grid point
// on a square's edge is shared by its neighbours, so its result is cached. Per direction, the walk
// stops at the texel's current minimum (whole texels): a direction can only lower it. Directions
// go in bit-reversed order (opposite sides of the circle first), so failing ones come early.
#include "model/relief/radius.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "model/common/error.h"

namespace nbsim::relief {
namespace {

// Tunable: phi this far below 0 (height units) still counts as 0: phi's rounding (~1e-16 per texel
// of travel) must not make a plane fail; a slope decrease this small cannot make a second crossing
// that any walk resolves.
constexpr double kPhiTolerance = 1e-12;
// Tunable: a failure distance this close under a whole number counts as that number (distances
// are often exactly whole, and their double a rounding below).
constexpr double kWholeTolerance = 1e-9;

// The bilinear patch of every cell a walk of max_radius texels from the field's square can reach
// (beyond them every texel is virtual: the plane z = 0), h(u, v) = h00 + A u + B v + C u v, and
// where the surface is one plane over a neighbourhood, as a chessboard distance map, so that a walk
// crosses planar ground (flat floors, the step's ramp) in a few jumps. A cell is a seed (0) unless
// it is planar (no twist: C = 0) and every 8-neighbour is planar with the same slopes (A, B); then,
// since 8-neighbours share a corner, they lie in one plane, and every cell within Chebyshev distance
// plane - 1 lies in that plane too. On a plane the slope from the start is constant
// (phi = g(0) - alpha), so a plane that passes at one cell passes at all of them.
struct CellMap {
  struct Cell {
    double h00 = 0.0, A = 0.0, B = 0.0, C = 0.0;
    int plane = 0;  // 0: a seed; k >= 1: the distance to the nearest seed
  };
  int first = 0, side = 0;  // cells ci, cj in [first, first + side)
  std::vector<Cell> cells;

  CellMap(const Heightfield& field, int max_radius) : first(-max_radius - 3), side(field.size + 2 * max_radius + 6) {
    cells.resize(static_cast<std::size_t>(side) * static_cast<std::size_t>(side));
    for (int b = 0; b < side; ++b) {
      for (int a = 0; a < side; ++a) {
        const int ci = first + a, cj = first + b;
        const double h00 = field.at(ci, cj), h10 = field.at(ci + 1, cj), h01 = field.at(ci, cj + 1), h11 = field.at(ci + 1, cj + 1);
        cells[index(a, b)] = {h00, h10 - h00, h01 - h00, h00 - h10 - h01 + h11, 0};
      }
    }
    const int far = 2 * side;
    for (int b = 0; b < side; ++b) {
      for (int a = 0; a < side; ++a) {
        const Cell& here = cells[index(a, b)];
        bool interior = here.C == 0.0;
        for (int nb = std::max(b - 1, 0); nb <= std::min(b + 1, side - 1) && interior; ++nb)
          for (int na = std::max(a - 1, 0); na <= std::min(a + 1, side - 1) && interior; ++na) {
            const Cell& there = cells[index(na, nb)];
            interior = there.C == 0.0 && there.A == here.A && there.B == here.B;
          }
        cells[index(a, b)].plane = interior ? far : 0;
      }
    }
    // Two passes of the chessboard distance transform (outside the map is one plane, z = 0).
    for (int b = 0; b < side; ++b)
      for (int a = 0; a < side; ++a)
        if (int& d = cells[index(a, b)].plane; d != 0)
          for (const auto [na, nb] : {std::array{a - 1, b}, std::array{a - 1, b - 1}, std::array{a, b - 1}, std::array{a + 1, b - 1}})
            if (na >= 0 && nb >= 0 && na < side) d = std::min(d, cells[index(na, nb)].plane + 1);
    for (int b = side - 1; b >= 0; --b)
      for (int a = side - 1; a >= 0; --a)
        if (int& d = cells[index(a, b)].plane; d != 0)
          for (const auto [na, nb] : {std::array{a + 1, b}, std::array{a + 1, b + 1}, std::array{a, b + 1}, std::array{a - 1, b + 1}})
            if (na < side && nb < side && na >= 0) d = std::min(d, cells[index(na, nb)].plane + 1);
  }
  std::size_t index(int a, int b) const noexcept { return static_cast<std::size_t>(b) * side + a; }
  const Cell& at(int ci, int cj) const noexcept {
    static const Cell zero{};  // outside the map (never reached): the zero plane, no jump
    const int a = ci - first, b = cj - first;
    return (a < 0 || b < 0 || a >= side || b >= side) ? zero : cells[index(a, b)];
  }
};

// floor for the cell coordinates of a walk (well inside int range): a truncation, no libm call.
int floor_int(double x) noexcept {
  const int t = static_cast<int>(x);
  return t - (t > x);
}

// A horizontal direction with what the cell walk needs of it.
struct Direction {
  double dx = 0.0, dy = 0.0;
  double inv_dx = 0.0, inv_dy = 0.0;    // 1 / d (infinite for 0)
  double delta_x = 0.0, delta_y = 0.0;  // the distance between two x (y) boundaries: |1 / d|
  int step_i = 0, step_j = 0;           // +1 or -1

  Direction(double x, double y) : dx(x), dy(y) {
    const double inf = std::numeric_limits<double>::infinity();
    inv_dx = dx != 0.0 ? 1.0 / dx : inf;
    inv_dy = dy != 0.0 ? 1.0 / dy : inf;
    delta_x = std::abs(inv_dx);
    delta_y = std::abs(inv_dy);
    step_i = dx > 0.0 ? 1 : -1;
    step_j = dy > 0.0 ? 1 : -1;
  }
};

// The point's radius: min over directions of the first s where the slope from the start
// decreases, in whole texels, at most `limit`.
int point_radius(const Heightfield& field, const CellMap& cells, double px, double py, int limit,
                 const std::vector<Direction>& dirs) {
  const double g0 = surface_height(field, px, py);
  const double x0 = px - 0.5, y0 = py - 0.5;  // cell space: cell (ci, cj) is [ci, ci + 1] x [cj, cj + 1]
  // On a plane reaching past the limit in every direction (a walk of `limit` texels from a point
  // of the cell ends at most limit + 1 cells away), every profile is a line: phi = 0 throughout.
  if (cells.at(floor_int(x0), floor_int(y0)).plane >= limit + 2) return limit;
  const double inf = std::numeric_limits<double>::infinity();
  int best = limit;
  for (const Direction& dir : dirs) {
    if (best == 0) break;
    const double dx = dir.dx, dy = dir.dy;
    int ci = 0, cj = 0;
    double next_x = inf, next_y = inf;
    // Amanatides-Woo set-up at distance s; a point on a boundary, heading to the lower side, is in
    // the lower cell.
    auto enter = [&](double s) {
      const double x = x0 + s * dx, y = y0 + s * dy;
      ci = floor_int(x);
      cj = floor_int(y);
      if (dx < 0.0 && ci == x) --ci;
      if (dy < 0.0 && cj == y) --cj;
      next_x = dx > 0.0 ? (ci + 1 - x0) * dir.inv_dx : dx < 0.0 ? (ci - x0) * dir.inv_dx : inf;
      next_y = dy > 0.0 ? (cj + 1 - y0) * dir.inv_dy : dy < 0.0 ? (cj - y0) * dir.inv_dy : inf;
    };
    enter(0.0);
    const double end = best;
    double sa = 0.0;
    while (sa < end) {
      const bool along_x = next_x < next_y;  // the next boundary crossed is an x boundary
      const double sb = std::min(along_x ? next_x : next_y, end);
      if (sb > sa) {
        const CellMap::Cell& cell = cells.at(ci, cj);
        // phi at the entry from the patch's local (u, v) there (no extrapolation over the walk),
        // then phi(s) = gamma s^2 + k with k = g(0) - alpha.
        const double ua = x0 + sa * dx - ci, va = y0 + sa * dy - cj;
        const double g_a = cell.h00 + cell.A * ua + cell.B * va + cell.C * ua * va;
        const double slope_a = cell.A * dx + cell.B * dy + cell.C * (ua * dy + va * dx);
        const double phi_a = sa * slope_a - (g_a - g0);
        const double gamma = cell.C * dx * dy;
        const double k = phi_a - gamma * sa * sa;
        double fail = -1.0;
        if (phi_a < -kPhiTolerance) {
          fail = sa;
        } else if (gamma < 0.0 && gamma * sb * sb + k < -kPhiTolerance) {
          fail = std::clamp(std::sqrt((k + kPhiTolerance) / -gamma), sa, sb);
        }
        if (fail >= 0.0) {
          best = std::min(best, static_cast<int>(std::floor(fail + kWholeTolerance)));
          break;
        }
        // The plane passes here, so for plane - 1 more texels of travel in any direction.
        if (cell.plane >= 2) {
          const double jump = sa + (cell.plane - 1);
          if (jump >= end) break;
          enter(jump);
          sa = jump;
          continue;
        }
      }
      if (sb >= end) break;
      sa = sb;  // written without branches: which axis steps is the loop's unpredictable choice
      ci += along_x ? dir.step_i : 0;
      cj += along_x ? 0 : dir.step_j;
      next_x += along_x ? dir.delta_x : 0.0;
      next_y += along_x ? 0.0 : dir.delta_y;
    }
  }
  return best;
}

}  // namespace

SafetyRadius safety_radius(const Heightfield& field, int max_radius, int directions, int samples) {
  check_heightfield(field, "the safety radius's heightfield");
  if (max_radius < 1 || max_radius > 255) throw InputError(fmt::format("the safety radius's max_radius must be 1 to 255, got {}", max_radius));
  if (directions < 8) throw InputError(fmt::format("the safety radius needs at least 8 directions, got {}", directions));
  if (samples < 2) throw InputError(fmt::format("the safety radius needs at least 2 samples a side, got {}", samples));

  // The directions 2 pi k / directions in bit-reversed order of k (0, 1/2, 1/4, 3/4, ... of the
  // circle): a point's failing directions (a concave quadrant, the side of a ridge) come early,
  // so the walks in the other directions stop early too. The minimum does not depend on the order.
  int bits = 0;
  while ((1 << bits) < directions) ++bits;
  std::vector<Direction> dirs;
  for (int r = 0; r < (1 << bits); ++r) {
    int k = 0;
    for (int b = 0; b < bits; ++b) k |= ((r >> b) & 1) << (bits - 1 - b);
    if (k >= directions) continue;
    const double angle = 2.0 * std::numbers::pi * k / directions;
    // The axis directions exactly (cos(pi / 2) is 6e-17, not 0): a walk along a boundary stays on it.
    const auto exact = [](double c) { return std::abs(c) < 1e-15 ? 0.0 : c; };
    dirs.emplace_back(exact(std::cos(angle)), exact(std::sin(angle)));
  }

  const CellMap cells(field, max_radius);
  // Grid point (gx, gy) is (gx / per, gy / per); texel (i, j) uses gx in [i per, (i + 1) per].
  // A point's result min(r, limit) is cached with its limit, and reused while the limit is at
  // least what the texel asks for.
  const int n = field.size, per = samples - 1, grid = n * per + 1;
  struct Cached {
    int value = 0, limit = -1;  // limit -1: not computed yet
  };
  std::vector<Cached> cache(static_cast<std::size_t>(grid) * static_cast<std::size_t>(grid));
  // The texel's points, its centre first (a corner of four cells: it finds most zeros at once).
  std::vector<std::array<int, 2>> order;
  order.push_back({per / 2, per / 2});
  for (int b = 0; b <= per; ++b)
    for (int a = 0; a <= per; ++a)
      if (a != per / 2 || b != per / 2) order.push_back({a, b});

  SafetyRadius r;
  r.size = n;
  r.radius.resize(static_cast<std::size_t>(n) * static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      int m = max_radius;
      for (const auto& [a, b] : order) {
        if (m == 0) break;
        const int gx = i * per + a, gy = j * per + b;
        Cached& c = cache[static_cast<std::size_t>(gy) * grid + gx];
        if (c.limit < m) c = {point_radius(field, cells, static_cast<double>(gx) / per, static_cast<double>(gy) / per, m, dirs), m};
        m = std::min(m, c.value);  // c.value = min(r, c.limit) with c.limit >= m
      }
      r.radius[static_cast<std::size_t>(j) * n + i] = static_cast<float>(m);
    }
  }
  return r;
}

std::string radius_problem(const Heightfield& field, const SafetyRadius& r, int max_radius) {
  if (std::string problem = heightfield_problem(field); !problem.empty()) return "the heightfield " + problem;
  if (max_radius < 1 || max_radius > 255) return fmt::format("max_radius {} is outside 1 to 255", max_radius);
  const int n = field.size;
  if (r.size != n) return fmt::format("has size {}, but the heightfield's is {}", r.size, n);
  const std::size_t needed = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  if (r.radius.size() != needed) return fmt::format("has {} radii, but {} x {} needs {}", r.radius.size(), n, n, needed);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const float v = r.radius[static_cast<std::size_t>(j) * n + i];
      if (std::isnan(v)) return fmt::format("texel ({}, {}) has radius NaN", i, j);
      if (v < 0.0f) return fmt::format("texel ({}, {}) has radius {}, which is negative", i, j, v);
      if (std::isfinite(v) && v != std::floor(v)) return fmt::format("texel ({}, {}) has radius {}, which is not whole", i, j, v);
    }
  }
  const SafetyRadius allowed = safety_radius(field, max_radius);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const std::size_t t = static_cast<std::size_t>(j) * n + i;
      if (r.radius[t] > allowed.radius[t])
        return fmt::format("texel ({}, {}) has radius {}, but the heightfield allows at most {}", i, j, r.radius[t], allowed.radius[t]);
    }
  }
  return {};
}

}  // namespace nbsim::relief

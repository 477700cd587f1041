// The paper's safety radius (unblocked rays, an allowed error); see paper_radius.h.
#include "model/relief/paper_radius.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "model/common/error.h"

namespace nbsim::relief {

namespace {

// Tunable: a slope this much under the back limit still counts as equal, so that the rounding of
// slopes along a plane (equal in exact arithmetic) never makes a plane fail.
constexpr double kSlopeTolerance = 1e-9;

// The upper convex hull of points in increasing x (Andrew's monotone chain): the back profile's
// hull, which every unblocked line lies above.
void upper_hull(const std::vector<std::array<double, 2>>& pts, std::vector<std::array<double, 2>>& hull) {
  hull.clear();
  for (const auto& p : pts) {
    while (hull.size() >= 2) {
      const auto& a = hull[hull.size() - 2];
      const auto& b = hull[hull.size() - 1];
      // Drop b when it lies on or below the segment a -> p.
      if ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) >= 0.0) hull.pop_back();
      else break;
    }
    hull.push_back(p);
  }
}

}  // namespace

std::string paper_radius_problem(const PaperRadiusOptions& o) {
  if (!(o.epsilon >= 0.0 && o.epsilon <= 1.0)) return fmt::format("epsilon {} is outside 0 .. 1 (box heights)", o.epsilon);
  if (o.directions < 4 || o.directions > 4096) return fmt::format("{} directions: 4 to 4096", o.directions);
  if (o.samples < 2 || o.samples > 64) return fmt::format("{} start points a side: 2 to 64", o.samples);
  if (!(o.step >= 0.05 && o.step <= 1.0)) return fmt::format("profile step {} texels is outside 0.05 .. 1", o.step);
  return {};
}

double paper_point_radius(const Heightfield& field, double px, double py, double dx, double dy, double limit,
                          const PaperRadiusOptions& o) {
  const double n = static_cast<double>(field.size);
  const double h = o.step;
  const auto g = [&](double s) { return surface_height(field, px + s * dx, py + s * dy); };
  // Behind p: back to where the ray's horizontal path enters the box's square [0, N]^2 (beyond it the
  // ray is outside the box, unblocked); a ray that entered through the top face is above every
  // height behind its entry, so the whole range back to the square's edge counts.
  // The distance behind p within the square along both axes: the smaller of the two entries.
  double behind = std::numeric_limits<double>::infinity();
  if (dx > 0.0) behind = std::min(behind, px / dx);
  if (dx < 0.0) behind = std::min(behind, (n - px) / -dx);
  if (dy > 0.0) behind = std::min(behind, py / dy);
  if (dy < 0.0) behind = std::min(behind, (n - py) / -dy);
  if (!std::isfinite(behind)) behind = 0.0;
  behind = std::max(behind, 0.0);
  static thread_local std::vector<std::array<double, 2>> pts, hull;
  pts.clear();
  const int nb = static_cast<int>(std::floor(behind / h));
  pts.push_back({-behind, g(-behind)});
  for (int i = nb; i >= 1; --i) {
    const double s = -h * i;
    if (s > -behind) pts.push_back({s, g(s)});
  }
  pts.push_back({0.0, g(0.0)});
  upper_hull(pts, hull);
  // Ahead: s2 = j h, s1 = k h (0 < k < j).
  static thread_local std::vector<double> ahead;
  const int kmax = static_cast<int>(std::ceil(limit / h)) + 1;
  ahead.assign(static_cast<std::size_t>(kmax) + 1, 0.0);
  for (int k = 0; k <= kmax; ++k) ahead[static_cast<std::size_t>(k)] = g(h * k);
  for (int j = 2; j <= kmax; ++j) {
    const double s2 = h * j, c = ahead[static_cast<std::size_t>(j)];
    // The steepest line from (s2, c) back that stays above the back hull: the least slope to a hull point.
    double m_back = std::numeric_limits<double>::infinity();
    for (const auto& p : hull) m_back = std::min(m_back, (c - p[1]) / (s2 - p[0]));
    // The least slope from a point epsilon under the surface ahead of p to (s2, c).
    double m_dip = std::numeric_limits<double>::infinity();
    for (int k = 1; k < j; ++k) {
      const double s1 = h * k;
      m_dip = std::min(m_dip, (c - ahead[static_cast<std::size_t>(k)] + o.epsilon) / (s2 - s1));
    }
    if (m_dip < m_back - kSlopeTolerance) return std::max(0.0, s2 - h);
  }
  return limit;
}

SafetyRadius paper_safety_radius(const Heightfield& field, int max_radius, const PaperRadiusOptions& o) {
  if (const std::string p = paper_radius_problem(o); !p.empty()) throw InputError("the paper's safety radius: " + p);
  if (max_radius < 1 || max_radius > 255) throw InputError(fmt::format("max_radius {} is outside 1 .. 255", max_radius));
  const int n = field.size;
  const int d = o.directions, m = o.samples;
  const double limit = static_cast<double>(max_radius) + 1.0;
  // Per start point of the (N (m - 1) + 1)^2 lattice (shared by neighbouring texels) and direction.
  const int side = n * (m - 1) + 1;
  std::vector<std::array<double, 2>> dirs(static_cast<std::size_t>(d));
  for (int k = 0; k < d; ++k) {
    const double angle = 2.0 * std::numbers::pi * (k + 0.5) / d;
    dirs[static_cast<std::size_t>(k)] = {std::cos(angle), std::sin(angle)};
  }
  std::vector<float> point(static_cast<std::size_t>(side) * static_cast<std::size_t>(side) * static_cast<std::size_t>(d));
  for (int b = 0; b < side; ++b)
    for (int a = 0; a < side; ++a) {
      const double px = static_cast<double>(a) / (m - 1), py = static_cast<double>(b) / (m - 1);
      for (int k = 0; k < d; ++k) {
        const auto [dx, dy] = dirs[static_cast<std::size_t>(k)];
        point[(static_cast<std::size_t>(b) * side + a) * d + k] = static_cast<float>(paper_point_radius(field, px, py, dx, dy, limit, o));
      }
    }
  SafetyRadius out{n, std::vector<float>(static_cast<std::size_t>(n) * static_cast<std::size_t>(n), 0.0f)};
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      double texel = o.combine == RadiusCombine::Max ? 0.0 : limit;
      for (int k = 0; k < d; ++k) {
        double worst = limit;  // the least over the texel's start points, this direction
        for (int v = 0; v < m; ++v)
          for (int u = 0; u < m; ++u) {
            const int a = i * (m - 1) + u, b = j * (m - 1) + v;
            worst = std::min(worst, static_cast<double>(point[(static_cast<std::size_t>(b) * side + a) * d + k]));
          }
        texel = o.combine == RadiusCombine::Max ? std::max(texel, worst) : std::min(texel, worst);
      }
      out.radius[static_cast<std::size_t>(j) * n + i] = static_cast<float>(std::clamp(std::floor(texel), 0.0, static_cast<double>(max_radius)));
    }
  return out;
}

}  // namespace nbsim::relief

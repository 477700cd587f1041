// The procedural closed shapes; see shapes.h.
#include "model/mesh/shapes.h"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <numeric>

#include "model/common/error.h"

namespace nbsim::mesh {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

void require(bool ok, std::string_view what) {
  if (!ok) throw InputError(fmt::format("shape parameters: {}", what));
}

Vec3f to_float(const Vec3d& p) {
  return {static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])};
}
Vec3d sub(const Vec3d& a, const Vec3d& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3d cross(const Vec3d& a, const Vec3d& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3d& a, const Vec3d& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3d normalized(const Vec3d& a) {
  const double n = std::sqrt(dot(a, a));
  return {a[0] / n, a[1] / n, a[2] / n};
}
std::uint32_t u32(std::size_t i) { return static_cast<std::uint32_t>(i); }

// A tube of radius r around curve(s), s in [0, 1]: `samples` rings of `sides` vertices. A loop
// (curve(0) == curve(1)) joins its last ring to its first; an open tube gets a flat cap at each end.
// Rings lie in the curve's normal plane, along its Frenet frame (normal N toward the centre of
// curvature, binormal B = T x N), from central differences of the curve.
void append_tube(TriMesh& m, const std::function<Vec3d(double)>& curve, int samples, int sides, double r, bool loop) {
  const auto base = m.vertices.size();
  const int rings = loop ? samples : samples + 1;
  const double h = 1e-4;
  for (int i = 0; i < rings; ++i) {
    const double s = double(i) / samples;
    const Vec3d c = curve(s), ahead = curve(s + h), behind = curve(s - h);
    const Vec3d t = normalized(sub(ahead, behind));
    const Vec3d second = sub(sub(ahead, c), sub(c, behind));
    const Vec3d n = normalized(sub(second, {t[0] * dot(second, t), t[1] * dot(second, t), t[2] * dot(second, t)}));
    const Vec3d b = cross(t, n);
    for (int j = 0; j < sides; ++j) {
      const double a = kTwoPi * j / sides;
      const double cn = std::cos(a) * r, sb = std::sin(a) * r;
      m.vertices.push_back(to_float({c[0] + cn * n[0] + sb * b[0], c[1] + cn * n[1] + sb * b[1],
                                     c[2] + cn * n[2] + sb * b[2]}));
    }
  }
  auto at = [&](int i, int j) { return u32(base + std::size_t(i % rings) * sides + std::size_t(j % sides)); };
  // Outward: the vertex moves along cos(a) N + sin(a) B, and (d/da) x (d/ds) points out of the tube.
  const int segments = loop ? rings : rings - 1;
  for (int i = 0; i < segments; ++i) {
    for (int j = 0; j < sides; ++j) {
      m.triangles.push_back({at(i, j), at(i, j + 1), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i + 1, j)});
    }
  }
  if (loop) return;
  // Caps: the ring turns counter-clockwise about T, so the start cap (facing -T) runs backwards.
  const auto start = u32(m.vertices.size());
  m.vertices.push_back(to_float(curve(0.0)));
  const auto end = u32(m.vertices.size());
  m.vertices.push_back(to_float(curve(1.0)));
  for (int j = 0; j < sides; ++j) {
    m.triangles.push_back({start, at(0, j + 1), at(0, j)});
    m.triangles.push_back({end, at(rings - 1, j), at(rings - 1, j + 1)});
  }
}

// A UV sphere about the origin, z up; `inward` reverses every triangle.
void append_sphere(TriMesh& m, int rings, int segments, double radius, bool inward) {
  const auto base = u32(m.vertices.size());
  m.vertices.push_back(to_float({0.0, 0.0, radius}));
  for (int i = 1; i <= rings; ++i) {
    const double theta = std::numbers::pi * i / (rings + 1);
    for (int j = 0; j < segments; ++j) {
      const double phi = kTwoPi * j / segments;
      m.vertices.push_back(to_float({radius * std::sin(theta) * std::cos(phi), radius * std::sin(theta) * std::sin(phi),
                                     radius * std::cos(theta)}));
    }
  }
  m.vertices.push_back(to_float({0.0, 0.0, -radius}));
  const auto north = base, south = u32(m.vertices.size() - 1);
  auto at = [&](int ring, int j) { return base + 1 + u32(std::size_t(ring - 1) * segments + std::size_t(j % segments)); };
  auto add = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    if (inward) std::swap(b, c);
    m.triangles.push_back({a, b, c});
  };
  // Outward: polar angle then azimuth, (d/dtheta) x (d/dphi) points out.
  for (int j = 0; j < segments; ++j) {
    add(north, at(1, j), at(1, j + 1));
    for (int i = 1; i < rings; ++i) {
      add(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      add(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
    add(south, at(rings, j + 1), at(rings, j));
  }
}

}  // namespace

TriMesh make_uv_sphere(const SphereParams& p) {
  require(p.rings >= 1 && p.segments >= 3, "a sphere needs rings >= 1 and segments >= 3");
  require(std::isfinite(p.radius) && p.radius > 0.0, "a sphere needs a positive radius");
  TriMesh m;
  append_sphere(m, p.rings, p.segments, p.radius, false);
  return m;
}

TriMesh make_torus_knot(const TorusKnotParams& p) {
  require(p.p >= 1 && p.q >= 1 && std::gcd(p.p, p.q) == 1, "a torus knot needs coprime p, q >= 1");
  require(p.curve_samples >= 3 && p.tube_sides >= 3, "a torus knot needs curve_samples >= 3 and tube_sides >= 3");
  require(p.major_radius > p.minor_radius && p.minor_radius > 0.0 && p.tube_radius > 0.0,
          "a torus knot needs major_radius > minor_radius > 0 and tube_radius > 0");
  TriMesh m;
  const auto curve = [&p](double s) -> Vec3d {
    const double t = kTwoPi * s;
    const double rr = p.major_radius + p.minor_radius * std::cos(p.q * t);
    return {rr * std::cos(p.p * t), rr * std::sin(p.p * t), p.minor_radius * std::sin(p.q * t)};
  };
  append_tube(m, curve, p.curve_samples, p.tube_sides, p.tube_radius, true);
  return m;
}

TriMesh make_nested_shells(const NestedParams& p) {
  require(p.shells >= 1 && p.rings >= 1 && p.segments >= 3,
          "nested shells need shells >= 1, rings >= 1 and segments >= 3");
  TriMesh m;
  for (int i = 0; i < p.shells; ++i) append_sphere(m, p.rings, p.segments, double(p.shells - i) / p.shells, i % 2 == 1);
  return m;
}

TriMesh make_beads(const BeadsParams& p) {
  require(p.core_shells >= 1 && p.beads >= 0 && p.rings >= 1 && p.segments >= 3,
          "beads need core_shells >= 1, beads >= 0, rings >= 1 and segments >= 3");
  TriMesh m = make_nested_shells({.shells = p.core_shells, .rings = p.rings, .segments = p.segments});
  const double length = std::sqrt(p.axis[0] * p.axis[0] + p.axis[1] * p.axis[1] + p.axis[2] * p.axis[2]);
  require(length > 0.0 && std::isfinite(length), "beads need a nonzero axis");
  constexpr double kRadius = 0.5, kGap = 0.1;
  for (int b = 0; b < p.beads; ++b) {
    const std::size_t first = m.vertices.size();
    append_sphere(m, p.rings, p.segments, kRadius, false);
    const double along = 1.0 + kGap + kRadius + b * (2.0 * kRadius + kGap);
    for (std::size_t v = first; v < m.vertices.size(); ++v)
      for (int k = 0; k < 3; ++k) m.vertices[v][static_cast<std::size_t>(k)] += static_cast<float>(along * p.axis[static_cast<std::size_t>(k)] / length);
  }
  return m;
}

TriMesh make_box(float lo, float hi) { return make_box({lo, lo, lo}, {hi, hi, hi}); }

TriMesh make_box(const std::array<float, 3>& lo, const std::array<float, 3>& hi) {
  TriMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.push_back({i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1], i & 4 ? hi[2] : lo[2]});
  constexpr std::uint32_t kFaces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : kFaces) {
    m.triangles.push_back({f[0], f[1], f[2]});
    m.triangles.push_back({f[0], f[2], f[3]});
  }
  return m;
}

TriMesh make_coil(const CoilParams& p) {
  require(p.turns >= 1 && p.samples_per_turn >= 3 && p.tube_sides >= 3,
          "a coil needs turns >= 1, samples_per_turn >= 3 and tube_sides >= 3");
  require(p.coil_radius > p.tube_radius && p.tube_radius > 0.0 && p.pitch > 2.0 * p.tube_radius,
          "a coil needs coil_radius > tube_radius > 0 and pitch > 2 tube_radius");
  TriMesh m;
  const auto curve = [&p](double s) -> Vec3d {
    const double a = kTwoPi * p.turns * s;
    return {p.coil_radius * std::cos(a), p.coil_radius * std::sin(a), p.pitch * p.turns * s};
  };
  append_tube(m, curve, p.turns * p.samples_per_turn, p.tube_sides, p.tube_radius, false);
  return m;
}

namespace {
constexpr ShapeEntry kShapes[] = {
    {"sphere", "UV sphere, 31 rings x 32 segments + 2 poles = 994 vertices (the paper's), d = 2", "", 0, 0, 0,
     [](int) { return make_uv_sphere(); }},
    {"knot", "(2, 3) torus-knot tube, 720 x 32 = 23,040 vertices", "", 0, 0, 0,
     [](int) { return make_torus_knot(); }},
    {"nested", "k concentric spheres, alternately oriented (hollow shells), d = 2k", "shells", 3, 1, 16,
     [](int k) { return make_nested_shells({.shells = k}); }},
    {"coil", "helical tube spring with capped ends, d = 2 turns along its axis", "turns", 4, 1, 16,
     [](int n) { return make_coil({.turns = n}); }},
    {"beads", "K nested shells with M beads strung after them along x, d from 2K across to 2(K + M) along", "KM (two digits)", 12,
     10, 99, [](int km) { return make_beads({.core_shells = km / 10, .beads = km % 10}); }},
};
}  // namespace

std::span<const ShapeEntry> shape_table() { return kShapes; }

TriMesh make_shape(std::string_view name, std::optional<int> parameter) {
  for (const ShapeEntry& e : kShapes) {
    if (e.name != name) continue;
    if (parameter && e.parameter.empty())
      throw InputError(fmt::format("shape '{}' takes no parameter (given {})", name, *parameter));
    const int value = parameter.value_or(e.default_parameter);
    if (value < e.min_parameter || value > e.max_parameter)
      throw InputError(fmt::format("shape '{}': {} = {} is outside [{}, {}]", name, e.parameter, value,
                                   e.min_parameter, e.max_parameter));
    return e.make(value);
  }
  std::string names;
  for (const ShapeEntry& e : kShapes) names += fmt::format("{}{}", names.empty() ? "" : ", ", e.name);
  throw InputError(fmt::format("unknown shape '{}' (known: {})", name, names));
}

}  // namespace nbsim::mesh

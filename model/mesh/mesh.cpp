// The mesh check and the unit-cube placement; see mesh.h.
#include "model/mesh/mesh.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "model/common/error.h"

namespace nbsim::mesh {
namespace {

std::string point_text(const Vec3f& p) { return fmt::format("({}, {}, {})", p[0], p[1], p[2]); }

// A position's key for welding: the three coordinates' bits, with -0.0 folded onto +0.0.
struct PositionKey {
  std::array<std::uint32_t, 3> bits;
  bool operator==(const PositionKey&) const = default;
};
struct PositionHash {
  std::size_t operator()(const PositionKey& k) const noexcept {
    std::uint64_t h = 0xcbf29ce484222325ull;
    for (std::uint32_t b : k.bits) h = (h ^ b) * 0x100000001b3ull;
    return static_cast<std::size_t>(h);
  }
};
PositionKey key_of(const Vec3f& p) {
  PositionKey k{};
  for (int i = 0; i < 3; ++i) k.bits[i] = std::bit_cast<std::uint32_t>(p[i] == 0.0f ? 0.0f : p[i]);
  return k;
}

// One use of an edge by a triangle: the welded endpoints in ascending order, whether the triangle
// traverses it from low to high, and the triangle.
struct EdgeUse {
  std::uint64_t key;  // low << 32 | high
  bool forward;
  std::uint32_t triangle;
  bool operator<(const EdgeUse& o) const { return key != o.key ? key < o.key : triangle < o.triangle; }
};

}  // namespace

MeshReport check_mesh(const TriMesh& m) {
  MeshReport r;
  r.vertex_count = m.vertices.size();
  r.triangle_count = m.triangles.size();
  auto note = [&r](std::string s) {
    if (r.first_problem.empty()) r.first_problem = std::move(s);
  };
  if (m.triangles.empty()) note("empty mesh: no triangles");

  const std::size_t nv = m.vertices.size();
  std::vector<bool> in_range(m.triangles.size(), true);
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    for (std::uint32_t i : m.triangles[t]) {
      if (i >= nv) {
        if (r.out_of_range_triangles == 0)
          note(fmt::format("triangle {} has vertex index {}, but the mesh has {} vertices", t, i, nv));
        ++r.out_of_range_triangles;
        in_range[t] = false;
        break;
      }
    }
  }
  for (std::size_t v = 0; v < nv; ++v) {
    const Vec3f& p = m.vertices[v];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      if (r.non_finite_vertices == 0) note(fmt::format("vertex {} is not finite: {}", v, point_text(p)));
      ++r.non_finite_vertices;
    }
  }

  // Weld the used vertices by exact position.
  std::unordered_map<PositionKey, std::uint32_t, PositionHash> ids;
  std::vector<std::uint32_t> weld(nv, 0);
  std::vector<std::uint32_t> representative;  // welded id -> first vertex with that position
  for (std::size_t v = 0; v < nv; ++v) {
    auto [it, inserted] = ids.try_emplace(key_of(m.vertices[v]), static_cast<std::uint32_t>(representative.size()));
    if (inserted) representative.push_back(static_cast<std::uint32_t>(v));
    weld[v] = it->second;
  }

  std::vector<EdgeUse> uses;
  uses.reserve(m.triangles.size() * 3);
  std::vector<bool> used_position(representative.size(), false);
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    if (!in_range[t]) continue;
    const Tri& tri = m.triangles[t];
    const std::array<std::uint32_t, 3> w = {weld[tri[0]], weld[tri[1]], weld[tri[2]]};
    for (std::uint32_t id : w) used_position[id] = true;
    const bool repeated = w[0] == w[1] || w[1] == w[2] || w[0] == w[2];
    bool zero_area = false;
    if (!repeated) {
      const Vec3f& a = m.vertices[tri[0]];
      const Vec3f& b = m.vertices[tri[1]];
      const Vec3f& c = m.vertices[tri[2]];
      const double ux = double(b[0]) - a[0], uy = double(b[1]) - a[1], uz = double(b[2]) - a[2];
      const double vx = double(c[0]) - a[0], vy = double(c[1]) - a[1], vz = double(c[2]) - a[2];
      const double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
      zero_area = nx == 0.0 && ny == 0.0 && nz == 0.0;
    }
    if (repeated || zero_area) {
      if (r.degenerate_triangles == 0)
        note(fmt::format("triangle {} is degenerate ({}): corners {} {} {}", t,
                         repeated ? "two corners at one position" : "zero area", point_text(m.vertices[tri[0]]),
                         point_text(m.vertices[tri[1]]), point_text(m.vertices[tri[2]])));
      ++r.degenerate_triangles;
    }
    if (repeated) continue;
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = w[e], b = w[(e + 1) % 3];
      const std::uint64_t lo = std::min(a, b), hi = std::max(a, b);
      uses.push_back({lo << 32 | hi, a < b, static_cast<std::uint32_t>(t)});
    }
  }
  r.welded_vertex_count = static_cast<std::size_t>(std::count(used_position.begin(), used_position.end(), true));

  std::sort(uses.begin(), uses.end());
  // The first offending edge of each kind, by the lowest triangle that uses it.
  std::uint32_t first_tri[3] = {UINT32_MAX, UINT32_MAX, UINT32_MAX};
  std::string first_text[3];
  auto edge_text = [&](std::uint64_t key) {
    return point_text(m.vertices[representative[key >> 32]]) + "-" +
           point_text(m.vertices[representative[key & 0xffffffffu]]);
  };
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    int forward = 0;
    while (j < uses.size() && uses[j].key == uses[i].key) forward += uses[j++].forward ? 1 : 0;
    const std::size_t n = j - i;
    ++r.edge_count;
    int kind = -1;
    std::string text;
    if (n == 1) {
      ++r.boundary_edges;
      kind = 0;
      text = fmt::format("the edge {} of triangle {}", edge_text(uses[i].key), uses[i].triangle);
    } else if (n > 2) {
      ++r.non_manifold_edges;
      kind = 1;
      std::string tris;
      for (std::size_t k = i; k < j; ++k) tris += fmt::format("{}{}", k == i ? "" : ", ", uses[k].triangle);
      text = fmt::format("the edge {} used by triangles {}", edge_text(uses[i].key), tris);
    } else if (forward != 1) {
      ++r.inconsistent_edges;
      kind = 2;
      text = fmt::format("the edge {} traversed in the same direction by triangles {} and {}", edge_text(uses[i].key),
                         uses[i].triangle, uses[i + 1].triangle);
    }
    if (kind >= 0 && uses[i].triangle < first_tri[kind]) {
      first_tri[kind] = uses[i].triangle;
      first_text[kind] = std::move(text);
    }
    i = j;
  }
  if (r.boundary_edges)
    note(fmt::format("not closed (a hole): {} boundary edges (used by one triangle only), e.g. {}", r.boundary_edges,
                     first_text[0]));
  if (r.non_manifold_edges)
    note(fmt::format("not closed: {} non-manifold edges (used by three or more triangles), e.g. {}",
                     r.non_manifold_edges, first_text[1]));
  if (r.inconsistent_edges)
    note(fmt::format("not consistently oriented: {} edges used twice in the same direction, e.g. {}",
                     r.inconsistent_edges, first_text[2]));
  return r;
}

MeshReport require_closed(const TriMesh& m, const std::string& what) {
  MeshReport r = check_mesh(m);
  if (!r.ok()) throw InputError(what + ": " + r.first_problem);
  return r;
}

UnitCubePlacement normalize_to_unit_cube(TriMesh& m, double margin) {
  if (!(margin >= 0.0 && margin < 0.5))
    throw InputError(fmt::format("unit cube margin {} is outside [0, 0.5)", margin));
  if (m.vertices.empty()) throw InputError("cannot place an empty mesh in the unit cube");
  Vec3d lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (const Vec3f& p : m.vertices) {
    for (int i = 0; i < 3; ++i) {
      if (!std::isfinite(p[i])) throw InputError("cannot place a mesh with non-finite vertices in the unit cube");
      lo[i] = std::min(lo[i], double(p[i]));
      hi[i] = std::max(hi[i], double(p[i]));
    }
  }
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  if (!(extent > 0.0)) throw InputError("cannot place a mesh whose vertices all coincide in the unit cube");
  const double span = 1.0 - 2.0 * margin;
  UnitCubePlacement placement;
  placement.scale = span / extent;
  Vec3d start{};  // where each axis's lower bound lands
  for (int i = 0; i < 3; ++i) {
    start[i] = margin + span * (extent - (hi[i] - lo[i])) / (2.0 * extent);
    placement.offset[i] = start[i] - lo[i] * placement.scale;
  }
  for (Vec3f& p : m.vertices) {
    for (int i = 0; i < 3; ++i) {
      // (p - lo) / extent is exactly 0 and 1 at the longest axis's extremes.
      const double t = start[i] + span * ((double(p[i]) - lo[i]) / extent);
      p[i] = std::clamp(static_cast<float>(t), 0.0f, 1.0f);
    }
  }
  return placement;
}

double signed_volume(const TriMesh& m) {
  double six_v = 0.0;
  for (const Tri& t : m.triangles) {
    const Vec3f& a = m.vertices[t[0]];
    const Vec3f& b = m.vertices[t[1]];
    const Vec3f& c = m.vertices[t[2]];
    six_v += double(a[0]) * (double(b[1]) * c[2] - double(b[2]) * c[1]) -
             double(a[1]) * (double(b[0]) * c[2] - double(b[2]) * c[0]) +
             double(a[2]) * (double(b[0]) * c[1] - double(b[1]) * c[0]);
  }
  return six_v / 6.0;
}

}  // namespace nbsim::mesh

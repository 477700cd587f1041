// ShapesTest: the procedural shapes (model/mesh/shapes.h) are closed, outward, of the stated sizes,
// do not meet themselves, and reach the stated depth complexity; the shape table.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "model/common/error.h"
#include "model/mesh/crossings.h"
#include "model/mesh/shapes.h"

namespace nbsim::mesh {
namespace {

void expect_closed(const TriMesh& m, const char* what) {
  const MeshReport r = check_mesh(m);
  EXPECT_TRUE(r.ok()) << what << ": " << r.first_problem;
  EXPECT_GT(signed_volume(m), 0.0) << what << ": outward triangles give a positive volume";
}

// The paper's sphere: 994 vertices, closed, a genus-0 surface, volume near 4/3 pi.
TEST(ShapesTest, SphereHasThePapersVertexCount) {
  const TriMesh m = make_uv_sphere();
  EXPECT_EQ(m.vertices.size(), 994u);
  EXPECT_EQ(m.triangles.size(), 1984u);
  expect_closed(m, "sphere");
  const MeshReport r = check_mesh(m);
  EXPECT_EQ(static_cast<long>(r.welded_vertex_count) - static_cast<long>(r.edge_count) +
                static_cast<long>(r.triangle_count), 2) << "Euler characteristic of a sphere";
  EXPECT_NEAR(signed_volume(m), 4.0 / 3.0 * std::numbers::pi, 0.05);
}

// The torus knot: 720 x 32 = 23,040 vertices, closed, a torus (Euler characteristic 0), and its
// volume is the tube's cross-section times the curve's length (the tube does not fold).
TEST(ShapesTest, TorusKnotIsAClosedTube) {
  const TorusKnotParams p;
  const TriMesh m = make_torus_knot(p);
  EXPECT_EQ(m.vertices.size(), 23040u);
  expect_closed(m, "knot");
  const MeshReport r = check_mesh(m);
  EXPECT_EQ(static_cast<long>(r.welded_vertex_count) - static_cast<long>(r.edge_count) +
                static_cast<long>(r.triangle_count), 0) << "Euler characteristic of a torus";
  // The curve's length and its self-distance, sampled finely.
  const int n = 4000;
  std::vector<Vec3d> c(n);
  for (int i = 0; i < n; ++i) {
    const double t = 2.0 * std::numbers::pi * i / n;
    const double rr = p.major_radius + p.minor_radius * std::cos(p.q * t);
    c[i] = {rr * std::cos(p.p * t), rr * std::sin(p.p * t), p.minor_radius * std::sin(p.q * t)};
  }
  double length = 0.0, nearest_other_strand = INFINITY;
  auto dist = [&](int a, int b) {
    return std::hypot(c[a][0] - c[b][0], c[a][1] - c[b][1], c[a][2] - c[b][2]);
  };
  for (int i = 0; i < n; ++i) length += dist(i, (i + 1) % n);
  for (int i = 0; i < n; i += 4) {
    for (int j = 0; j < n; j += 2) {
      const int gap = std::min(std::abs(i - j), n - std::abs(i - j));
      if (gap * length / n > 4.0 * p.tube_radius) nearest_other_strand = std::min(nearest_other_strand, dist(i, j));
    }
  }
  EXPECT_GT(nearest_other_strand, 2.0 * p.tube_radius * 1.1) << "strands at least a tube diameter apart";
  const double tube_volume = std::numbers::pi * p.tube_radius * p.tube_radius * length;
  EXPECT_NEAR(signed_volume(m), tube_volume, 0.02 * tube_volume);
}

// Nested shells: k spheres, alternately oriented, closed together; a line through the centre
// crosses 2k surfaces, in alternating direction, so the parity flips at each.
TEST(ShapesTest, NestedShellsReachDepth2k) {
  for (int k : {3, 6, 9}) {
    const TriMesh m = make_nested_shells({.shells = k});
    expect_closed(m, "nested");
    const CrossingReference ref(m, OrthoFrame::look_along({0.0, 0.0, -1.0}));
    const CrossingCount c = ref.count({0.013, 0.007, 5.0});
    EXPECT_EQ(c.in_front + c.beyond, static_cast<std::uint32_t>(2 * k)) << "d = 2k for k = " << k;
    // Between shells 0 and 1 (radii 1 and (k-1)/k) the point is inside the material.
    const double mid = (1.0 + double(k - 1) / k) / 2.0;
    EXPECT_TRUE(ref.count({0.013, 0.007, mid}).inside()) << "k = " << k;
    const double hollow = (double(k - 1) / k + double(k - 2) / k) / 2.0;
    EXPECT_FALSE(ref.count({0.013, 0.007, hollow}).inside()) << "k = " << k;
  }
}

// The coil: closed (capped), successive turns apart, and seen along its axis a line through the
// tube's rim crosses 2 surfaces per turn.
TEST(ShapesTest, CoilDepthGrowsWithTurns) {
  for (int turns : {1, 3, 8}) {
    const CoilParams p{.turns = turns};
    const TriMesh m = make_coil(p);
    expect_closed(m, "coil");
    EXPECT_EQ(m.vertices.size(), std::size_t(turns * p.samples_per_turn + 1) * p.tube_sides + 2);
    const CrossingReference ref(m, OrthoFrame::look_along({0.0, 0.0, -1.0}));
    // A line through the helix at angle 45 degrees (mid-sample, so not on a ring's edge).
    const double a = std::numbers::pi / 4.0 + 0.001;
    const CrossingCount c = ref.count({p.coil_radius * std::cos(a), p.coil_radius * std::sin(a), 100.0});
    EXPECT_EQ(c.in_front + c.beyond, static_cast<std::uint32_t>(2 * turns)) << turns << " turns";
  }
}

// The table: every row builds a closed shape; names, parameters and refusals.
TEST(ShapesTest, TableBuildsEveryShape) {
  std::vector<std::string> names;
  for (const ShapeEntry& e : shape_table()) {
    names.emplace_back(e.name);
    const TriMesh m = make_shape(e.name);
    expect_closed(m, std::string(e.name).c_str());
  }
  EXPECT_EQ(names, (std::vector<std::string>{"sphere", "knot", "nested", "coil", "beads"}));
  EXPECT_EQ(make_shape("sphere").vertices.size(), 994u);
  EXPECT_EQ(make_shape("nested", 5).triangles.size(), make_nested_shells({.shells = 5}).triangles.size());
  EXPECT_THROW(make_shape("teapot"), InputError);
  EXPECT_THROW(make_shape("sphere", 3), InputError) << "the sphere takes no parameter";
  EXPECT_THROW(make_shape("nested", 0), InputError);
  EXPECT_THROW(make_shape("coil", 17), InputError);
  EXPECT_THROW(make_uv_sphere({.rings = 0}), InputError);
  EXPECT_THROW(make_torus_knot({.p = 2, .q = 4}), InputError) << "p, q not coprime";
  EXPECT_THROW(make_coil({.tube_radius = 0.5, .pitch = 0.7}), InputError) << "turns would touch";
  try {
    make_shape("teapot");
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("sphere, knot, nested, coil, beads"), std::string::npos) << e.what();
  }
  EXPECT_THROW(make_shape("beads", 9), InputError) << "KM: at least one core shell";
  EXPECT_THROW(make_shape("beads", 100), InputError);
  EXPECT_EQ(make_shape("beads", 43).vertices.size(), make_beads({.core_shells = 4, .beads = 3}).vertices.size());
}

// Beads: a core of K shells and M beads on a string: closed, the beads apart; a line along the
// string through the centres crosses 2(K + M) surfaces, a line across it through the core 2K, one
// across a bead 2.
TEST(ShapesTest, BeadsSpreadTheirDepthOverDirections) {
  for (const auto& [k, m] : {std::pair{1, 2}, std::pair{4, 3}, std::pair{5, 4}}) {
    const BeadsParams p{.core_shells = k, .beads = m};
    const TriMesh mesh = make_beads(p);
    expect_closed(mesh, "beads");
    double norm = 0;
    for (double a : p.axis) norm += a * a;
    norm = std::sqrt(norm);
    const Vec3d axis = {p.axis[0] / norm, p.axis[1] / norm, p.axis[2] / norm};
    // Along the string, slightly off the centres' line (not through a pole or a ring exactly).
    const Vec3d off = {0.011, -0.013, 0.007};
    const CrossingReference along(mesh, OrthoFrame::look_along(axis, {0.0, 1.0, 0.0}));
    const CrossingCount c = along.count({off[0] - 50.0 * axis[0], off[1] - 50.0 * axis[1], off[2] - 50.0 * axis[2]});
    EXPECT_EQ(c.in_front + c.beyond, static_cast<std::uint32_t>(2 * (k + m))) << "K " << k << ", M " << m;
    // Across the string (perpendicular to the axis and to y): the core alone, or one bead alone.
    const Vec3d across = {-axis[2], 0.0, axis[0]};
    const double an = std::sqrt(across[0] * across[0] + across[2] * across[2]);
    const Vec3d dir = {across[0] / an, 0.0, across[2] / an};
    const CrossingReference side(mesh, OrthoFrame::look_along(dir, {0.0, 1.0, 0.0}));
    const CrossingCount core = side.count({off[0] - 50.0 * dir[0], off[1], off[2] - 50.0 * dir[2]});
    EXPECT_EQ(core.in_front + core.beyond, static_cast<std::uint32_t>(2 * k));
    const double bead = 1.0 + 0.1 + 0.5;  // the first bead's centre along the axis
    const Vec3d at = {bead * axis[0] + off[0] - 50.0 * dir[0], bead * axis[1] + off[1], bead * axis[2] + off[2] - 50.0 * dir[2]};
    const CrossingCount one = side.count(at);
    EXPECT_EQ(one.in_front + one.beyond, 2u);
  }
}

}  // namespace
}  // namespace nbsim::mesh

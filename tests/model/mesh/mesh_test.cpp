// MeshTest: the closedness check (model/mesh/mesh.h) on a closed box, its broken variants and the
// hostile inputs, and the placement in the unit cube.
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "model/common/error.h"
#include "model/mesh/mesh.h"
#include "model/mesh/shapes.h"

namespace nbsim::mesh {
namespace {


// The same box with every triangle on its own three vertices (an STL-like soup).
TriMesh soup(const TriMesh& m) {
  TriMesh s;
  for (const Tri& t : m.triangles) {
    const auto base = static_cast<std::uint32_t>(s.vertices.size());
    for (std::uint32_t i : t) s.vertices.push_back(m.vertices[i]);
    s.triangles.push_back({base, base + 1, base + 2});
  }
  return s;
}

bool mentions(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// A closed, outward box passes, with 18 edges, and its volume is positive.
TEST(MeshTest, ClosedBoxPasses) {
  const MeshReport r = check_mesh(make_box());
  EXPECT_TRUE(r.closed()) << r.first_problem;
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.edge_count, 18u);
  EXPECT_EQ(r.welded_vertex_count, 8u);
  EXPECT_EQ(r.first_problem, "");
  EXPECT_DOUBLE_EQ(signed_volume(make_box()), 1.0) << "outward orientation gives a positive volume";
}

// Duplicated vertices at one position are welded first: a triangle soup of the box is closed.
TEST(MeshTest, SoupIsWeldedByPosition) {
  const MeshReport r = check_mesh(soup(make_box()));
  EXPECT_EQ(r.vertex_count, 36u);
  EXPECT_EQ(r.welded_vertex_count, 8u);
  EXPECT_TRUE(r.ok()) << r.first_problem;
}

// -0.0 and +0.0 are one position.
TEST(MeshTest, NegativeZeroWeldsWithZero) {
  TriMesh m = soup(make_box());
  for (Vec3f& v : m.vertices)
    for (float& c : v)
      if (c == 0.0f && (&v - m.vertices.data()) % 2 == 0) c = -0.0f;
  EXPECT_TRUE(check_mesh(m).ok()) << check_mesh(m).first_problem;
}

// A missing triangle is a hole: its three edges are boundary edges, named in the message.
TEST(MeshTest, HoleIsReportedWithItsBoundary) {
  TriMesh m = make_box();
  m.triangles.erase(m.triangles.begin() + 4);
  const MeshReport r = check_mesh(m);
  EXPECT_FALSE(r.closed());
  EXPECT_EQ(r.boundary_edges, 3u);
  EXPECT_TRUE(mentions(r.first_problem, "3 boundary edges")) << r.first_problem;
  EXPECT_TRUE(mentions(r.first_problem, "of triangle")) << r.first_problem;
  EXPECT_THROW(require_closed(m, "box"), InputError);
  try {
    require_closed(m, "box.stl");
  } catch (const InputError& e) {
    EXPECT_TRUE(mentions(e.what(), "box.stl: not closed (a hole)")) << e.what();
  }
}

// A flipped triangle leaves every edge used twice, but three of them in the same direction.
TEST(MeshTest, FlippedTriangleIsInconsistent) {
  TriMesh m = make_box();
  std::swap(m.triangles[7][1], m.triangles[7][2]);
  const MeshReport r = check_mesh(m);
  EXPECT_EQ(r.boundary_edges, 0u);
  EXPECT_EQ(r.inconsistent_edges, 3u);
  EXPECT_FALSE(r.closed());
  EXPECT_TRUE(mentions(r.first_problem, "triangles 6 and 7") || mentions(r.first_problem, "and 7"))
      << r.first_problem;
}

// A triangle repeated (a duplicate face) makes its edges non-manifold.
TEST(MeshTest, DuplicateFaceIsNonManifold) {
  TriMesh m = make_box();
  m.triangles.push_back(m.triangles[0]);
  const MeshReport r = check_mesh(m);
  EXPECT_EQ(r.non_manifold_edges, 3u);
  EXPECT_FALSE(r.closed());
  EXPECT_TRUE(mentions(r.first_problem, "non-manifold")) << r.first_problem;
}

// Two closed boxes sharing nothing are closed together.
TEST(MeshTest, TwoComponentsAreClosed) {
  TriMesh m = make_box(0.0f, 1.0f);
  const TriMesh b = make_box(2.0f, 3.0f);
  for (const Tri& t : b.triangles) m.triangles.push_back({t[0] + 8, t[1] + 8, t[2] + 8});
  m.vertices.insert(m.vertices.end(), b.vertices.begin(), b.vertices.end());
  EXPECT_TRUE(check_mesh(m).ok());
}

// The hostile inputs, each with its reason, and the message naming it.
TEST(MeshTest, BadInputIsNamed) {
  struct Case {
    TriMesh m;
    const char* expected;
    const char* why;
  };
  TriMesh out_of_range = make_box();
  out_of_range.triangles[3][2] = 99;
  TriMesh nan = make_box();
  nan.vertices[5][1] = std::numeric_limits<float>::quiet_NaN();
  TriMesh repeated = make_box();
  repeated.triangles[2] = {1, 1, 3};
  TriMesh collinear = make_box();
  collinear.vertices.push_back({0.5f, 0.0f, 0.0f});
  collinear.triangles.push_back({0, 8, 1});
  TriMesh welded_repeat = make_box();  // triangle 2 is {1, 3, 7}: its corner 1 replaced by a copy of corner 3
  welded_repeat.vertices.push_back(welded_repeat.vertices[3]);
  welded_repeat.triangles[2][0] = 8;
  const Case cases[] = {
      {TriMesh{}, "empty mesh", "no triangles at all"},
      {out_of_range, "triangle 3 has vertex index 99", "an index past the vertices"},
      {nan, "vertex 5 is not finite", "a NaN coordinate"},
      {repeated, "triangle 2 is degenerate (two corners at one position)", "a repeated index"},
      {collinear, "zero area", "three distinct collinear corners"},
      {welded_repeat, "triangle 2 is degenerate (two corners at one position)", "distinct indices, one position"},
  };
  for (const Case& c : cases) {
    const MeshReport r = check_mesh(c.m);
    EXPECT_FALSE(r.ok()) << c.why;
    EXPECT_TRUE(mentions(r.first_problem, c.expected)) << c.why << ": " << r.first_problem;
  }
  EXPECT_EQ(check_mesh(out_of_range).out_of_range_triangles, 1u);
  EXPECT_EQ(check_mesh(nan).non_finite_vertices, 1u);
  EXPECT_EQ(check_mesh(collinear).degenerate_triangles, 1u);
}

// normalize_to_unit_cube: the longest axis onto [margin, 1 - margin], the others centred, uniform.
TEST(MeshTest, NormalizeToUnitCube) {
  TriMesh m;
  m.vertices = {{-2.0f, 10.0f, 5.0f}, {6.0f, 12.0f, 5.0f}, {2.0f, 11.0f, 9.0f}};
  m.triangles = {{0, 1, 2}};
  TriMesh a = m;
  const UnitCubePlacement p = normalize_to_unit_cube(a, 0.0);
  EXPECT_DOUBLE_EQ(p.scale, 1.0 / 8.0);
  EXPECT_EQ(a.vertices[0][0], 0.0f) << "margin 0: the longest axis touches face x = 0 exactly";
  EXPECT_EQ(a.vertices[1][0], 1.0f) << "margin 0: the longest axis touches face x = 1 exactly";
  EXPECT_FLOAT_EQ(a.vertices[0][1], 0.375f) << "y extent 2/8 centred";
  EXPECT_FLOAT_EQ(a.vertices[1][1], 0.625f);
  EXPECT_FLOAT_EQ(a.vertices[0][2], 0.25f) << "z extent 4/8 centred";
  EXPECT_FLOAT_EQ(a.vertices[2][2], 0.75f);
  TriMesh b = m;
  normalize_to_unit_cube(b, 0.1);
  EXPECT_FLOAT_EQ(b.vertices[0][0], 0.1f);
  EXPECT_FLOAT_EQ(b.vertices[1][0], 0.9f);
  for (const Vec3f& v : b.vertices)
    for (int i = 0; i < 3; ++i) EXPECT_TRUE(v[i] >= 0.1f - 1e-6f && v[i] <= 0.9f + 1e-6f);
  for (const Vec3f& v : a.vertices) {
    for (int i = 0; i < 3; ++i) {
      EXPECT_GE(v[i], 0.0f);
      EXPECT_LE(v[i], 1.0f);
    }
  }
}

// Refused placements: bad margins, empty, a point, non-finite.
TEST(MeshTest, NormalizeRefusesBadInput) {
  TriMesh m = make_box();
  EXPECT_THROW(normalize_to_unit_cube(m, -0.1), InputError);
  EXPECT_THROW(normalize_to_unit_cube(m, 0.5), InputError);
  EXPECT_THROW(normalize_to_unit_cube(m, std::numeric_limits<double>::quiet_NaN()), InputError);
  TriMesh empty;
  EXPECT_THROW(normalize_to_unit_cube(empty, 0.0), InputError);
  TriMesh point;
  point.vertices = {{1.0f, 1.0f, 1.0f}, {1.0f, 1.0f, 1.0f}, {1.0f, 1.0f, 1.0f}};
  point.triangles = {{0, 1, 2}};
  EXPECT_THROW(normalize_to_unit_cube(point, 0.0), InputError);
  TriMesh inf = make_box();
  inf.vertices[0][0] = std::numeric_limits<float>::infinity();
  EXPECT_THROW(normalize_to_unit_cube(inf, 0.0), InputError);
}

}  // namespace
}  // namespace nbsim::mesh

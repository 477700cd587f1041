// CrossingsTest: the exact crossing reference (model/mesh/crossings.h) against an independent
// brute force in long double on random lines, and its tie rule on lines exactly through shared
// edges and vertices, silhouettes and edge-on faces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "model/common/error.h"
#include "model/mesh/crossings.h"
#include "model/mesh/shapes.h"

namespace nbsim::mesh {
namespace {

using LD = long double;


// The brute force: every triangle against the line o + s d in 3D, long double, Pluecker signs
// (no projection, no grid, no snapping). Valid for lines in general position (no ties).
std::vector<LD> brute_depths(const TriMesh& m, const Vec3d& o, const Vec3d& d) {
  std::vector<LD> out;
  const LD od = LD(o[0]) * d[0] + LD(o[1]) * d[1] + LD(o[2]) * d[2];
  for (const Tri& t : m.triangles) {
    LD p[3][3];
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 3; ++i) p[k][i] = LD(m.vertices[t[k]][i]) - LD(o[i]);
    auto triple = [&](const LD* a, const LD* b) {  // d . (a x b)
      return LD(d[0]) * (a[1] * b[2] - a[2] * b[1]) + LD(d[1]) * (a[2] * b[0] - a[0] * b[2]) +
             LD(d[2]) * (a[0] * b[1] - a[1] * b[0]);
    };
    const LD s0 = triple(p[0], p[1]), s1 = triple(p[1], p[2]), s2 = triple(p[2], p[0]);
    if (!((s0 > 0 && s1 > 0 && s2 > 0) || (s0 < 0 && s1 < 0 && s2 < 0))) continue;
    LD e1[3], e2[3], n[3];
    for (int i = 0; i < 3; ++i) e1[i] = p[1][i] - p[0][i], e2[i] = p[2][i] - p[0][i];
    n[0] = e1[1] * e2[2] - e1[2] * e2[1], n[1] = e1[2] * e2[0] - e1[0] * e2[2], n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    const LD s = (n[0] * p[0][0] + n[1] * p[0][1] + n[2] * p[0][2]) / (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]);
    out.push_back(od + s);
  }
  std::sort(out.begin(), out.end());
  return out;
}

Vec3d random_direction(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  for (;;) {
    const Vec3d v{g(rng), g(rng), g(rng)};
    const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (n > 1e-3) return {v[0] / n, v[1] / n, v[2] / n};
  }
}

// Random lines through a mesh: the reference agrees with the brute force on every crossing (count
// in front, count beyond, depths), and a closed mesh is always crossed an even number of times.
void compare_random_lines(const TriMesh& m, int directions, int lines_per_direction, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-0.2, 1.2);
  int crossed = 0;
  for (int k = 0; k < directions; ++k) {
    const Vec3d dir = random_direction(rng);
    const Vec3d hint = std::abs(dir[1]) < 0.9 ? Vec3d{0, 1, 0} : Vec3d{1, 0, 0};
    const CrossingReference ref(m, OrthoFrame::look_along(dir, hint));
    const Vec3d d = ref.frame().direction;
    for (int i = 0; i < lines_per_direction; ++i) {
      const Vec3d o{u(rng), u(rng), u(rng)};
      const std::vector<double> got = ref.crossing_depths(o);
      const std::vector<LD> want = brute_depths(m, o, d);
      ASSERT_EQ(got.size(), want.size()) << "direction " << k << " line " << i;
      EXPECT_EQ(got.size() % 2, 0u) << "a closed mesh is crossed an even number of times";
      for (std::size_t j = 0; j < got.size(); ++j) EXPECT_NEAR(got[j], double(want[j]), 1e-9);
      const CrossingCount c = ref.count(o);
      const double od = o[0] * d[0] + o[1] * d[1] + o[2] * d[2];
      const auto front = static_cast<std::uint32_t>(std::count_if(want.begin(), want.end(), [&](LD t) { return t < od; }));
      EXPECT_EQ(c.in_front, front);
      EXPECT_EQ(c.in_front + c.beyond + c.at_point, want.size());
      crossed += got.empty() ? 0 : 1;
    }
  }
  EXPECT_GT(crossed, directions * lines_per_direction / 4) << "the random lines must actually hit the mesh";
}

// A unit cube from 200 random directions x 20 lines.
TEST(CrossingsTest, CubeMatchesBruteForce) { compare_random_lines(make_box(), 200, 20, 1); }

// The paper's sphere, in the unit cube, from 100 random directions x 20 lines.
TEST(CrossingsTest, SphereMatchesBruteForce) {
  TriMesh m = make_uv_sphere();
  normalize_to_unit_cube(m, 0.05);
  compare_random_lines(m, 100, 20, 2);
}

// Lines exactly through the front and back faces' shared diagonal, and along a row of points on it
// and on the square's edges: each crossing counted once.
TEST(CrossingsTest, SharedDiagonalCountsOnce) {
  const CrossingReference ref(make_box(), OrthoFrame::look_along({0.0, 0.0, -1.0}));
  for (int i = 1; i < 16; ++i) {
    const double s = i / 16.0;
    const CrossingCount c = ref.count({s, s, 0.5});
    EXPECT_EQ(c.in_front, 1u) << "on the front diagonal at " << s;
    EXPECT_EQ(c.beyond, 1u) << "on the back diagonal at " << s;
    EXPECT_TRUE(c.inside());
  }
}

// Two triangles sharing a horizontal edge, and two sharing a vertical one (in both windings): a line
// through a point of the shared edge crosses exactly one of them (the rule's dy == 0 branch and its
// dy != 0 branch).
TEST(CrossingsTest, SharedHorizontalAndVerticalEdgesCountOnce) {
  TriMesh h;
  h.vertices = {{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.5f, 1.0f, 0.0f}, {0.5f, -1.0f, 0.0f}};
  h.triangles = {{0, 1, 2}, {0, 3, 1}};
  TriMesh v;
  v.vertices = {{0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, {-1.0f, 0.5f, 0.0f}, {1.0f, 0.5f, 0.0f}};
  v.triangles = {{0, 1, 2}, {0, 3, 1}};
  for (const bool horizontal : {true, false}) {
    TriMesh m = horizontal ? h : v;
    for (int winding = 0; winding < 2; ++winding) {
      const CrossingReference ref(m, OrthoFrame::look_along({0.0, 0.0, -1.0}));
      for (double s : {0.125, 0.5, 0.75}) {
        const Vec3d p = horizontal ? Vec3d{s, 0.0, 1.0} : Vec3d{0.0, s, 1.0};
        EXPECT_EQ(ref.crossing_depths(p).size(), 1u)
            << (horizontal ? "horizontal" : "vertical") << " shared edge at " << s << ", winding " << winding;
      }
      for (Tri& t : m.triangles) std::swap(t[1], t[2]);
    }
  }
}

// Lines on the box's silhouette (its edges and corners seen along z) follow the tie rule: as if
// moved by (+e, +e^2): the left (x = 0) and bottom (y = 0) sides count 2, the right and top 0,
// never 1; the side faces, edge-on, count nothing.
TEST(CrossingsTest, SilhouetteFollowsTheTieRule) {
  const CrossingReference ref(make_box(), OrthoFrame::look_along({0.0, 0.0, -1.0}));
  struct Case {
    double x, y;
    std::uint32_t total;
    const char* why;
  };
  const Case cases[] = {
      {0.0, 0.5, 2, "left side: moved right, inside"},   {1.0, 0.5, 0, "right side: moved right, outside"},
      {0.5, 1.0, 0, "top side: moved up, outside"},      {0.5, 0.0, 2, "bottom side: moved up, inside"},
      {0.0, 1.0, 0, "top-left corner: outside"},         {0.0, 0.0, 2, "bottom-left corner: inside"},
      {1.0, 1.0, 0, "top-right corner: outside"},        {1.0, 0.0, 0, "bottom-right corner: outside"},
      {0.5, 0.5, 2, "centre, on the diagonals"},         {0.25, 0.5, 2, "interior"},
  };
  for (const Case& c : cases) {
    const CrossingCount n = ref.count({c.x, c.y, 2.0});
    EXPECT_EQ(n.in_front + n.beyond, c.total) << c.why;
    EXPECT_EQ(n.beyond, c.total) << c.why << ": every crossing beyond a point in front of the box";
  }
}

// Seen along the cube's diagonal, the corner (1,1,1) is shared by six front triangles and the corner
// (0,0,0) by six back ones, projected onto one point: the line through both crosses twice; lines
// through the front's shared edges (from that corner to the silhouette) too.
TEST(CrossingsTest, SharedVertexCountsOnce) {
  const CrossingReference ref(make_box(), OrthoFrame::look_along({-1.0, -1.0, -1.0}));
  const CrossingCount c = ref.count({0.5, 0.5, 0.5});
  EXPECT_EQ(c.in_front, 1u) << "the front corner, once";
  EXPECT_EQ(c.beyond, 1u) << "the back corner, once";
  EXPECT_NEAR(c.nearest_distance, std::sqrt(0.75), 1e-9);
  for (double s : {0.1, 0.25, 0.5, 0.75, 0.9}) {
    // Points on the cube's edges from (1,1,1) toward (1,1,0), (1,0,1) and (0,1,1).
    for (const Vec3d& p : {Vec3d{1.0, 1.0, s}, Vec3d{1.0, s, 1.0}, Vec3d{s, 1.0, 1.0}}) {
      const CrossingCount e = ref.count({p[0] - 0.01, p[1] - 0.01, p[2] - 0.01});
      EXPECT_EQ(e.in_front + e.beyond, 2u) << "line through a front edge at s = " << s;
      EXPECT_EQ(e.in_front, 1u);
    }
  }
}

// Every vertex of the sphere and every edge midpoint, from many directions: the line through it
// crosses the closed surface an even number of times (a line through a shared vertex or edge is
// never counted twice or missed).
TEST(CrossingsTest, LinesThroughSphereVerticesAndEdgesAreEven) {
  TriMesh m = make_uv_sphere({.rings = 9, .segments = 12});
  normalize_to_unit_cube(m, 0.0);
  std::mt19937_64 rng(3);
  // Seen from the side with up = z, the rings' edges project onto horizontal segments (the rule's
  // dy == 0 branch); along z, the poles are vertices shared by a whole fan.
  std::vector<OrthoFrame> frames = {OrthoFrame::look_along({0, 0, -1}), OrthoFrame::look_along({0, 0, 1}),
                                    OrthoFrame::look_along({0, -1, 0}, {0, 0, 1}),
                                    OrthoFrame::look_along({1, 0, 0}, {0, 0, 1}),
                                    OrthoFrame::look_along({0.0, -1.0, 0.0001}, {1, 0, 0})};
  for (int i = 0; i < 12; ++i) frames.push_back(OrthoFrame::look_along(random_direction(rng), {0.0, 0.6, 0.8}));
  for (const OrthoFrame& frame : frames) {
    const CrossingReference ref(m, frame);
    for (const Tri& t : m.triangles) {
      for (int k = 0; k < 3; ++k) {
        const Vec3f& a = m.vertices[t[k]];
        const Vec3f& b = m.vertices[t[(k + 1) % 3]];
        const Vec3d mid{(double(a[0]) + b[0]) / 2, (double(a[1]) + b[1]) / 2, (double(a[2]) + b[2]) / 2};
        const Vec3d at{a[0], a[1], a[2]};
        EXPECT_EQ(ref.crossing_depths(at).size() % 2, 0u) << "through a vertex";
        EXPECT_EQ(ref.crossing_depths(mid).size() % 2, 0u) << "through an edge midpoint";
      }
    }
  }
}

// A face seen edge-on counts 0; a single triangle's coverage on its own edges is the same for both
// windings (the rule is a perturbation of the line, not of the triangle).
TEST(CrossingsTest, EdgeOnAndSingleTriangleTies) {
  TriMesh wall;
  wall.vertices = {{0.0f, 0.5f, 0.0f}, {1.0f, 0.5f, 0.0f}, {0.0f, 0.5f, 1.0f}};
  wall.triangles = {{0, 1, 2}};
  const CrossingReference edge_on(wall, OrthoFrame::look_along({0.0, 0.0, -1.0}));
  EXPECT_TRUE(edge_on.crossing_depths({0.2, 0.5, 5.0}).empty()) << "a line inside the triangle's plane";

  TriMesh tri;
  tri.vertices = {{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}};
  tri.triangles = {{0, 1, 2}};
  TriMesh flipped = tri;
  flipped.triangles = {{0, 2, 1}};
  struct Case {
    double x, y;
    bool covered;
    const char* why;
  };
  const Case cases[] = {
      {0.0, 0.5, true, "left edge (runs down in CCW order)"},
      {0.5, 0.0, true, "bottom edge (horizontal, rightward in CCW order)"},
      {0.5, 0.5, false, "hypotenuse (runs up in CCW order)"},
      {0.0, 0.0, true, "lower-left corner"},
      {0.0, 1.0, false, "upper corner"},
      {0.2, 0.2, true, "interior"},
  };
  for (const TriMesh* m : {&tri, &flipped}) {
    const CrossingReference ref(*m, OrthoFrame::look_along({0.0, 0.0, -1.0}));
    for (const Case& c : cases) EXPECT_EQ(ref.crossing_depths({c.x, c.y, 1.0}).size(), c.covered ? 1u : 0u) << c.why;
  }
}

// Depth bookkeeping: a point on the surface is at_point with distance 0; otherwise the nearest
// crossing's distance; lines missing the mesh, and far away, cross nothing.
TEST(CrossingsTest, DepthsAndNearestDistance) {
  const CrossingReference ref(make_box(), OrthoFrame::look_along({0.0, 0.0, -1.0}));
  const CrossingCount on = ref.count({0.3, 0.4, 1.0});
  EXPECT_EQ(on.at_point, 1u);
  EXPECT_EQ(on.beyond, 1u);
  EXPECT_EQ(on.nearest_distance, 0.0);
  const CrossingCount in = ref.count({0.3, 0.4, 0.75});
  EXPECT_EQ(in.in_front, 1u);
  EXPECT_EQ(in.beyond, 1u);
  EXPECT_DOUBLE_EQ(in.nearest_distance, 0.25);
  EXPECT_EQ(ref.crossing_depths({0.3, 0.4, 0.0}), (std::vector<double>{-1.0, 0.0}));
  const CrossingCount miss = ref.count({3.0, 0.4, 0.5});
  EXPECT_EQ(miss.in_front + miss.beyond, 0u);
  EXPECT_TRUE(std::isinf(miss.nearest_distance));
  EXPECT_TRUE(ref.crossing_depths({1e300, -1e300, 0.0}).empty());
}

// Refusals: a zero, non-finite or up-parallel direction, a NaN point, a broken mesh.
TEST(CrossingsTest, BadInputIsRefused) {
  EXPECT_THROW(OrthoFrame::look_along({0.0, 0.0, 0.0}), InputError);
  EXPECT_THROW(OrthoFrame::look_along({NAN, 0.0, 1.0}), InputError);
  EXPECT_THROW(OrthoFrame::look_along({0.0, 2.0, 0.0}), InputError) << "parallel to the default up hint";
  const OrthoFrame f = OrthoFrame::look_along({0.0, 0.0, -1.0});
  const CrossingReference ref(make_box(), f);
  EXPECT_THROW(ref.count({NAN, 0.0, 0.0}), InputError);
  TriMesh bad = make_box();
  bad.triangles[0][0] = 42;
  EXPECT_THROW(CrossingReference(bad, f), InputError);
  bad = make_box();
  bad.vertices[0][0] = INFINITY;
  EXPECT_THROW(CrossingReference(bad, f), InputError);
}

}  // namespace
}  // namespace nbsim::mesh

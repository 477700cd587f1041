// GeometryTest: the geometry stage (model/geometry/geometry.h): clipping at the viewport edges and
// the near and far planes, huge coordinates, trivial rejects, both clip-control conventions, and
// the clipper-output counts of Mesa's draw module.
#include "model/geometry/geometry.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "tests/model/raster/coverage.h"

namespace nbsim::raster {
namespace {

using namespace nbsim::raster::testing;
using geometry::ClipControl;
using geometry::ClipPosition;

struct GeometryRun {
  std::vector<WindowTriangle> tris;
  geometry::GeometryCounters k;
};

GeometryRun run_geometry(const std::vector<ClipPosition>& clip, ClipControl cc = ClipControl::NegativeOneToOne,
                         FaceState face = kNoCull, int w = 64, int h = 48) {
  geometry::GeometryStage g({w, h, 85, true});
  GeometryRun r;
  geometry::GeometryState st;
  st.clip = cc;
  st.face = face;
  g.process(clip, st, r.tris, r.k);
  return r;
}

long fragments_of(const std::vector<WindowTriangle>& tris, int w, int h) { return cover(tris, w, h).total(); }

// A triangle far larger than the viewport is clipped to it and covers every pixel exactly once.
TEST(GeometryTest, ViewportEdgesClipToExactlyTheTarget) {
  const std::vector<ClipPosition> big = {{-1, -1, 0, 1}, {3, -1, 0, 1}, {-1, 3, 0, 1}};
  const GeometryRun r = run_geometry(big);
  EXPECT_EQ(r.k.clipped, 1u);
  // Clipped to the square. The corner (1, 1) lies on the y = w plane, so Mesa's clipper repeats
  // it (t = 0) and the fan has a zero-area triangle that setup drops.
  EXPECT_EQ(r.k.prims_out, 3u) << "fan of the 5-vertex polygon";
  const Coverage c = cover(r.tris, 64, 48);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) ASSERT_EQ(c.at(x, y), 1) << "pixel (" << x << "," << y << ") once";
}

// Large clip coordinates and large w are clipped to the target; enormous ones (where float
// clipping itself loses the shape) stay inside the target and never cover a pixel twice.
TEST(GeometryTest, HugeCoordinatesAreClipped) {
  const std::vector<ClipPosition> large = {{-1e4f, -1e4f, 0, 1}, {1e4f, -1e4f, 0, 1}, {0, 1e4f, 0, 1}};
  EXPECT_EQ(fragments_of(run_geometry(large).tris, 64, 48), 64 * 48) << "a large triangle around the viewport fills it";
  const std::vector<ClipPosition> far_w = {{-1e20f, -1e20f, 0, 1e19f}, {1e20f, -1e20f, 0, 1e19f}, {0, 1e20f, 0, 1e19f}};
  EXPECT_EQ(fragments_of(run_geometry(far_w).tris, 64, 48), 64 * 48) << "huge w: the same triangle in NDC";
  const float b = 1e30f;
  const std::vector<ClipPosition> enormous = {{-b, -b, 0, 1}, {b, -b, 0, 1}, {0, b, 0, 1}};
  const GeometryRun r = run_geometry(enormous);
  EXPECT_EQ(r.k.clipped, 1u);
  const Coverage c = cover(r.tris, 64, 48);
  EXPECT_EQ(c.outside, 0) << "no pixel outside the target";
  for (int v : c.count) EXPECT_LE(v, 1) << "no pixel twice";
  const std::vector<ClipPosition> nan = {{NAN, 0, 0, 1}, {1, 0, 0, 1}, {0, 1, 0, 1}};
  EXPECT_EQ(fragments_of(run_geometry(nan).tris, 64, 48), 0) << "a NaN vertex (no outcode) is refused by setup";
}

// Triangles behind the eye (w < 0) or beyond one plane are rejected without clipping.
TEST(GeometryTest, TriviallyRejectedTriangles) {
  const GeometryRun behind = run_geometry({{0, 0, 0, -1}, {0.5f, 0, 0, -1}, {0, 0.5f, 0, -1}});
  EXPECT_EQ(behind.k.trivially_rejected, 1u) << "all vertices behind the eye";
  EXPECT_EQ(behind.k.prims_out, 0u);
  const GeometryRun right = run_geometry({{2, 0, 0, 1}, {3, 0, 0, 1}, {2, 1, 0, 1}});
  EXPECT_EQ(right.k.trivially_rejected, 1u) << "all vertices right of x = w";
}

// A triangle crossing the near plane is cut there: depth reaches the near value along the cut and
// nothing is drawn beyond it; the same for the far plane. Cutting one corner off gives a quad.
TEST(GeometryTest, NearAndFarPlaneCrossing) {
  // Bottom edge behind the near plane (z = -2w), apex inside: the cut is the line NDC y = -1/3.
  const std::vector<ClipPosition> near_cross = {{-1, -1, -2, 1}, {1, -1, -2, 1}, {0, 1, 1, 1}};
  const GeometryRun r = run_geometry(near_cross);
  EXPECT_EQ(r.k.clipped, 1u);
  EXPECT_EQ(r.k.prims_out, 1u) << "two vertices behind the plane: a smaller triangle";
  float zmin = 1.0f;
  for (const auto& t : r.tris)
    for (const auto& v : t.v) zmin = std::min(zmin, v.z);
  EXPECT_NEAR(zmin, 0.0f, 1e-6f) << "the cut lies on the near plane (window depth 0)";
  EXPECT_GE(zmin, 0.0f) << "nothing in front of the near plane";
  const Coverage c = cover(r.tris, 64, 48);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 64; ++x)
      EXPECT_EQ(c.at(x, y), 0) << "row " << y << " lies beyond the near plane (window y < 16)";
  EXPECT_GT(c.total(), 0);
  const std::vector<ClipPosition> far_cross = {{-1, -1, 2, 1}, {1, -1, 2, 1}, {0, 1, -1, 1}};
  const GeometryRun f = run_geometry(far_cross);
  EXPECT_EQ(f.k.prims_out, 1u);
  float zmax = 0.0f;
  for (const auto& t : f.tris)
    for (const auto& v : t.v) zmax = std::max(zmax, v.z);
  EXPECT_NEAR(zmax, 1.0f, 1e-6f) << "the cut lies on the far plane (window depth 1)";
  EXPECT_LE(zmax, 1.0f);
  const std::vector<ClipPosition> corner = {{-1, -1, -2, 1}, {1, -1, 0, 1}, {0, 1, 0, 1}};
  EXPECT_EQ(run_geometry(corner).k.prims_out, 2u) << "one vertex behind the near plane: a quad, two triangles";
}

// Clip control: NEGATIVE_ONE_TO_ONE maps z = -w to depth 0 and keeps z in [-w, 0); ZERO_TO_ONE maps
// z = 0 to depth 0 and clips z < 0.
TEST(GeometryTest, ClipControlConventions) {
  const std::vector<ClipPosition> at_minus_w = {{-1, -1, -1, 1}, {1, -1, -1, 1}, {0, 1, -1, 1}};
  const GeometryRun n = run_geometry(at_minus_w, ClipControl::NegativeOneToOne);
  ASSERT_EQ(n.tris.size(), 1u);
  EXPECT_EQ(n.tris[0].v[0].z, 0.0f) << "z = -w is depth 0 with NEGATIVE_ONE_TO_ONE";
  EXPECT_EQ(run_geometry(at_minus_w, ClipControl::ZeroToOne).k.trivially_rejected, 1u)
      << "z = -w is outside with ZERO_TO_ONE";
  const std::vector<ClipPosition> at_zero = {{-1, -1, 0, 1}, {1, -1, 0, 1}, {0, 1, 0, 1}};
  EXPECT_EQ(run_geometry(at_zero, ClipControl::NegativeOneToOne).tris[0].v[0].z, 0.5f);
  EXPECT_EQ(run_geometry(at_zero, ClipControl::ZeroToOne).tris[0].v[0].z, 0.0f) << "z = 0 is depth 0 with ZERO_TO_ONE";
  const std::vector<ClipPosition> half_in = {{-1, -1, -0.5f, 1}, {1, -1, -0.5f, 1}, {0, 1, 0.5f, 1}};
  EXPECT_EQ(run_geometry(half_in, ClipControl::NegativeOneToOne).k.clipped, 0u) << "inside for [-w, w]";
  EXPECT_EQ(run_geometry(half_in, ClipControl::ZeroToOne).k.clipped, 1u) << "crosses z = 0 for [0, w]";
}

// Like llvmpipe: a batch without clipping reaches setup whole (back faces included in the
// clipper-output count), a batch that needs clipping is face-culled by the draw module first.
TEST(GeometryTest, ClipOutputCountsFollowTheDrawModule) {
  const FaceState back{CullFace::Back, true};
  const std::vector<ClipPosition> front_tri = {{-0.5f, -0.5f, 0, 1}, {0.5f, -0.5f, 0, 1}, {0, 0.5f, 0, 1}};
  const std::vector<ClipPosition> back_tri = {{-0.5f, -0.5f, 0, 1}, {0, 0.5f, 0, 1}, {0.5f, -0.5f, 0, 1}};
  const std::vector<ClipPosition> crossing = {{-0.5f, -0.5f, 0, 1}, {2.0f, -0.5f, 0, 1}, {0, 0.5f, 0, 1}};
  std::vector<ClipPosition> no_clip = front_tri;
  no_clip.insert(no_clip.end(), back_tri.begin(), back_tri.end());
  EXPECT_EQ(run_geometry(no_clip, ClipControl::NegativeOneToOne, back).k.prims_out, 2u)
      << "no clipping in the batch: the back face is counted (llvmpipe culls it later)";
  std::vector<ClipPosition> with_clip = no_clip;
  with_clip.insert(with_clip.end(), crossing.begin(), crossing.end());
  const GeometryRun r = run_geometry(with_clip, ClipControl::NegativeOneToOne, back);
  EXPECT_EQ(r.k.draw_culled, 1u) << "clipping in the batch: the draw module culls the back face";
  EXPECT_EQ(r.k.prims_out, 1u + 2u) << "the front triangle and the clipped one's two pieces";
}

}  // namespace
}  // namespace nbsim::raster

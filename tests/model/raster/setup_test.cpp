// SetupTest: triangle setup (model/raster/setup.h) on window-space triangles: snapping, the fill
// rule on shared edges and on pixel centres, tiny, sliver and degenerate triangles, face culling.
#include "model/raster/setup.h"

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

// Two triangles sharing an edge cover every pixel of their union exactly once.
TEST(SetupTest, SharedEdgeCoversEachPixelOnce) {
  struct Row {
    float x0, y0, x1, y1;  // quad corners (axis-aligned) or a skewed quad below
    bool skew;
    const char* why;
  };
  const Row rows[] = {
      {2.0f, 3.0f, 40.0f, 30.0f, false, "diagonal through pixel corners"},
      {2.5f, 3.5f, 40.5f, 30.5f, false, "diagonal through pixel centres"},
      {2.3f, 3.7f, 41.1f, 29.9f, false, "arbitrary sub-pixel corners"},
      {10.0f, 5.0f, 11.0f, 45.0f, false, "one pixel wide"},
      {0.5f, 0.5f, 96.5f, 70.5f, false, "several tiles"},
      {3.25f, 2.75f, 50.125f, 33.875f, true, "skewed quad, edges through centres"},
  };
  for (const Row& r : rows) {
    std::vector<WindowTriangle> tris;
    if (!r.skew) {
      tris.push_back(tri(r.x0, r.y0, r.x1, r.y0, r.x1, r.y1));
      tris.push_back(tri(r.x0, r.y0, r.x1, r.y1, r.x0, r.y1));
    } else {
      const float sx = 7.5f;
      tris.push_back(tri(r.x0, r.y0, r.x1, r.y0, r.x1 + sx, r.y1));
      tris.push_back(tri(r.x0, r.y0, r.x1 + sx, r.y1, r.x0 + sx, r.y1));
    }
    const Coverage c = cover(tris, 100, 80);
    long reference = 0;
    for (int y = 0; y < 80; ++y)
      for (int x = 0; x < 100; ++x) {
        EXPECT_LE(c.at(x, y), 1) << r.why << ": pixel (" << x << "," << y << ") covered twice";
        reference += reference_covers(tris[0], x, y) + reference_covers(tris[1], x, y);
        EXPECT_EQ(c.at(x, y), reference_covers(tris[0], x, y) + reference_covers(tris[1], x, y))
            << r.why << ": pixel (" << x << "," << y << ") differs from the reference rule";
      }
    EXPECT_EQ(c.total(), reference) << r.why;
    if (!r.skew && r.x0 == std::floor(r.x0) && r.y0 == std::floor(r.y0) && r.x1 == std::floor(r.x1)) {
      EXPECT_EQ(c.total(), static_cast<long>((r.x1 - r.x0) * (r.y1 - r.y0)))
          << r.why << ": integer quad area in pixels";
    }
  }
}

// A mesh of random quads, each split along a random diagonal, covers every pixel of the mesh once.
TEST(SetupTest, RandomMeshCoversEachPixelOnce) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> jitter(-3.0f, 3.0f);
  constexpr int kN = 9;
  float gx[kN + 1][kN + 1], gy[kN + 1][kN + 1];
  for (int j = 0; j <= kN; ++j)
    for (int i = 0; i <= kN; ++i) {
      const bool border = i == 0 || j == 0 || i == kN || j == kN;
      gx[j][i] = 5.0f + 14.0f * static_cast<float>(i) + (border ? 0.0f : jitter(rng));
      gy[j][i] = 4.0f + 12.0f * static_cast<float>(j) + (border ? 0.0f : jitter(rng));
    }
  std::vector<WindowTriangle> tris;
  for (int j = 0; j < kN; ++j)
    for (int i = 0; i < kN; ++i) {
      const float ax = gx[j][i], ay = gy[j][i], bx = gx[j][i + 1], by = gy[j][i + 1];
      const float cx = gx[j + 1][i + 1], cy = gy[j + 1][i + 1], dx = gx[j + 1][i], dy = gy[j + 1][i];
      if (rng() & 1) {
        tris.push_back(tri(ax, ay, bx, by, cx, cy));
        tris.push_back(tri(ax, ay, cx, cy, dx, dy));
      } else {
        tris.push_back(tri(ax, ay, bx, by, dx, dy));
        tris.push_back(tri(bx, by, cx, cy, dx, dy));
      }
    }
  const Coverage c = cover(tris, 140, 120);
  for (int y = 0; y < 120; ++y)
    for (int x = 0; x < 140; ++x) {
      const bool in_mesh = x >= 5 && x < 5 + 14 * kN && y >= 4 && y < 4 + 12 * kN;
      EXPECT_EQ(c.at(x, y), in_mesh ? 1 : 0) << "pixel (" << x << "," << y << ") of the mesh";
    }
}

// Pixel centres exactly on an edge: the left and bottom edges own them, the right and top do not.
TEST(SetupTest, CentresOnEdgesFollowBottomLeftRule) {
  // Rectangle with its four edges through pixel centres x = 10.5 .. 20.5, y = 5.5 .. 15.5.
  const std::vector<WindowTriangle> quad = {tri(10.5f, 5.5f, 20.5f, 5.5f, 20.5f, 15.5f),
                                            tri(10.5f, 5.5f, 20.5f, 15.5f, 10.5f, 15.5f)};
  const Coverage c = cover(quad, 32, 32);
  EXPECT_EQ(c.at(10, 8), 1) << "left edge centres belong to the quad";
  EXPECT_EQ(c.at(20, 8), 0) << "right edge centres do not";
  EXPECT_EQ(c.at(14, 5), 1) << "bottom edge centres belong to the quad (y up)";
  EXPECT_EQ(c.at(14, 15), 0) << "top edge centres do not";
  EXPECT_EQ(c.at(10, 5), 1) << "bottom-left corner belongs";
  EXPECT_EQ(c.at(20, 15), 0) << "top-right corner does not";
  EXPECT_EQ(c.total(), 10 * 10) << "a 10 x 10 pixel quad";
  // Right and top edges through the centres of the last column and row of 4x4 and 16x16 blocks:
  // those blocks' smallest edge value is exactly 0, so they must not be classified full.
  const std::vector<WindowTriangle> aligned = {tri(0.5f, 0.5f, 47.5f, 0.5f, 47.5f, 31.5f),
                                               tri(0.5f, 0.5f, 47.5f, 31.5f, 0.5f, 31.5f)};
  const Coverage a = cover(aligned, 64, 64);
  EXPECT_EQ(a.total(), 47 * 31) << "columns 0..46 and rows 0..30";
  EXPECT_EQ(a.at(47, 10), 0) << "column 47 (last of its blocks) is on the right edge";
  EXPECT_EQ(a.at(10, 31), 0) << "row 31 (last of its blocks) is on the top edge";
}

// Tiny, sliver and degenerate triangles: a table of what each must produce.
TEST(SetupTest, TinySliverAndDegenerateTriangles) {
  struct Row {
    WindowTriangle t;
    long fragments;
    const char* why;
  };
  const Row rows[] = {
      {tri(4.4f, 4.4f, 4.6f, 4.4f, 4.5f, 4.7f), 1, "sub-pixel triangle around a centre"},
      {tri(4.6f, 4.6f, 4.9f, 4.6f, 4.8f, 4.9f), 0, "sub-pixel triangle missing every centre"},
      {tri(4.5f, 2.0f, 4.51f, 2.0f, 4.5f, 30.0f), 28, "sliver 0.01 px wide on a column of centres (left edge)"},
      {tri(4.49f, 2.0f, 4.5f, 2.0f, 4.5f, 30.0f), 0, "sliver whose right edge is the column of centres"},
      {tri(1.0f, 1.0f, 9.0f, 9.0f, 17.0f, 17.0f), 0, "collinear vertices"},
      {tri(5.0f, 5.0f, 5.0f, 5.0f, 9.0f, 9.0f), 0, "two equal vertices"},
      {tri(5.0f, 5.0f, 5.001f, 5.0f, 5.0f, 5.001f), 0, "collapses to a point when snapped"},
      {tri(0.5f, 0.5f, 0.5f + 1.0f / 512.0f, 0.5f, 0.5f, 9.5f), 0, "narrower than half a subpixel: no area"},
  };
  for (const Row& r : rows) {
    const Coverage c = cover({r.t}, 32, 32);
    EXPECT_EQ(c.total(), r.fragments) << r.why;
    long reference = 0;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) reference += reference_covers(r.t, x, y);
    EXPECT_EQ(c.total(), reference) << r.why << " (reference rule)";
  }
  const Coverage degenerate = cover({tri(1.0f, 1.0f, 9.0f, 9.0f, 17.0f, 17.0f)}, 32, 32);
  EXPECT_EQ(degenerate.setup.zero_area, 1u) << "collinear triangles are dropped by setup as zero area";
}

// Snapping rounds (x - 0.5) * 256 half to even, as cvtps2dq does.
TEST(SetupTest, SnappingRoundsHalfToEven) {
  EXPECT_EQ(snap_to_subpixel(0.5f), 0);
  EXPECT_EQ(snap_to_subpixel(1.5f), 256);
  EXPECT_EQ(snap_to_subpixel(0.5f + 0.5f / 256.0f), 0) << "half a subpixel above 0 rounds to even 0";
  EXPECT_EQ(snap_to_subpixel(0.5f + 1.5f / 256.0f), 2) << "1.5 subpixels rounds to even 2";
  EXPECT_EQ(snap_to_subpixel(0.5f - 0.5f / 256.0f), 0) << "-0.5 rounds to even 0";
  EXPECT_EQ(snap_to_subpixel(100.25f), 99 * 256 + 192);
}

// Back faces are culled by the sign of the snapped area; the front face follows glFrontFace.
TEST(SetupTest, FaceCullingFollowsFrontFaceAndCullMode) {
  const WindowTriangle ccw = tri(2.0f, 2.0f, 20.0f, 2.0f, 2.0f, 20.0f);  // counter-clockwise, y up
  const WindowTriangle cw = tri(2.0f, 2.0f, 2.0f, 20.0f, 20.0f, 2.0f);
  struct Row {
    FaceState face;
    bool ccw_drawn, cw_drawn;
    const char* why;
  };
  const Row rows[] = {
      {{CullFace::Back, true}, true, false, "GL default: CCW front, back culled"},
      {{CullFace::Back, false}, false, true, "glFrontFace(GL_CW)"},
      {{CullFace::Front, true}, false, true, "front faces culled"},
      {{CullFace::None, true}, true, true, "no culling"},
      {{CullFace::FrontAndBack, true}, false, false, "both culled"},
  };
  for (const Row& r : rows) {
    EXPECT_EQ(cover({ccw}, 32, 32, r.face).total() > 0, r.ccw_drawn) << r.why << ": CCW triangle";
    EXPECT_EQ(cover({cw}, 32, 32, r.face).total() > 0, r.cw_drawn) << r.why << ": CW triangle";
  }
  // Both windings of the same triangle cover the same pixels when drawn.
  const Coverage a = cover({ccw}, 32, 32), b = cover({cw}, 32, 32);
  EXPECT_EQ(a.count, b.count) << "winding does not change coverage";
  SetupTriangle s;
  SetupCounters k;
  ASSERT_EQ(TriangleSetup({32, 32}).setup(ccw, kNoCull, s, k), SetupResult::Accepted);
  EXPECT_TRUE(s.front_facing) << "CCW is front-facing with front_ccw";
  ASSERT_EQ(TriangleSetup({32, 32}).setup(cw, kNoCull, s, k), SetupResult::Accepted);
  EXPECT_FALSE(s.front_facing) << "CW is back-facing with front_ccw";
}

// Coordinates llvmpipe's fixed-point planes cannot hold (non-finite, or vertices 32768 px or more
// apart) are refused, never wrapped into garbage coverage; the clipper never produces them.
TEST(SetupTest, RefusesCoordinatesBeyondFixedPointRange) {
  struct Row {
    WindowTriangle t;
    const char* why;
  };
  const Row rows[] = {
      {tri(NAN, 1.0f, 9.0f, 1.0f, 1.0f, 9.0f), "NaN coordinate"},
      {tri(INFINITY, 1.0f, 9.0f, 1.0f, 1.0f, 9.0f), "infinite coordinate"},
      {tri(-20000.0f, 1.0f, 20000.0f, 1.0f, 1.0f, 9.0f), "40000 px wide"},
      {tri(1.0f, 1.0f, 9.0f, 1.0f, 1.0f, 5e6f), "beyond 2^22 px"},
  };
  for (const Row& r : rows) {
    const Coverage c = cover({r.t}, 64, 64);
    EXPECT_EQ(c.setup.unsupported, 1u) << r.why;
    EXPECT_EQ(c.total(), 0) << r.why;
  }
  const Coverage wide = cover({tri(-100.0f, -100.0f, 31000.0f, -100.0f, -100.0f, 31000.0f)}, 64, 64);
  EXPECT_EQ(wide.setup.unsupported, 0u) << "31100 px apart in x and y is still supported";
  EXPECT_EQ(wide.total(), 64 * 64) << "and covers the whole target once";
}

}  // namespace
}  // namespace nbsim::raster

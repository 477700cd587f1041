// PointSetupTest: point setup (model/raster/point_setup.h) and the geometry stage's point path
// (model/geometry/geometry.h process_points) without GL: coverage against a reference on random
// and adversarial points, the fill-rule ties, the size clamps, centre clipping, constant depth
// through the early depth test, and bad input refused.
#include "model/raster/point_setup.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "model/common/error.h"
#include "model/raster/raster_path.h"
#include "tests/model/raster/point_coverage.h"

namespace nbsim::raster {
namespace {

using namespace nbsim::raster::testing;
using geometry::ClipPosition;
using geometry::WindowPoint;
using geometry::WindowVertex;

constexpr int kW = 64, kH = 48;

// Pixels the model covers for one window-space point (through setup and the tile walk).
std::vector<int> cover_point(const WindowPoint& p, SetupResult* result = nullptr) {
  std::vector<int> c(static_cast<std::size_t>(kW * kH), 0);
  const PointSetup setup(SetupConfig{kW, kH});
  const Rasterizer raster(kW, kH);
  SetupTriangle s;
  SetupCounters k;
  TileCounters tiles;
  const SetupResult r = setup.setup(p, s, k);
  if (result) *result = r;
  if (r != SetupResult::Accepted) return c;
  raster.rasterize(s, tiles, [&](int x, int y, std::uint16_t mask) {
    for (int i = 0; i < 16; ++i)
      if (mask & (1u << i)) ++c[static_cast<std::size_t>((y + (i >> 2)) * kW + x + (i & 3))];
  });
  return c;
}

WindowPoint point(float x, float y, float size, float z = 0.5f) { return WindowPoint{WindowVertex{x, y, z, 1.0f}, size}; }

void expect_reference(const WindowPoint& p, const char* what) {
  const std::vector<int> c = cover_point(p);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      ASSERT_EQ(c[static_cast<std::size_t>(y * kW + x)], reference_point_covers(p.v.x, p.v.y, p.size, x, y) ? 1 : 0)
          << what << ": point (" << p.v.x << ", " << p.v.y << ") size " << p.size << ", pixel (" << x << ", " << y
          << ") must be covered once by the square rule or not at all";
}

// Random centres (inside, on and beyond the borders) and sizes, including ties, match the reference.
TEST(PointSetupTest, RandomPointsMatchReference) {
  std::mt19937 rng(12);
  const float sizes[] = {1, 1.5f, 2, 3, 7.5f, 16, 24, 33, 64, 100, 255, 300, 0.5f, 0.0f, -4.0f, 1.001953125f};
  for (int i = 0; i < 600; ++i) {
    const float fx = static_cast<float>(rng() % (kW * 512 + 2048)) / 512.0f - 2.0f;  // 1/512 steps: ties
    const float fy = static_cast<float>(rng() % (kH * 512 + 2048)) / 512.0f - 2.0f;
    const float size = i % 3 == 0 ? static_cast<float>(rng() % 80000) / 1000.0f : sizes[rng() % std::size(sizes)];
    expect_reference(point(fx, fy, size), "random");
  }
}

// A size-1 point centred on a pixel corner covers exactly the pixel below-left of the corner.
TEST(PointSetupTest, CentreOnPixelCornerOwnsLowerLeftPixel) {
  const std::vector<int> c = cover_point(point(10.0f, 20.0f, 1.0f));
  long total = 0;
  for (int v : c) total += v;
  EXPECT_EQ(total, 1) << "a 1x1 square through four pixel centres' midpoint covers one pixel";
  EXPECT_EQ(c[static_cast<std::size_t>(19 * kW + 9)], 1) << "left and bottom edges own their centres";
  // A size-2 point centred on a pixel centre: square edges through the neighbours' centres.
  const std::vector<int> d = cover_point(point(10.5f, 20.5f, 2.0f));
  total = 0;
  for (int v : d) total += v;
  EXPECT_EQ(total, 4) << "2x2: left/bottom neighbours in, right/top out";
  EXPECT_EQ(d[static_cast<std::size_t>(19 * kW + 9)], 1);
  EXPECT_EQ(d[static_cast<std::size_t>(20 * kW + 10)], 1);
  EXPECT_EQ(d[static_cast<std::size_t>(21 * kW + 11)], 0);
}

// Snapping rounds 1/512 ties away from zero (util_iround), not to even as triangle setup does.
TEST(PointSetupTest, SnapTiesRoundAwayFromZero) {
  EXPECT_EQ(snap_point_coordinate(10.501953125f), 2689) << "2688.5 rounds up";
  EXPECT_EQ(snap_point_coordinate(10.505859375f), 2690) << "2689.5 rounds up";
  EXPECT_EQ(snap_point_coordinate(-10.501953125f), -2689) << "negative ties round down";
  EXPECT_EQ(snap_to_subpixel(11.001953125f), 2688) << "triangle snap: half to even";
  // Centre x = 11.001953125: a size-1 square from 2561/256 px: pixel 11, not 10.
  const std::vector<int> c = cover_point(point(11.001953125f, 5.5f, 1.0f));
  EXPECT_EQ(c[static_cast<std::size_t>(5 * kW + 11)], 1) << "tie rounded away: the square starts past pixel 10";
  EXPECT_EQ(c[static_cast<std::size_t>(5 * kW + 10)], 0);
}

// Sizes are clamped to 1 .. 255 pixels: 300 draws as 255, sub-pixel, zero and negative sizes as 1.
TEST(PointSetupTest, SizeClamps) {
  EXPECT_EQ(point_width_fixed(300.0f), 255 * 256);
  EXPECT_EQ(point_width_fixed(std::numeric_limits<float>::infinity()), 255 * 256);
  EXPECT_EQ(point_width_fixed(255.0f), 255 * 256);
  EXPECT_EQ(point_width_fixed(0.5f), 256);
  EXPECT_EQ(point_width_fixed(0.0f), 256);
  EXPECT_EQ(point_width_fixed(-7.0f), 256);
  EXPECT_EQ(point_width_fixed(7.5f), 1920);
  EXPECT_EQ(cover_point(point(30.5f, 20.5f, 300.0f)), cover_point(point(30.5f, 20.5f, 255.0f)));
}

// A square entirely beyond the target is Offscreen; one partly beyond it is cut to the target.
TEST(PointSetupTest, OffscreenAndPartlyOffscreen) {
  SetupResult r{};
  cover_point(point(-10.0f, 10.0f, 4.0f), &r);
  EXPECT_EQ(r, SetupResult::Offscreen);
  const std::vector<int> c = cover_point(point(1.0f, 47.0f, 8.0f), &r);
  EXPECT_EQ(r, SetupResult::Accepted);
  long total = 0;
  for (int v : c) total += v;
  EXPECT_EQ(total, 5 * 5) << "an 8x8 square at the top-left corner keeps 5x5 pixels";
  cover_point(point(NAN, 3.0f, 4.0f), &r);
  EXPECT_EQ(r, SetupResult::Unsupported) << "a non-finite window position (w = 0) is not set up";
}

// Centre clipping: a point whose centre is outside the clip volume is dropped even though its
// square overlaps the viewport; inside ones pass unchanged; near/far planes likewise.
TEST(PointSetupTest, GeometryClipsPointsByCentre) {
  const geometry::GeometryStage g({kW, kH, 85, true});
  const std::vector<ClipPosition> clip = {
      {0.0f, 0.0f, 0.0f, 1.0f},    // inside
      {1.01f, 0.0f, 0.0f, 1.0f},   // just right of the viewport (square of 64 px would overlap)
      {0.0f, -1.01f, 0.0f, 1.0f},  // just below
      {1.0f, 1.0f, 1.0f, 1.0f},    // on the corner and the far plane: inside (not >)
      {0.0f, 0.0f, 1.01f, 1.0f},   // beyond far
      {0.0f, 0.0f, -1.01f, 1.0f},  // beyond near
      {0.0f, 0.0f, 0.0f, -1.0f},   // behind the eye
  };
  const std::vector<float> sizes(clip.size(), 64.0f);
  std::vector<WindowPoint> out;
  geometry::GeometryCounters k;
  g.process_points(clip, sizes, geometry::GeometryState{}, out, k);
  EXPECT_EQ(k.prims_in, 7u);
  EXPECT_EQ(k.prims_out, 2u) << "only the centres inside the clip volume";
  EXPECT_EQ(k.trivially_rejected, 5u);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].v.x, 32.0f);
  EXPECT_EQ(out[1].v.x, 64.0f);
  EXPECT_EQ(out[1].v.z, 1.0f);
  // Depth clamp turns the near and far planes off.
  out.clear();
  geometry::GeometryState clamp;
  clamp.depth_clamp = true;
  geometry::GeometryCounters k2;
  g.process_points(clip, sizes, clamp, out, k2);
  EXPECT_EQ(k2.prims_out, 4u) << "with depth clamp the beyond-near and beyond-far centres pass";
  // ZERO_TO_ONE: z in [0, w].
  geometry::GeometryState zo;
  zo.clip = geometry::ClipControl::ZeroToOne;
  const std::vector<ClipPosition> zclip = {{0, 0, -0.01f, 1}, {0, 0, 0, 1}, {0, 0, 1, 1}};
  out.clear();
  geometry::GeometryCounters k3;
  g.process_points(zclip, std::vector<float>(3, 1.0f), zo, out, k3);
  EXPECT_EQ(k3.prims_out, 2u) << "ZERO_TO_ONE: z < 0 is beyond near";
}

// Every fragment of a point has the vertex's window depth: equal stored depth fails LESS and
// passes LEQUAL; GREATER under reversed Z.
TEST(PointSetupTest, ConstantDepthThroughDepthTest) {
  RasterPathConfig cfg;
  cfg.width_px = kW;
  cfg.height_px = kH;
  const std::vector<ClipPosition> clip = {{0.0f, 0.0f, 0.5f, 1.0f}};  // window z = 0.75 exactly
  const std::vector<float> sizes = {7.5f};
  struct Row {
    DepthFunc func;
    float stored;
    std::uint64_t passed;
    const char* why;
  } rows[] = {
      {DepthFunc::Less, 0.75f, 0, "equal depth fails LESS"},
      {DepthFunc::Lequal, 0.75f, 64, "equal depth passes LEQUAL"},
      {DepthFunc::Less, std::nextafter(0.75f, 1.0f), 64, "one ulp farther passes LESS"},
      {DepthFunc::Greater, 0.75f, 0, "equal depth fails GREATER"},
      {DepthFunc::Greater, std::nextafter(0.75f, 0.0f), 64, "one ulp nearer (reversed Z) passes GREATER"},
  };
  for (const Row& r : rows) {
    DepthImage depth(kW, kH, r.stored);
    RasterPath path(cfg, depth);
    DrawState st;
    st.depth.func = r.func;
    const DrawCounters k = path.draw_points(clip, sizes, st);
    EXPECT_EQ(k.depth.fragments, 64u) << r.why << ": a 7.5 px point centred on a pixel corner covers 8x8";
    EXPECT_EQ(k.depth.passed, r.passed) << r.why;
    EXPECT_EQ(k.geometry.prims_out, 1u);
    EXPECT_EQ(k.setup.points, 1u);
  }
}

// Bad point draws are refused with an InputError that names the problem, never a crash.
TEST(PointSetupTest, BadPointDrawsRefused) {
  RasterPathConfig cfg;
  cfg.width_px = kW;
  cfg.height_px = kH;
  DepthImage depth(kW, kH, 1.0f);
  RasterPath path(cfg, depth);
  const std::vector<ClipPosition> two = {{0, 0, 0, 1}, {0.5f, 0, 0, 1}};
  const auto refused = [&](const std::vector<ClipPosition>& c, const std::vector<float>& s, const char* needle) {
    try {
      path.draw_points(c, s, DrawState{});
      ADD_FAILURE() << "expected an InputError mentioning '" << needle << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  refused(two, {1.0f}, "2 vertices but 1 point sizes");
  refused(two, {1.0f, 2.0f, 3.0f}, "2 vertices but 3 point sizes");
  refused(two, {1.0f, NAN}, "point 1 of a point draw has a NaN or infinite point size");
  refused(two, {INFINITY, 1.0f}, "point 0 of a point draw has a NaN or infinite point size");
  refused({{0, 0, 0, 1}, {NAN, 0, 0, 1}}, {1, 1}, "point 1 of a point draw has a NaN or infinite clip position");
  refused({{0, 0, 0, INFINITY}}, {1}, "point 0 of a point draw has a NaN or infinite clip position");
  EXPECT_EQ(path.draw_points({}, {}, DrawState{}).geometry.prims_in, 0u) << "an empty point draw is fine";
}

}  // namespace
}  // namespace nbsim::raster

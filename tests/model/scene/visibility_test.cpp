// VisibilityTest: model/scene/visibility.h's bounds test on boxes and cameras a damaged trace can
// hold (NaN, infinite or huge corners and matrices): never culled, a rectangle inside the viewport,
// and no float-to-int conversion out of range (run under NBSIM_SANITIZE=ON to see UBSan agree).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "model/scene/visibility.h"

namespace {

using namespace nbsim::scene;

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNan = std::numeric_limits<float>::quiet_NaN();

// Identity view and glFrustum's projection for near 0.5, far 100 (x and y unscaled): a box at
// z = -2 .. -3 lies 2 to 3 m in front of the camera, beyond the near plane.
FrameBegin camera() {
  constexpr float n = 0.5f, f = 100.0f;
  FrameBegin fb;
  fb.view = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  fb.proj = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -(f + n) / (f - n), -1, 0, 0, -2 * f * n / (f - n), 0};
  return fb;
}

FrameView view_of(const FrameBegin& f, bool reversed = false) {
  return FrameView::make(f, 64, 32, 0.5, 1e-6, reversed, reversed);
}

Aabb box(float lo_x, float hi_x) { return Aabb{{lo_x, -0.5f, -3.0f}, {hi_x, 0.5f, -2.0f}}; }

void expect_never_culled(const BoundsTest& t, const FrameView& v, const std::string& why) {
  EXPECT_TRUE(t.crosses_near) << why << ": non-finite bounds must be treated as crossing the near plane";
  EXPECT_EQ(t.x, 0) << why;
  EXPECT_EQ(t.y, 0) << why;
  EXPECT_EQ(t.w, v.width_px) << why << ": the whole viewport";
  EXPECT_EQ(t.h, v.height_px) << why;
  EXPECT_EQ(t.nearest_depth, v.reversed ? 1.0f : 0.0f) << why << ": the nearest possible depth";
}

// A finite box in front of the camera gets an ordinary rectangle (the baseline for the rows below).
TEST(VisibilityTest, FiniteBoxBaseline) {
  const FrameView v = view_of(camera());
  const BoundsTest t = bounds_test(box(-0.5f, 0.5f), v);
  EXPECT_FALSE(t.crosses_near);
  EXPECT_GT(t.w, 0);
  EXPECT_LT(t.w, v.width_px);
  EXPECT_GT(t.nearest_depth, 0.0f);
}

// A NaN or infinite box corner is never culled: the whole viewport at the nearest depth.
TEST(VisibilityTest, NonFiniteCornersNeverCulled) {
  const struct {
    Aabb b;
    const char* why;
  } rows[] = {
      {box(kNan, 0.5f), "NaN lo.x"},
      {box(-0.5f, kNan), "NaN hi.x"},
      {Aabb{{kNan, kNan, kNan}, {kNan, kNan, kNan}}, "every coordinate NaN"},
      {box(-kInf, 0.5f), "-inf lo.x"},
      {box(-0.5f, kInf), "+inf hi.x"},
      {Aabb{{-0.5f, -0.5f, -kInf}, {0.5f, 0.5f, -2.0f}}, "-inf lo.z (w infinite)"},
  };
  for (const bool reversed : {false, true}) {
    const FrameView v = view_of(camera(), reversed);
    for (const auto& r : rows) expect_never_culled(bounds_test(r.b, v), v, std::string(r.why) + (reversed ? ", reversed Z" : ""));
  }
}

// A NaN or infinite entry in the view or projection matrix is never culled either.
TEST(VisibilityTest, NonFiniteMatricesNeverCulled) {
  for (std::size_t i = 0; i < 16; ++i) {
    for (const float bad : {kNan, kInf, -kInf}) {
      FrameBegin f = camera();
      f.proj[i] = bad;
      const FrameView pv = view_of(f);
      const BoundsTest tp = bounds_test(box(-0.5f, 0.5f), pv);
      f = camera();
      f.view[i] = bad;
      const FrameView vv = view_of(f);
      const BoundsTest tv = bounds_test(box(-0.5f, 0.5f), vv);
      // Some entries multiply a zero and leave the product finite; where the product is not
      // finite, the bounds must be the never-culled ones.
      const auto finite = [](const FrameView& v) {
        for (double x : v.view_proj_d)
          if (!std::isfinite(x)) return false;
        return true;
      };
      if (!finite(pv)) expect_never_culled(tp, pv, "proj[" + std::to_string(i) + "] = " + std::to_string(bad));
      if (!finite(vv)) expect_never_culled(tv, vv, "view[" + std::to_string(i) + "] = " + std::to_string(bad));
      EXPECT_LE(tp.x + tp.w, pv.width_px);
      EXPECT_LE(tv.y + tv.h, vv.height_px);
    }
  }
}

// Huge finite corners (far outside the viewport, beyond int's range once in pixels) clamp to
// the viewport instead of converting an out-of-range double to int.
TEST(VisibilityTest, HugeFiniteCornersClampToViewport) {
  const FrameView v = view_of(camera());
  const float big = std::numeric_limits<float>::max();
  const BoundsTest wide = bounds_test(box(-big, big), v);
  EXPECT_FALSE(wide.crosses_near);
  EXPECT_EQ(wide.x, 0);
  EXPECT_EQ(wide.w, v.width_px) << "a box wider than the screen covers it";
  const BoundsTest right = bounds_test(box(1e30f, 2e30f), v);
  EXPECT_EQ(right.x, v.width_px) << "a box far to the right is clipped to the right edge";
  EXPECT_EQ(right.w, 0) << "and covers nothing";
  const BoundsTest left = bounds_test(box(-2e30f, -1e30f), v);
  EXPECT_EQ(left.x, 0);
  EXPECT_EQ(left.w, 0);
}

}  // namespace

// DemoSceneTest: the built-in city depth scene (pipeline/scenes/demo_scene.h) that `nbsim nbuffer`
// and the N-buffer benchmarks use: the requested size, deterministic for a size and a seed, depths
// in [0, 1] with sky at the far plane above the horizon, ground that gets nearer row by row below it.
#include "pipeline/scenes/demo_scene.h"

#include <gtest/gtest.h>

namespace nbsim::scenes {
namespace {

TEST(DemoSceneTest, DeterministicStreetWithSkyAtTheFarPlane) {
  const DepthImage a = city_depth(160, 120, 3);
  ASSERT_EQ(a.width, 160);
  ASSERT_EQ(a.height, 120);
  EXPECT_EQ(city_depth(160, 120, 3).texels, a.texels) << "the same size and seed give the same scene";
  EXPECT_NE(city_depth(160, 120, 4).texels, a.texels) << "another seed places other buildings";
  for (float d : a.texels) ASSERT_TRUE(d >= 0.0f && d <= 1.0f) << d;
  EXPECT_EQ(a.at(80, a.height - 1), 1.0f) << "the sky (y up) at the top row's centre, above the street";
  EXPECT_LT(a.at(80, 0), a.at(80, 40)) << "the street nearer at the bottom row than further up";
  int above_horizon = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) above_horizon += a.at(x, y) < 1.0f && y > 0.62 * a.height;
  EXPECT_GT(above_horizon, 0) << "buildings rise above the horizon";
}

}  // namespace
}  // namespace nbsim::scenes

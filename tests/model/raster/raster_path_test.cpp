// RasterPathTest: one draw through geometry, setup, traversal and depth test (model/raster/
// raster_path.h): ties at equal depth with normal and reversed Z, and refused sizes.
#include "model/raster/raster_path.h"

#include <gtest/gtest.h>

#include <vector>

#include "model/common/depth.h"
#include "model/common/error.h"

namespace nbsim::raster {
namespace {

using geometry::ClipControl;
using geometry::ClipPosition;

// A draw into a cleared buffer passes everywhere; the same draw again ties: LESS rejects every
// fragment, LEQUAL passes every one. Reversed Z (GREATER, clear 0) behaves the same way.
TEST(RasterPathTest, RepeatedDrawTiesAtEqualDepth) {
  const std::vector<ClipPosition> quad = {{-0.8f, -0.7f, 0.2f, 1}, {0.9f, -0.6f, 0.5f, 1}, {0.7f, 0.8f, 0.1f, 1},
                                          {-0.8f, -0.7f, 0.2f, 1}, {0.7f, 0.8f, 0.1f, 1},  {-0.9f, 0.6f, 0.3f, 1}};
  for (const bool reversed : {false, true}) {
    DepthImage img(96, 64, reversed ? 0.0f : 1.0f);
    RasterPath path({96, 64, 85, true, true}, img);
    DrawState st;
    st.geometry.clip = reversed ? ClipControl::ZeroToOne : ClipControl::NegativeOneToOne;
    st.depth.func = reversed ? DepthFunc::Greater : DepthFunc::Less;
    const DrawCounters first = path.draw(quad, st);
    EXPECT_GT(first.depth.fragments, 1000u);
    EXPECT_EQ(first.depth.passed, first.depth.fragments) << "everything passes against the clear value";
    EXPECT_EQ(first.depth.written, first.depth.fragments);
    EXPECT_EQ(first.depth.depth_tests, first.depth.fragments) << "one depth test per fragment";
    const DrawCounters second = path.draw(quad, st);
    EXPECT_EQ(second.depth.fragments, first.depth.fragments) << "same geometry, same fragments";
    EXPECT_EQ(second.depth.passed, 0u) << "strict test against identical depths fails";
    st.depth.func = reversed ? DepthFunc::Gequal : DepthFunc::Lequal;
    st.depth.write = false;
    EXPECT_EQ(path.draw(quad, st).depth.passed, first.depth.fragments) << "non-strict test passes ties";
  }
}

// A bad target size is the user's error, not a crash.
TEST(RasterPathTest, RejectsBadSizes) {
  DepthImage img(4, 4, 1.0f);
  EXPECT_THROW(RasterPath({0, 4}, img), InputError);
  EXPECT_THROW(RasterPath({8, 8}, img), InputError) << "depth buffer of another size";
  EXPECT_THROW(geometry::GeometryStage({64, 64, 0, true}), InputError) << "batch of zero triangles";
}

}  // namespace
}  // namespace nbsim::raster

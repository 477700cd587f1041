// RasterPathTest: one draw through geometry, setup, traversal and depth test (model/raster/
// raster_path.h): ties at equal depth with normal and reversed Z, and refused sizes.
#include "model/raster/raster_path.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "model/common/depth.h"
#include "model/common/error.h"

namespace nbsim::raster {
namespace {

using geometry::ClipControl;
using geometry::ClipPosition;
using geometry::CullFace;

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

// A window-system framebuffer (RasterPathConfig::window_framebuffer) is drawn upside down with the
// bottom-edge fill rule, as llvmpipe draws one: the image GL reads back (rows mirrored) is the one an
// FBO gets, pixel for pixel, also where an edge runs through pixel centres (where the fill rule
// decides). Without the rule's change, the rows on the horizontal edges would differ.
TEST(RasterPathTest, WindowFramebufferIsTheFboImageUpsideDown) {
  constexpr int kW = 32, kH = 32;
  // A rectangle from window y 8.5 to 23.5 (clip y -0.46875 .. 0.46875: edges through pixel centres),
  // and a tilted triangle with no ties.
  const std::vector<std::vector<ClipPosition>> draws = {
      {{-0.5f, -0.46875f, 0.25f, 1}, {0.5f, -0.46875f, 0.25f, 1}, {0.5f, 0.46875f, -0.25f, 1},
       {-0.5f, -0.46875f, 0.25f, 1}, {0.5f, 0.46875f, -0.25f, 1}, {-0.5f, 0.46875f, -0.25f, 1}},
      {{-0.83f, -0.71f, 0.3f, 1}, {0.77f, -0.52f, -0.1f, 1}, {0.11f, 0.93f, 0.6f, 1}}};
  for (const auto& positions : draws) {
    DepthImage fbo(kW, kH, 1.0f), window(kW, kH, 1.0f);
    RasterPathConfig c{kW, kH, 85, true, true};
    RasterPath fbo_path(c, fbo);
    c.window_framebuffer = true;
    RasterPath window_path(c, window);
    DrawState st;
    st.geometry.face.cull = CullFace::None;
    const DrawCounters a = fbo_path.draw(positions, st);
    const DrawCounters b = window_path.draw(positions, st);
    EXPECT_GT(a.depth.passed, 100u);
    EXPECT_EQ(a.depth.passed, b.depth.passed);
    int differing = 0;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) differing += (fbo.at(x, y) == 1.0f) != (window.at(x, kH - 1 - y) == 1.0f) ? 1 : 0;
    EXPECT_EQ(differing, 0) << "covered pixels of the read-back image";
  }
}

// Rasterization reuse (set_reuse_rasterization) changes no count and no depth: a sequence of draws
// (the same triangles again, then moved ones, then the first again, under other depth funcs) gives
// the same counters and buffer with it on as off; a moved vertex or another face state is not reused.
TEST(RasterPathTest, ReuseOfTheRasterizationChangesNothing) {
  std::vector<ClipPosition> a;
  for (int i = 0; i < 40; ++i) {  // overlapping triangles of varied depth
    const float fi = static_cast<float>(i), x = -0.9f + 0.04f * fi, z = 0.1f + 0.02f * static_cast<float>(i % 7);
    a.insert(a.end(), {{x, -0.8f, z, 1}, {x + 0.5f, -0.5f + 0.01f * fi, z + 0.3f, 1}, {x + 0.1f, 0.7f, 0.9f - z, 1}});
  }
  std::vector<ClipPosition> b = a;
  b[5][0] = std::nextafter(b[5][0], 1.0f);  // one ulp: not the same draw
  struct Step {
    const std::vector<ClipPosition>* positions;
    DepthFunc func;
    CullFace cull;
  };
  const Step steps[] = {{&a, DepthFunc::Lequal, CullFace::None}, {&a, DepthFunc::Less, CullFace::None},
                        {&b, DepthFunc::Lequal, CullFace::None}, {&a, DepthFunc::Greater, CullFace::None},
                        {&a, DepthFunc::Lequal, CullFace::Back}, {&a, DepthFunc::Always, CullFace::Back}};
  DepthImage off(80, 72, 1.0f), on(80, 72, 1.0f);
  RasterPath plain({80, 72, 85, true, true}, off), reusing({80, 72, 85, true, true}, on);
  reusing.set_reuse_rasterization(true);
  for (const Step& st : steps) {
    DrawState ds;
    ds.geometry.face.cull = st.cull;
    ds.depth.func = st.func;
    const DrawCounters p = plain.draw(*st.positions, ds), r = reusing.draw(*st.positions, ds);
    EXPECT_EQ(r.geometry.prims_out, p.geometry.prims_out);
    EXPECT_EQ(r.setup.culled, p.setup.culled);
    EXPECT_EQ(r.tiles.blocks16_partial, p.tiles.blocks16_partial);
    EXPECT_EQ(r.depth.fragments, p.depth.fragments);
    EXPECT_EQ(r.depth.passed, p.depth.passed);
    EXPECT_EQ(r.depth.written, p.depth.written);
    ASSERT_EQ(on.texels, off.texels) << "the buffers after each draw are the same";
  }
}

// A point draw's rasterization shared between two paths (PointRaster, as the two litmaps share
// their receiver splats) changes no count and no depth: a min and a max target drawn with and
// without sharing end alike after each draw; moved points, other sizes or another path size are
// rasterized anew.
TEST(RasterPathTest, SharedPointRasterizationChangesNothing) {
  std::vector<ClipPosition> a;
  std::vector<float> ones, twos;
  for (int i = 0; i < 300; ++i) {  // points of varied depth, some on pixel edges, some off screen
    const float fi = static_cast<float>(i);
    a.push_back({-1.1f + 0.0075f * fi, std::sin(fi) * 0.95f, 0.5f + 0.45f * std::cos(fi * 0.7f), 1});
    ones.push_back(1.0f), twos.push_back(i % 3 == 0 ? 3.0f : 1.0f);
  }
  std::vector<ClipPosition> b = a;
  b[7][1] = std::nextafter(b[7][1], 1.0f);
  struct Step {
    const std::vector<ClipPosition>* positions;
    const std::vector<float>* sizes;
  };
  const Step steps[] = {{&a, &ones}, {&a, &ones}, {&b, &ones}, {&b, &twos}, {&a, &twos}};
  DepthImage min_plain(80, 72, 1.0f), max_plain(80, 72, 0.0f), min_shared(80, 72, 1.0f), max_shared(80, 72, 0.0f);
  DepthImage other(81, 72, 0.0f), other_plain(81, 72, 0.0f);
  const RasterPathConfig c{80, 72, 85, true, true}, c81{81, 72, 85, true, true};
  RasterPath p_min(c, min_plain), p_max(c, max_plain), s_min(c, min_shared), s_max(c, max_shared), s_other(c81, other),
      p_other(c81, other_plain);
  RasterPath::PointRaster shared;
  DrawState lequal, gequal;
  lequal.depth.func = DepthFunc::Lequal;
  gequal.depth.func = DepthFunc::Gequal;
  const auto same = [](const DrawCounters& x, const DrawCounters& y) {
    return x.geometry.prims_out == y.geometry.prims_out && x.setup.culled == y.setup.culled &&
           x.tiles.blocks4_partial == y.tiles.blocks4_partial && x.tiles.blocks4_empty == y.tiles.blocks4_empty &&
           x.depth.fragments == y.depth.fragments && x.depth.passed == y.depth.passed && x.depth.written == y.depth.written;
  };
  for (const Step& st : steps) {
    EXPECT_TRUE(same(s_min.draw_points(*st.positions, *st.sizes, lequal, &shared), p_min.draw_points(*st.positions, *st.sizes, lequal)));
    EXPECT_TRUE(shared.valid);
    EXPECT_TRUE(same(s_max.draw_points(*st.positions, *st.sizes, gequal, &shared), p_max.draw_points(*st.positions, *st.sizes, gequal)));
    EXPECT_TRUE(same(s_other.draw_points(*st.positions, *st.sizes, gequal, &shared), p_other.draw_points(*st.positions, *st.sizes, gequal)))
        << "another size: rasterized anew";
    ASSERT_EQ(min_shared.texels, min_plain.texels);
    ASSERT_EQ(max_shared.texels, max_plain.texels);
    ASSERT_EQ(other.texels, other_plain.texels);
  }
  EXPECT_GT(std::count_if(max_plain.texels.begin(), max_plain.texels.end(), [](float v) { return v > 0.0f; }), 100);
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

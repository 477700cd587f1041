// RasterizerTest: the tile traversal (model/raster/rasterizer.h) against the brute-force coverage
// reference on random triangles, and its block classes.
#include "model/raster/rasterizer.h"

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

// The tile/block traversal reports exactly the reference pixel set, inside the target, for random
// triangles from sub-pixel to larger than the target (on a target that is no multiple of 16).
// Every other triangle is adversarial: its vertices lie on the half-pixel grid, so edges run
// through pixel centres and along tile and block borders.
TEST(RasterizerTest, TraversalMatchesBruteForceReference) {
  constexpr int W = 203, H = 141;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  int mismatches = 0, covered_total = 0;
  for (int n = 0; n < 2000 && mismatches < 10; ++n) {
    const float scale = std::pow(2.0f, unit(rng) * 10.0f - 2.0f);  // 0.25 .. 256 px
    const float cx = -40.0f + unit(rng) * (W + 80.0f), cy = -40.0f + unit(rng) * (H + 80.0f);
    WindowTriangle t;
    for (auto& v : t.v) {
      v = WindowVertex{cx + (unit(rng) - 0.5f) * scale, cy + (unit(rng) - 0.5f) * scale, 0.5f, 1.0f};
      if (n % 2 == 1) {
        v.x = std::round(v.x * 2.0f) / 2.0f;
        v.y = std::round(v.y * 2.0f) / 2.0f;
      }
    }
    const Coverage c = cover({t}, W, H);
    ASSERT_EQ(c.outside, 0) << "triangle " << n << " reported pixels outside the target";
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const int want = reference_covers(t, x, y) ? 1 : 0;
        covered_total += want;
        if (c.at(x, y) != want && mismatches++ < 10)
          ADD_FAILURE() << "triangle " << n << " pixel (" << x << "," << y << "): traversal " << c.at(x, y)
                        << ", reference " << want;
      }
  }
  EXPECT_GT(covered_total, 100000) << "the random triangles must cover a meaningful area";
}

// Block classes: a triangle over most of a 256 x 256 target bins into full interior tiles and
// partial ones along its hypotenuse and the target's right and top borders; small triangles are
// single-stamp and single-block commands.
TEST(RasterizerTest, TileCountersClassifyBlocks) {
  const WindowTriangle big = tri(-10.0f, -10.0f, 500.0f, -10.0f, -10.0f, 500.0f);
  const Coverage c = cover({big}, 256, 256);
  long reference = 0;
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) reference += reference_covers(big, x, y);
  EXPECT_EQ(c.total(), reference);
  EXPECT_EQ(c.tiles.tri_binned, 1u) << "spans several tiles";
  EXPECT_EQ(c.tiles.tiles_full, 9u) << "the 3 x 3 interior tiles are full";
  EXPECT_EQ(c.tiles.tiles_partial, 7u) << "the border row and column are partial (scissor planes)";
  EXPECT_EQ(c.tiles.tiles_empty, 0u);
  EXPECT_GT(c.tiles.blocks16_full, 0u);
  EXPECT_GT(c.tiles.blocks4_partial, 0u) << "the hypotenuse needs pixel tests";
  const Coverage stamp = cover({tri(8.6f, 8.6f, 10.9f, 8.6f, 8.6f, 10.9f)}, 32, 32);
  EXPECT_EQ(stamp.tiles.tri_stamp4, 1u) << "box inside one 4 x 4 stamp";
  EXPECT_EQ(stamp.total(), 1) << "only the centre (9.5, 9.5) lies inside";
  const Coverage block = cover({tri(1.0f, 1.0f, 12.0f, 1.0f, 1.0f, 12.0f)}, 32, 32);
  EXPECT_EQ(block.tiles.tri_block16, 1u) << "box inside one 16 x 16 block";
}

}  // namespace
}  // namespace nbsim::raster

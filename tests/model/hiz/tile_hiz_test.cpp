// TileHiZTest: the single-level tile Hi-Z baseline (model/hiz/tile_hiz.h) against brute force:
// conservative and exact over the tiles read, the right lookup count, kept up to date by
// rectangle, pixel-write and clear updates, at any tile size and image size.
#include "model/hiz/tile_hiz.h"

#include <gtest/gtest.h>

#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "model/common/error.h"
#include "tests/common/reference.h"

namespace nbsim {
namespace {

constexpr FarOp kOps[] = {FarOp::Max, FarOp::Min};

// Random rectangle, pixel-write and clear updates interleaved with random queries: every answer
// equals the farthest over the union of the tiles touched (quantized toward far), is at least the
// rectangle's farthest, and reads exactly the tiles touched.
TEST(TileHiZTest, ConservativeAndCountsTilesTouched) {
  for (const FarOp op : kOps)
    for (const int tile : {1, 3, 8, 16})
      for (const StorageFormat f : {StorageFormat::F32, StorageFormat::U16}) {
        const int w = 45, h = 27;
        TileHiZ hiz(w, h, {op, f, tile});
        DepthImage truth(w, h, far_limit(op));
        std::mt19937 rng(static_cast<unsigned>(tile * 13 + static_cast<int>(op)));
        ref::Failures fails;
        for (int step = 0; step < 120; ++step) {
          const int kind = ref::uniform_int(rng, 0, 19);
          if (kind == 0) {
            const float v = ref::unit_float(rng);
            std::fill(truth.texels.begin(), truth.texels.end(), v);
            hiz.clear(v);
          } else if (kind < 10) {
            const Rect r = ref::random_rect(rng, w, h, true);
            const Rect c = clip(r, w, h);
            for (int y = c.y; y < c.y1(); ++y)
              for (int x = c.x; x < c.x1(); ++x) truth.at(x, y) = ref::unit_float(rng);
            hiz.update(truth, r);
          } else {
            std::vector<PixelWrite> writes;
            for (int i = ref::uniform_int(rng, 1, 30); i > 0; --i) {
              const PixelWrite pw{ref::uniform_int(rng, 0, w - 1), ref::uniform_int(rng, 0, h - 1),
                                  ref::unit_float(rng)};
              truth.at(pw.x, pw.y) = pw.depth;
              writes.push_back(pw);
            }
            hiz.update(truth, writes);
          }
          for (int q = 0; q < 3; ++q) {
            const Rect r = ref::random_rect(rng, w, h, true);
            const Rect c = clip(r, w, h);
            const float nearest = ref::unit_float(rng);
            const TileHiZAnswer a = hiz.query(r, nearest);
            std::set<std::pair<int, int>> touched;
            for (int y = c.y; y < c.y1(); ++y)
              for (int x = c.x; x < c.x1(); ++x) touched.insert({x / tile, y / tile});
            float over_tiles = neutral_depth(op);
            for (const auto& [tx, ty] : touched)
              over_tiles = farther(op, over_tiles, ref::farthest(truth, op, {tx * tile, ty * tile, tile, tile}));
            over_tiles = quantize_toward_far(over_tiles, f, op);
            const float exact = ref::farthest(truth, op, c);
            const std::string at = ref::str(r) + " tile " + std::to_string(tile) + ": ";
            if (a.lookups != static_cast<int>(touched.size()))
              fails.add(at + "lookups " + std::to_string(a.lookups) + ", tiles touched " +
                        std::to_string(touched.size()));
            if (c.empty()) {
              if (!a.offscreen || a.hidden) fails.add(at + "off-screen rectangle answered on-screen");
              continue;
            }
            if (!at_least_as_far(op, a.value, exact)) fails.add(at + "conservative: nearer than the true farthest");
            if (a.value != over_tiles) fails.add(at + "exact: differs from the farthest over the tiles touched");
            if (a.hidden != (op == FarOp::Max ? nearest > a.value : nearest < a.value)) fails.add(at + "hidden rule");
          }
        }
        EXPECT_EQ(fails.count(), 0) << "op " << to_string(op) << ", tile " << tile << ", format " << to_string(f)
                                    << ": " << fails.summary();
      }
}

// Lookup counts on a table of rectangles at tile and image borders (64x40, 8x8 tiles: 8x5 tiles).
TEST(TileHiZTest, LookupCountTable) {
  struct Row {
    Rect r;
    int lookups;
    const char* why;
  };
  const Row rows[] = {
      {{0, 0, 1, 1}, 1, "one pixel reads its tile"},
      {{0, 0, 8, 8}, 1, "an aligned tile reads one"},
      {{7, 7, 2, 2}, 4, "a 2x2 on a tile corner reads four"},
      {{4, 0, 8, 8}, 2, "half a tile shifted reads two"},
      {{0, 0, 64, 40}, 40, "the whole image reads every tile"},
      {{60, 36, 10, 10}, 1, "clipped at the top-right corner"},
      {{-100, -100, 50, 50}, 0, "off the image reads nothing"},
      {{1, 1, 17, 1}, 3, "a 17-pixel sliver spans three tiles"},
  };
  TileHiZ hiz(64, 40);
  for (const Row& row : rows) EXPECT_EQ(hiz.query(row.r, 0.5f).lookups, row.lookups) << row.why;
}

// Updates recompute each touched tile once and report the pixels read.
TEST(TileHiZTest, UpdateWork) {
  TileHiZ hiz(20, 12, {FarOp::Max, StorageFormat::F32, 8});  // tiles 8, 8, 4 wide; 8, 4 high
  DepthImage depth(20, 12, 0.5f);
  TileHiZUpdate u = hiz.build(depth);
  EXPECT_EQ(u.tiles_recomputed, 6u);
  EXPECT_EQ(u.pixels_read, 240u);
  EXPECT_EQ(u.tiles_changed, 6u) << "every tile moves from the clear 1.0 to 0.5";
  const PixelWrite writes[] = {{0, 0, 0.2f}, {1, 1, 0.2f}, {17, 9, 0.7f}};
  depth.at(0, 0) = depth.at(1, 1) = 0.2f;
  depth.at(17, 9) = 0.7f;
  u = hiz.update(depth, writes);
  EXPECT_EQ(u.tiles_recomputed, 2u) << "two writes in one tile recompute it once";
  EXPECT_EQ(u.pixels_read, 64u + 16u);
  EXPECT_EQ(u.tiles_changed, 1u) << "the tile whose max stays 0.5 does not change";
  EXPECT_EQ(hiz.tile(2, 1), 0.7f);
  EXPECT_EQ(hiz.storage_bytes(), 6 * 4);
}

// Bad sizes and writes outside the image are the user's error, with a message.
TEST(TileHiZTest, Refusals) {
  EXPECT_THROW(TileHiZ(0, 4), InputError);
  EXPECT_THROW(TileHiZ(4, 4, {FarOp::Max, StorageFormat::F32, 0}), InputError);
  TileHiZ hiz(4, 4);
  const DepthImage depth(4, 4, 0.5f);
  const PixelWrite bad[] = {{4, 0, 0.1f}};
  try {
    hiz.update(depth, bad);
    ADD_FAILURE() << "a write outside the image was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("outside the 4x4 image"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace nbsim

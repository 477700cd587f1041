// RectLevelsTest: the rectangle levels of model/nbuffer/nbuffer.h (LevelShape::Rect, the paper's
// future work): which levels exist, every texel against brute force, exact queries in at most four
// lookups, capped aspect ratios, incremental updates (dirty rectangles and pixel writes) equal to a
// full rebuild, the memory limit.
#include <gtest/gtest.h>

#include <bit>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "model/nbuffer/nbuffer.h"
#include "tests/common/reference.h"

namespace nbsim {
namespace {

NBufferConfig rect_config(FarOp op, int max_aspect_log2 = -1, StorageFormat format = StorageFormat::F32) {
  NBufferConfig c;
  c.op = op;
  c.format = format;
  c.shape = LevelShape::Rect;
  c.max_aspect_log2 = max_aspect_log2;
  return c;
}

// The brute-force farthest of the 2^i x 2^j neighbourhood at (x, y), clipped to the image.
float neighbourhood(const DepthImage& img, FarOp op, int i, int j, int x, int y) {
  return ref::farthest(img, op, clip({x, y, 1 << i, 1 << j}, img.width, img.height));
}

TEST(RectLevelsTest, WhichLevelsExist) {
  EXPECT_EQ(rect_levels(512, 512, -1).size(), 81u) << "9 x 9";
  EXPECT_EQ(rect_levels(640, 480, -1).size(), 90u) << "10 x 9";
  EXPECT_EQ(rect_levels(1, 1, -1).size(), 1u);
  EXPECT_EQ(rect_levels(1, 40, -1).size(), 6u) << "1 x 6: a 1-pixel-wide image";
  // |i - j| <= 1 on 512x512: the diagonal and its two neighbours (9 + 8 + 8).
  const auto k1 = rect_levels(512, 512, 1);
  std::set<std::pair<int, int>> have(k1.begin(), k1.end());
  EXPECT_EQ(have.size(), k1.size());
  EXPECT_TRUE(have.count({8, 8}) && have.count({7, 8}) && have.count({3, 4}));
  EXPECT_FALSE(have.count({3, 5}) || have.count({8, 0}));
  EXPECT_EQ(k1.size(), 9u + 8u + 8u);
  // On 512x8 the last row of levels is whole: a 512x1 rectangle reads 2^8 x 2^2 (j raised to
  // 8 - 1 = 7 is past the image's 3 height exponents).
  const auto wide = rect_levels(512, 8, 1);
  const std::set<std::pair<int, int>> w8(wide.begin(), wide.end());
  EXPECT_TRUE(w8.count({8, 2}) && w8.count({4, 2}) && w8.count({0, 0}) && w8.count({1, 0}));
  EXPECT_FALSE(w8.count({4, 0}));
  // Build order: each level after the one it is built from.
  for (std::size_t p = 1; p < k1.size(); ++p) EXPECT_LE(k1[p - 1].first + k1[p - 1].second, k1[p].first + k1[p].second);
}

// Every texel of every level equals the farthest of its neighbourhood, on odd, power-of-two and
// 1-pixel images, both ops, with and without an aspect cap.
TEST(RectLevelsTest, EveryTexelIsItsNeighbourhoodsFarthest) {
  for (const auto& [w, h] : {std::pair{37, 23}, std::pair{32, 16}, std::pair{1, 19}, std::pair{21, 1}})
    for (const FarOp op : {FarOp::Max, FarOp::Min})
      for (const int k : {-1, 1, 2}) {
        const DepthImage img = ref::uniform(w, h, static_cast<std::uint32_t>(w * 31 + h + k));
        const NBuffer nb(img, rect_config(op, k));
        ASSERT_EQ(nb.level_count(), static_cast<int>(rect_levels(w, h, k).size()));
        for (int p = 0; p < nb.level_count(); ++p) {
          const auto [i, j] = nb.level_exponents(p);
          EXPECT_EQ(nb.level_label(p), std::to_string(1 << i) + "x" + std::to_string(1 << j));
          for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
              ASSERT_EQ(nb.texel(p, x, y), neighbourhood(img, op, i, j, x, y)) << w << "x" << h << " level " << nb.level_label(p);
        }
      }
}

// With every level, any rectangle is answered exactly in at most four lookups; with a cap, the
// answer is the farthest over the rectangles read (each inside the image from its corner), at
// least the rectangle's.
TEST(RectLevelsTest, QueriesAreExactWithEveryLevel) {
  std::mt19937 rng(5);
  for (const auto& [w, h] : {std::pair{37, 23}, std::pair{64, 64}, std::pair{1, 40}, std::pair{77, 3}}) {
    const DepthImage img = ref::uniform(w, h, static_cast<std::uint32_t>(w + h));
    for (const FarOp op : {FarOp::Max, FarOp::Min}) {
      const NBuffer full(img, rect_config(op)), capped(img, rect_config(op, 1));
      for (int n = 0; n < 2000; ++n) {
        const Rect r = ref::random_rect(rng, w, h, true);
        const Rect c = clip(r, w, h);
        if (c.empty()) continue;
        const float truth = ref::farthest(img, op, c);
        const QueryResult q = full.query(r, {CoveringKind::Paper, n % 2 ? CoveringAlign::Top : CoveringAlign::Bottom});
        ASSERT_EQ(q.value, truth) << ref::str(r) << " in " << w << "x" << h;
        ASSERT_LE(q.texel_count, 4);
        const QueryResult qc = capped.query(r);
        const Covering cov = capped.covering(c, {});
        float over = neutral_depth(op);
        for (const Texel& t : qc.read()) over = farther(op, over, ref::farthest(img, op, clip({t.x, t.y, cov.width_px(), cov.height_px()}, w, h)));
        ASSERT_EQ(qc.value, over) << ref::str(r);
        ASSERT_TRUE(at_least_as_far(op, qc.value, truth));
        ASSERT_LE(qc.texel_count, 4);
      }
    }
  }
  // A 100 x 10 box: 64 x 8 rectangles, two by two, exact.
  const DepthImage img = ref::uniform(256, 256, 3);
  const NBuffer nb(img, rect_config(FarOp::Max));
  const Covering c = nb.covering({10, 200, 100, 10}, {});
  EXPECT_EQ(c.width_px(), 64);
  EXPECT_EQ(c.height_px(), 8);
  EXPECT_EQ(c.count, 4);
  EXPECT_EQ(covered_area(c), 100 * 10);
  // Capped at |i - j| <= 1: 64 x 32 rectangles, one row flush with the box's top.
  const NBuffer k1(img, rect_config(FarOp::Max, 1));
  const Covering d = k1.covering({10, 200, 100, 10}, {});
  EXPECT_EQ(d.width_px(), 64);
  EXPECT_EQ(d.height_px(), 32);
  EXPECT_EQ(d.count, 2);
  EXPECT_EQ(d.squares[0].y, 210 - 32);
}

// Updates (a dirty rectangle, a batch of pixel writes) leave every level equal to a full rebuild,
// and recompute nothing above level 0 when nothing changed.
TEST(RectLevelsTest, UpdatesEqualAFullRebuild) {
  std::mt19937 rng(9);
  for (const auto& [w, h] : {std::pair{37, 23}, std::pair{16, 16}, std::pair{1, 13}})
    for (const FarOp op : {FarOp::Max, FarOp::Min})
      for (const StorageFormat f : {StorageFormat::F32, StorageFormat::U16})
        for (const int k : {-1, 1}) {
          DepthImage depth = ref::uniform(w, h, 1);
          NBuffer nb(depth, rect_config(op, k, f));
          for (int step = 0; step < 40; ++step) {
            if (step % 2 == 0) {
              const Rect r = ref::random_rect(rng, w, h, true);
              const Rect c = clip(r, w, h);
              for (int y = c.y; y < c.y1(); ++y)
                for (int x = c.x; x < c.x1(); ++x) depth.at(x, y) = ref::uniform_float(rng, 0.0f, 1.0f);
              nb.update(depth, r);
            } else {
              std::vector<PixelWrite> writes;
              for (int n = ref::uniform_int(rng, 1, 6); n > 0; --n) {
                PixelWrite pw{ref::uniform_int(rng, 0, w - 1), ref::uniform_int(rng, 0, h - 1), ref::uniform_float(rng, 0.0f, 1.0f)};
                depth.at(pw.x, pw.y) = pw.depth;
                writes.push_back(pw);
              }
              nb.update(writes);
            }
            const NBuffer fresh(depth, rect_config(op, k, f));
            for (int p = 0; p < nb.level_count(); ++p)
              for (std::size_t t = 0; t < nb.level(p).size(); ++t)
                ASSERT_EQ(std::bit_cast<std::uint32_t>(nb.level(p)[t]), std::bit_cast<std::uint32_t>(fresh.level(p)[t]))
                    << w << "x" << h << " step " << step << " level " << nb.level_label(p);
          }
          const UpdateStats same = nb.update(depth, {0, 0, w, h});
          EXPECT_EQ(same.total_changed(), 0);
          EXPECT_EQ(same.total_recomputed(), static_cast<long long>(w) * h) << "level 0 is compared, nothing above it";
        }
}

TEST(RectLevelsTest, RefusesWhatItCannotHold) {
  EXPECT_THROW(NBuffer(16, 16, [] { auto c = rect_config(FarOp::Max); c.max_level = 2; return c; }()), InputError);
  EXPECT_THROW(NBuffer(16, 16, rect_config(FarOp::Max, 0)), InputError);
  try {
    NBuffer(8192, 8192, rect_config(FarOp::Max));
    ADD_FAILURE() << "169 levels of 8192x8192 floats (42 GiB) were accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("above the limit of 4096 MiB"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace nbsim

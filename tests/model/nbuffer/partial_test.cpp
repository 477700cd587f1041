// PartialBuildTest: N-buffers built only up to NBufferConfig::max_level (model/nbuffer/nbuffer.h)
// against the full build: same levels, same answers where the level exists, the far limit with
// complete == false where it does not.
#include "model/nbuffer/nbuffer.h"

#include <gtest/gtest.h>

#include <climits>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "tests/common/reference.h"

namespace nbsim {
namespace {

constexpr FarOp kOps[] = {FarOp::Max, FarOp::Min};
constexpr CoveringSpec kKinds[] = {{CoveringKind::Paper, CoveringAlign::Top},
                                   {CoveringKind::Corners, CoveringAlign::Bottom},
                                   {CoveringKind::One, CoveringAlign::Bottom}};

// Compares the partial answer p with the full build's answer f to the same rectangle, whose
// true farthest depth is truth; "" when every rule holds.
std::string check_partial(const QueryResult& p, const QueryResult& f, int max_level, FarOp op, float truth) {
  std::string err;
  auto fail = [&](const std::string& rule) { err += (err.empty() ? "" : "; ") + rule; };
  if (!at_least_as_far(op, p.value, truth))
    fail("conservative: answered " + std::to_string(p.value) + ", nearer than the truth " + std::to_string(truth));
  if (f.level <= max_level) {
    if (!p.complete) fail("complete: level " + std::to_string(f.level) + " is built but the answer is incomplete");
    if (p.value != f.value) fail("same answer: " + std::to_string(p.value) + " vs the full build's " + std::to_string(f.value));
    if (p.level != f.level || p.texel_count != f.texel_count || p.texels != f.texels)
      fail("same texels: read other texels than the full build");
  } else {
    if (p.complete) fail("incomplete: needs level " + std::to_string(f.level) + " > max_level but answered complete");
    if (p.value != far_limit(op)) fail("far limit: an incomplete answer must be the far limit, got " + std::to_string(p.value));
    if (p.level != f.level) fail("level: must name the level needed, " + std::to_string(f.level) + ", got " + std::to_string(p.level));
    if (p.texel_count != 0) fail("no reads: an incomplete answer read " + std::to_string(p.texel_count) + " texels");
  }
  return err;
}

// Levels 0..max_level of a partial build equal the full build's, bit for bit; nothing above.
TEST(PartialBuildTest, LevelsEqualFullBuild) {
  const std::pair<int, int> sizes[] = {{37, 21}, {64, 64}, {1, 45}, {70, 33}};
  for (const FarOp op : kOps)
    for (const auto& [w, h] : sizes) {
      const DepthImage img = ref::uniform(w, h, 1);
      const NBuffer full(img, {.op = op});
      for (int k = 0; k < full.level_count(); ++k) {
        const NBuffer part(img, {.op = op, .max_level = k});
        ASSERT_EQ(part.level_count(), k + 1) << w << "x" << h << " max_level " << k;
        EXPECT_EQ(part.full_level_count(), full.level_count()) << "the full count does not depend on max_level";
        EXPECT_EQ(part.storage_bytes(), static_cast<long long>(k + 1) * w * h * 4) << "only built levels take memory";
        for (int i = 0; i <= k; ++i) {
          const auto a = part.level(i), b = full.level(i);
          EXPECT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end()))
              << to_string(op) << " " << w << "x" << h << " max_level " << k << ": level " << i << " differs from the full build";
        }
      }
    }
}

// max_level beyond the top level is clamped to a full build; -1 means all; below -1 is an error.
TEST(PartialBuildTest, MaxLevelClamped) {
  const DepthImage img = ref::uniform(37, 21, 2);
  const NBuffer full(img);
  const int top = full.level_count() - 1;
  struct Row { int max_level; int levels; const char* why; };
  const Row rows[] = {
      {-1, top + 1, "-1 builds every level"},
      {top, top + 1, "the top level itself"},
      {top + 1, top + 1, "one past the top is clamped"},
      {1000, top + 1, "far past the top is clamped"},
  };
  for (const Row& row : rows) {
    const NBuffer nb(img, {.max_level = row.max_level});
    ASSERT_EQ(nb.level_count(), row.levels) << row.why;
    for (int i = 0; i < nb.level_count(); ++i) {
      const auto a = nb.level(i), b = full.level(i);
      EXPECT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end())) << row.why << ": level " << i;
    }
    EXPECT_TRUE(nb.query({0, 0, 37, 21}).complete) << row.why << ": the whole image is answerable";
  }
  EXPECT_THROW(NBuffer(img, {.max_level = -2}), InputError) << "below -1 is a config error";
  EXPECT_THROW(NBuffer(8, 8, {.max_level = INT_MIN}), InputError) << "below -1 is a config error";
}

// The largest max_level is clamped like any other (max_level + 1 must not overflow).
TEST(PartialBuildTest, MaxLevelIntMaxIsClamped) {
  const NBuffer nb(ref::uniform(37, 21, 2), {.max_level = INT_MAX});
  EXPECT_EQ(nb.level_count(), nb.full_level_count()) << "INT_MAX means every level";
}

// Every rectangle of small images, every max_level: conservative always, the full build's answer
// whenever the level needed is built, the far limit marked incomplete otherwise.
TEST(PartialBuildTest, EveryRectAgreesWithFullBuild) {
  const std::pair<int, int> sizes[] = {{37, 21}, {16, 16}, {1, 19}, {5, 3}};
  for (const FarOp op : kOps)
    for (const auto& [w, h] : sizes) {
      const DepthImage img = op == FarOp::Max ? ref::uniform(w, h, 3) : ref::mirror(ref::uniform(w, h, 3));
      const NBuffer full(img, {.op = op});
      ref::Failures f;
      long long incomplete = 0, complete = 0;
      for (int k = 0; k < full.level_count(); ++k) {
        const NBuffer part(img, {.op = op, .max_level = k});
        ref::for_each_rect(img, op, [&](const Rect& r, float truth) {
          for (const CoveringSpec kind : kKinds) {
            const QueryResult p = part.query(r, kind), q = full.query(r, kind);
            (p.complete ? complete : incomplete) += 1;
            const std::string e = check_partial(p, q, k, op, truth);
            if (!e.empty()) f.add("max_level " + std::to_string(k) + " " + ref::str(r) + ": " + e);
          }
        });
      }
      EXPECT_EQ(f.count(), 0) << to_string(op) << " " << w << "x" << h << ": " << f.summary();
      if (full.level_count() > 1) {
        EXPECT_GT(incomplete, 0) << "both outcomes must be exercised";
      }
      EXPECT_GT(complete, 0);
    }
}

// Random rectangles (some partly outside) on 641x479 with the levels sprites need (max_level 5).
TEST(PartialBuildTest, RandomRects641x479) {
  for (const FarOp op : kOps) {
    const DepthImage img = ref::uniform(641, 479, 4);
    const NBuffer full(img, {.op = op});
    const ref::RowTable table(img, op);
    for (const int k : {0, 5, 8}) {
      const NBuffer part(img, {.op = op, .max_level = k});
      std::mt19937 rng(static_cast<std::uint32_t>(5 + k));
      ref::Failures f;
      for (int n = 0; n < 20000; ++n) {
        const Rect r = ref::random_rect(rng, 641, 479, true);
        const float truth = table.farthest(r);
        for (const CoveringSpec kind : kKinds) {
          const std::string e = check_partial(part.query(r, kind), full.query(r, kind), k, op, truth);
          if (!e.empty()) f.add(ref::str(r) + ": " + e);
        }
      }
      EXPECT_EQ(f.count(), 0) << to_string(op) << " max_level " << k << ": " << f.summary();
    }
  }
}

// Incremental updates on a partial build keep its levels equal to a partial rebuild.
TEST(PartialBuildTest, UpdatesMatchPartialRebuild) {
  for (const FarOp op : kOps) {
    std::mt19937 rng(6);
    DepthImage depth = ref::uniform(45, 27, 7);
    const NBufferConfig cfg{.op = op, .max_level = 2};
    NBuffer nb(depth, cfg);
    for (int round = 0; round < 60; ++round) {
      UpdateStats st;
      if (round % 2) {
        const Rect dirty = ref::random_rect(rng, 45, 27, true), c = clip(dirty, 45, 27);
        DepthImage next = depth;
        for (int y = c.y; y < c.y1(); ++y)
          for (int x = c.x; x < c.x1(); ++x) next.at(x, y) = depth.at(x, y) = ref::unit_float(rng);
        st = nb.update(next, dirty);
      } else {
        const PixelWrite wr{ref::uniform_int(rng, 0, 44), ref::uniform_int(rng, 0, 26), far_limit(op)};
        depth.at(wr.x, wr.y) = wr.depth;
        st = nb.update(std::span(&wr, 1));
      }
      ASSERT_EQ(st.texels_recomputed.size(), 3u) << "stats cover the built levels only";
      const NBuffer rebuilt(depth, cfg);
      for (int i = 0; i < nb.level_count(); ++i) {
        const auto a = nb.level(i), b = rebuilt.level(i);
        ASSERT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end())) << "round " << round << " level " << i;
      }
    }
  }
}

// Hand-checked partial answers; each row says why it is there.
TEST(PartialBuildTest, EdgeCases) {
  struct Row { const char* why; int max_level; FarOp op; Rect r; CoveringSpec kind; bool complete; int level; };
  constexpr CoveringSpec Four{CoveringKind::Corners, CoveringAlign::Bottom}, One{CoveringKind::One, CoveringAlign::Bottom},
      Paper{CoveringKind::Paper, CoveringAlign::Top};
  const Row rows[] = {
      {"8x8 needs level 3, built", 3, FarOp::Max, {0, 0, 8, 8}, Four, true, 3},
      {"8x8 needs level 3, only 0..2 built", 2, FarOp::Max, {0, 0, 8, 8}, Four, false, 3},
      {"8x8, the paper's covering: four level-2 squares, built", 2, FarOp::Max, {0, 0, 8, 8}, Paper, true, 2},
      {"8x2, the paper's covering: a row of level-1 squares", 1, FarOp::Max, {0, 4, 8, 2}, Paper, true, 1},
      {"5x5: four squares need level 2 (built)", 2, FarOp::Max, {0, 0, 5, 5}, Four, true, 2},
      {"5x5: one square needs level 3 (missing)", 2, FarOp::Max, {0, 0, 5, 5}, One, false, 3},
      {"reversed Z: incomplete answers 0, the far plane", 0, FarOp::Min, {3, 3, 2, 2}, Four, false, 1},
      {"1-pixel rectangle needs only level 0", 0, FarOp::Max, {7, 7, 1, 1}, One, true, 0},
      {"clipped to 2x2 at the corner: level 1 is enough", 1, FarOp::Max, {30, 30, 10, 10}, Four, true, 1},
  };
  const DepthImage img = ref::uniform(32, 32, 8, 0.1f, 0.9f);
  for (const Row& row : rows) {
    const NBuffer nb(img, {.op = row.op, .max_level = row.max_level});
    const QueryResult q = nb.query(row.r, row.kind);
    EXPECT_EQ(q.complete, row.complete) << row.why;
    EXPECT_EQ(q.level, row.level) << row.why;
    if (!row.complete) EXPECT_EQ(q.value, far_limit(row.op)) << row.why;
    else EXPECT_EQ(q.value, NBuffer(img, {.op = row.op}).query(row.r, row.kind).value) << row.why;
  }
}

}  // namespace
}  // namespace nbsim

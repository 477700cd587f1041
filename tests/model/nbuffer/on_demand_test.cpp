// OnDemandTest: the on-demand N-buffer (NBuffer::set_on_demand): random updates (dirty rectangles,
// pixel writes, rebuilds) and queries on odd sizes, both far operators and a rounding format; every
// query answers what a full build of the same level 0 answers, every texel it read equals the full
// build's, and once every texel is made current the levels equal it bit for bit. The upkeep follows
// the queries: an update computes nothing above level 0, a query computes at most the texels under
// its squares, and asking again computes nothing.
#include "model/nbuffer/nbuffer.h"

#include <gtest/gtest.h>

#include <bit>
#include <random>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "tests/common/reference.h"

namespace nbsim {
namespace {

float random_depth(std::mt19937& rng) { return std::uniform_real_distribution<float>(0.0f, 1.0f)(rng); }

DepthImage random_image(std::mt19937& rng, int w, int h) {
  DepthImage d(w, h, 1.0f);
  for (float& v : d.texels) v = random_depth(rng);
  return d;
}

long long computed_above_level_0(const UpdateStats& s) { return s.total_recomputed() - s.texels_recomputed[0]; }

TEST(OnDemandTest, EveryQueryEqualsAFullBuild) {
  struct Case {
    int w, h;
    FarOp op;
    StorageFormat format;
  };
  const Case cases[] = {{37, 23, FarOp::Max, StorageFormat::F32}, {64, 64, FarOp::Min, StorageFormat::F32},
                        {100, 3, FarOp::Max, StorageFormat::U16}, {1, 45, FarOp::Min, StorageFormat::U16}};
  for (const Case& c : cases) {
    SCOPED_TRACE(std::to_string(c.w) + "x" + std::to_string(c.h));
    std::mt19937 rng(static_cast<unsigned>(c.w * 131 + c.h));
    const NBufferConfig cfg{c.op, c.format};
    DepthImage truth = random_image(rng, c.w, c.h);
    NBuffer lazy(truth, cfg);
    lazy.set_on_demand(true);
    UpdateStats work = lazy.new_stats();
    long long queries = 0, mismatches = 0;
    for (int step = 0; step < 200; ++step) {
      const int kind = static_cast<int>(rng() % 10);
      if (kind == 0) {
        truth = random_image(rng, c.w, c.h);
        lazy.build(truth);
      } else if (kind < 6) {
        const Rect r = ref::random_rect(rng, c.w, c.h, false);
        for (int y = r.y; y < r.y1(); ++y)
          for (int x = r.x; x < r.x1(); ++x) truth.at(x, y) = random_depth(rng);
        const UpdateStats s = lazy.update(truth, r);
        EXPECT_EQ(computed_above_level_0(s), 0) << "an update computes nothing above level 0";
      } else {
        std::vector<PixelWrite> writes;
        for (int i = 0, n = 1 + static_cast<int>(rng() % 30); i < n; ++i) {
          PixelWrite pw{static_cast<int>(rng() % static_cast<unsigned>(c.w)), static_cast<int>(rng() % static_cast<unsigned>(c.h)),
                        random_depth(rng)};
          truth.at(pw.x, pw.y) = pw.depth;
          writes.push_back(pw);
        }
        EXPECT_EQ(computed_above_level_0(lazy.update(writes)), 0);
      }
      const NBuffer full(truth, cfg);
      for (int q = 0; q < 6; ++q) {
        const Rect r = ref::random_rect(rng, c.w, c.h, false);
        const Covering cov = lazy.covering(r, {});
        for (int i = 0; i < cov.count; ++i)
          lazy.ensure(cov.level, cov.squares[static_cast<std::size_t>(i)].x, cov.squares[static_cast<std::size_t>(i)].y, work);
        const QueryResult a = lazy.query(r), b = full.query(r);
        ++queries;
        mismatches += std::bit_cast<std::uint32_t>(a.value) != std::bit_cast<std::uint32_t>(b.value);
        for (const Texel& t : a.read())
          mismatches += std::bit_cast<std::uint32_t>(lazy.texel(a.level, t.x, t.y)) != std::bit_cast<std::uint32_t>(full.texel(a.level, t.x, t.y));
      }
    }
    EXPECT_EQ(mismatches, 0) << "of " << queries << " queries";
    // Every texel made current: the levels equal a full build.
    lazy.ensure_all(work);
    const NBuffer full(truth, cfg);
    long long differ = 0;
    for (int i = 0; i < full.level_count(); ++i) {
      EXPECT_EQ(lazy.current_texels(i), static_cast<long long>(c.w) * c.h);
      for (int y = 0; y < c.h; ++y)
        for (int x = 0; x < c.w; ++x) differ += std::bit_cast<std::uint32_t>(lazy.texel(i, x, y)) != std::bit_cast<std::uint32_t>(full.texel(i, x, y));
    }
    EXPECT_EQ(differ, 0);
  }
}

TEST(OnDemandTest, UpkeepFollowsTheQueries) {
  std::mt19937 rng(9);
  DepthImage truth = random_image(rng, 128, 128);
  NBuffer nb(truth, {});
  nb.set_on_demand(true);
  // A change of one pixel marks stale at most the texels of each level that read it (4^0 .. ), and
  // no texel is computed.
  truth.at(70, 70) = 0.0f;
  const UpdateStats u = nb.update(truth, {70, 70, 1, 1});
  EXPECT_EQ(computed_above_level_0(u), 0);
  for (int i = 1; i < nb.level_count(); ++i) {
    const long long side = std::min(1LL << i, 71LL);
    EXPECT_EQ(u.texels_invalidated[static_cast<std::size_t>(i)], side * side) << "level " << i;
  }
  // A query at level 3 over the change computes the stale texels under its squares, no more.
  UpdateStats q = nb.new_stats();
  nb.ensure(3, 68, 68, q);
  EXPECT_EQ(q.texels_recomputed[3], 1);
  EXPECT_EQ(q.texels_recomputed[2], 1) << "only the source texel over the change was stale";
  EXPECT_EQ(q.texels_recomputed[1], 1);
  // Asking again computes nothing; a second change marks only what is current again.
  UpdateStats again = nb.new_stats();
  nb.ensure(3, 68, 68, again);
  EXPECT_EQ(again.total_recomputed(), 0);
  truth.at(70, 70) = 0.5f;
  const UpdateStats u2 = nb.update(truth, {70, 70, 1, 1});
  EXPECT_EQ(u2.texels_invalidated[1], 1);
  EXPECT_EQ(u2.texels_invalidated[3], 1);
  EXPECT_EQ(u2.texels_invalidated[4], 0) << "level 4 was never computed since the first change";
  const NBuffer full(truth, {});
  UpdateStats w = nb.new_stats();
  const int top = nb.top_level();
  nb.ensure(top, 0, 0, w);
  EXPECT_EQ(nb.texel(top, 0, 0), full.texel(top, 0, 0));
}

// replace_on_demand: a new level 0 with every texel above it stale, as a cleared N-buffer given a
// new image; each texel then made current equals a full build of that image, and computing one
// texel of level L computes the 4^L - 1 texels above level 0 under it, once.
TEST(OnDemandTest, ReplacedLevelZeroLeavesEveryLevelStale) {
  std::mt19937 rng(11);
  NBuffer nb(random_image(rng, 33, 20), NBufferConfig{FarOp::Max, StorageFormat::F32, -1});
  nb.set_on_demand(true);
  const DepthImage next = random_image(rng, 33, 20);
  nb.replace_on_demand(next);
  for (int l = 1; l < nb.level_count(); ++l) EXPECT_EQ(nb.current_texels(l), 0) << "level " << l;
  UpdateStats s = nb.new_stats();
  nb.ensure(3, 4, 2, s);
  EXPECT_EQ(computed_above_level_0(s), 1 + 4 + 16) << "the texel and the 4 + 16 below it";
  nb.ensure(3, 4, 2, s);
  EXPECT_EQ(computed_above_level_0(s), 21) << "kept";
  const NBuffer full(next, NBufferConfig{FarOp::Max, StorageFormat::F32, -1});
  for (int l = 0; l < nb.level_count(); ++l)
    for (int y = 0; y < 20; ++y)
      for (int x = 0; x < 33; ++x) {
        nb.ensure(l, x, y, s);
        ASSERT_EQ(std::bit_cast<std::uint32_t>(nb.texel(l, x, y)), std::bit_cast<std::uint32_t>(full.texel(l, x, y)))
            << "level " << l << " (" << x << ", " << y << ")";
      }
}

TEST(OnDemandTest, RectangleLevelsRefused) {
  NBuffer nb(16, 16, NBufferConfig{FarOp::Max, StorageFormat::F32, -1, LevelShape::Rect});
  try {
    nb.set_on_demand(true);
    FAIL() << "rectangle levels on demand";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("square levels only"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace nbsim

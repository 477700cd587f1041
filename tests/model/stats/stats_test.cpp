// StatsTest: statistics groups and the registry of model/stats/stats.h.
#include "model/stats/stats.h"

#include <gtest/gtest.h>

namespace nbsim::stats {
namespace {

// Counters, vectors and formulas dump under their group's full name, in declaration order.
TEST(StatsTest, DumpsValuesInDeclarationOrder) {
  Registry r;
  Group& g = r.group("gpu.nbuffer");
  Counter& lookups = g.counter("lookups", "texels", "N-buffer texels read by queries");
  VectorCounter& per_level = g.vector("updates", "texels", "texels rewritten per level", {"l0", "l1"});
  g.formula("lookups_per_update", "ratio", "lookups per rewritten texel",
            [&] { return ratio(static_cast<double>(lookups.value()), static_cast<double>(per_level.total())); });
  lookups += 6;
  per_level.add(1, 3);
  const auto v = r.values();
  EXPECT_EQ(v["gpu.nbuffer"]["lookups"], 6);
  EXPECT_EQ(v["gpu.nbuffer"]["updates"]["l1"], 3);
  EXPECT_DOUBLE_EQ(v["gpu.nbuffer"]["lookups_per_update"].get<double>(), 2.0);
  EXPECT_EQ(v["gpu.nbuffer"].begin().key(), "lookups") << "declaration order is kept";
  const auto flat = r.flatten();
  ASSERT_EQ(flat.size(), 4u);
  EXPECT_EQ(flat[2].first, "gpu.nbuffer.updates.l1");
}

// A maximum keeps the largest value raised to, sits in declaration order among the counters, and
// is described as a maximum.
TEST(StatsTest, MaximumKeepsTheLargest) {
  Registry r;
  Group& g = r.group("gpu.cull");
  Counter& tests = g.counter("bounds_tests", "tests", "bounds tested");
  Counter& most = g.maximum("max_lookups", "texels", "most texels one test read");
  Counter& after = g.counter("culled", "objects", "culled");
  most.raise_to(3);
  most.raise_to(1);
  tests += 2;
  after += 5;
  const auto v = r.values()["gpu.cull"];
  EXPECT_EQ(v["max_lookups"], 3) << "a smaller value lowered the maximum";
  EXPECT_EQ(v["bounds_tests"], 2);
  EXPECT_EQ(v["culled"], 5) << "a maximum between two counters shifted their values";
  EXPECT_EQ(r.describe()[1]["kind"], "maximum");
}

// Every statistic is described with its full name, unit and description.
TEST(StatsTest, DescribesEveryStatistic) {
  Registry r;
  r.group("gpu.depth").counter("tests", "tests", "depth tests performed");
  const auto d = r.describe();
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0]["name"], "gpu.depth.tests");
  EXPECT_EQ(d[0]["unit"], "tests");
}

// Ratios of empty counters are 0, never NaN; reset zeroes counters but keeps declarations.
TEST(StatsTest, RatioOfZeroAndReset) {
  EXPECT_EQ(ratio(5, 0), 0.0);
  Registry r;
  Counter& c = r.group("a.b").counter("n", "events", "n");
  ++c;
  r.reset();
  EXPECT_EQ(c.value(), 0u);
  EXPECT_EQ(r.values()["a.b"]["n"], 0);
}

// Declaring a name twice is a bug and aborts.
TEST(StatsDeathTest, DuplicateNameAborts) {
  Registry r;
  Group& g = r.group("a.b");
  g.counter("n", "events", "n");
  EXPECT_DEATH(g.counter("n", "events", "again"), "declared twice");
}

}  // namespace
}  // namespace nbsim::stats

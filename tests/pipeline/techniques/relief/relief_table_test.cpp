// ReliefTableTest: `nbsim relief`'s table functions (pipeline/techniques/relief/relief_table.h) on
// hand-built run.json values: one row per frame and method with its ratios and the frame's angle,
// the methods ranked by cycles with the Pareto front, the N-buffer walk against the exact walk per
// heightfield, the paper's Table 1 rows beside the fbm rows of the same size, and the refusal of a
// run.json that is not a relief replay.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "model/common/error.h"
#include "pipeline/techniques/relief/relief_table.h"

namespace {

using nlohmann::json;
using nlohmann::ordered_json;
using namespace nbsim::techniques;

json method_values(std::uint64_t fragments, std::uint64_t lookups, std::uint64_t errors, std::uint64_t cycles) {
  return {{"fragments", fragments}, {"lookups", lookups}, {"steps", lookups / 2}, {"errors", errors}, {"cycles", cycles},
          {"reference_hits", fragments}};
}

// A relief run.json: `frames` frames, each with the given methods' values, of field `field` at `size`.
json relief_run(const std::string& field, int size, const json& methods, int frames, const std::string& angles = "30,60") {
  json run;
  run["trace_properties"] = {{"technique", "relief"}, {"relief_field", field}, {"relief_field_size", std::to_string(size)},
                             {"relief_angles", angles}};
  run["frames"] = json::array();
  for (int f = 0; f < frames; ++f) run["frames"].push_back({{"frame", f}, {"relief", methods}});
  return run;
}

const ordered_json* find(const ordered_json& array, const std::string& key, const std::string& value) {
  for (const auto& e : array)
    if (e[key] == value) return &e;
  return nullptr;
}

TEST(ReliefTableTest, RowsPerFrameAndMethod) {
  const json methods = {{"exact", method_values(100, 800, 0, 5000)}, {"binary", method_values(100, 300, 7, 2000)}};
  const ordered_json rows = relief_rows({relief_run("fbm", 64, methods, 3)}, {"a.nbt"});
  ASSERT_EQ(rows.size(), 6u);  // 3 frames x 2 methods
  const ordered_json& r = rows[2];  // frame 1's first method (methods in the object's key order)
  EXPECT_EQ(r["trace"], "a.nbt");
  EXPECT_EQ(r["field"], "fbm");
  EXPECT_EQ(r["field_size"], 64);
  EXPECT_EQ(r["frame"], 1);
  EXPECT_DOUBLE_EQ(r["angle"].get<double>(), 60.0) << "frame 1 takes the second angle";
  EXPECT_DOUBLE_EQ(rows[4]["angle"].get<double>(), 30.0) << "frame 2 wraps round to the first";
  const ordered_json& binary = r["method"] == "binary" ? r : rows[3];
  EXPECT_DOUBLE_EQ(binary["lookups_per_fragment"].get<double>(), 3.0);
  EXPECT_DOUBLE_EQ(binary["steps_per_fragment"].get<double>(), 1.5);
  EXPECT_DOUBLE_EQ(binary["error_rate"].get<double>(), 0.07);
  EXPECT_EQ(binary["pixel_mismatches"], 0u) << "absent counters read as 0";
}

TEST(ReliefTableTest, NoFragmentsGiveNullRatiosAndBadAnglesNoAngle) {
  const json methods = {{"exact", method_values(0, 0, 0, 10)}};
  const ordered_json rows = relief_rows({relief_run("walls", 32, methods, 1, "thirty")}, {"b.nbt"});
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_TRUE(rows[0]["lookups_per_fragment"].is_null());
  EXPECT_TRUE(rows[0]["error_rate"].is_null());
  EXPECT_TRUE(rows[0]["angle"].is_null());
}

TEST(ReliefTableTest, RunOfAnotherTechniqueRefused) {
  json run = relief_run("fbm", 64, {{"exact", method_values(1, 1, 0, 1)}}, 1);
  run["trace_properties"]["technique"] = "particles";
  try {
    relief_rows({run}, {"p.nbt"});
    FAIL() << "a particles run.json was read as a relief one";
  } catch (const nbsim::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'p.nbt' was not replayed as a relief trace"), std::string::npos) << e.what();
  }
  json no_frames = relief_run("fbm", 64, json::object(), 0);
  no_frames.erase("frames");
  EXPECT_THROW(relief_rows({no_frames}, {"q.nbt"}), nbsim::InputError);
}

// A replay with relief.score=false has null hit errors: the table refuses it rather than read 0.
TEST(ReliefTableTest, UnscoredRunRefused) {
  json methods = {{"exact", method_values(100, 800, 0, 5000)}};
  methods["exact"]["errors"] = nullptr;
  try {
    relief_rows({relief_run("fbm", 64, methods, 1)}, {"u.nbt"});
    FAIL() << "an unscored run gave rows";
  } catch (const nbsim::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("relief.score=false"), std::string::npos) << e.what();
  }
}

// Ranking: mean cycles a frame, error rate over all fragments; a method is on the front unless
// another is at most as costly and as wrong and better in one.
TEST(ReliefTableTest, RankingOrdersByCyclesAndMarksTheParetoFront) {
  const json methods = {{"exact", method_values(100, 800, 0, 5000)},
                        {"binary", method_values(100, 300, 7, 2000)},
                        {"robust", method_values(100, 400, 0, 3000)},
                        {"slow_and_wrong", method_values(100, 900, 9, 6000)}};
  const ordered_json ranking = relief_ranking(relief_rows({relief_run("fbm", 64, methods, 2)}, {"a.nbt"}));
  ASSERT_EQ(ranking.size(), 4u);
  std::vector<std::string> order;
  for (const auto& m : ranking) order.push_back(m["method"]);
  EXPECT_EQ(order, (std::vector<std::string>{"binary", "robust", "exact", "slow_and_wrong"}));
  EXPECT_TRUE((*find(ranking, "method", "binary"))["pareto"].get<bool>());
  EXPECT_TRUE((*find(ranking, "method", "robust"))["pareto"].get<bool>());
  EXPECT_FALSE((*find(ranking, "method", "exact"))["pareto"].get<bool>()) << "robust is cheaper and as exact";
  EXPECT_FALSE((*find(ranking, "method", "slow_and_wrong"))["pareto"].get<bool>());
  const ordered_json& binary = *find(ranking, "method", "binary");
  EXPECT_EQ(binary["fragments"], 200u);
  EXPECT_EQ(binary["errors"], 14u);
  EXPECT_DOUBLE_EQ(binary["cycles_per_frame"].get<double>(), 2000.0);
  EXPECT_DOUBLE_EQ(binary["error_rate"].get<double>(), 0.07);
}

TEST(ReliefTableTest, NBufferAgainstExactPerHeightfield) {
  const json fbm = {{"exact", method_values(100, 800, 1, 5000)}, {"nbuffer", method_values(100, 200, 3, 2500)}};
  const json walls = {{"exact", method_values(50, 100, 0, 900)}};  // no N-buffer walk: no row
  const ordered_json pairs =
      relief_nbuffer_vs_exact(relief_rows({relief_run("fbm", 64, fbm, 1), relief_run("walls", 64, walls, 1)}, {"a.nbt", "b.nbt"}));
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0]["field"], "fbm");
  EXPECT_EQ(pairs[0]["field_size"], 64);
  EXPECT_DOUBLE_EQ(pairs[0]["exact_lookups_per_fragment"].get<double>(), 8.0);
  EXPECT_DOUBLE_EQ(pairs[0]["nbuffer_lookups_per_fragment"].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(pairs[0]["lookup_ratio"].get<double>(), 0.25);
  EXPECT_EQ(pairs[0]["extra_errors"], 2);
}

// The paper's rows are always there (3 methods x 4 sizes); our cycles stand beside them only for
// fbm heightfields of the same size.
TEST(ReliefTableTest, PaperTableBesideTheFbmRowsOfTheSameSize) {
  const json m = {{"robust", method_values(100, 400, 0, 3000)}};
  const ordered_json table = relief_paper_table(
      relief_rows({relief_run("fbm", 64, m, 2), relief_run("walls", 128, m, 1)}, {"a.nbt", "b.nbt"}));
  ASSERT_EQ(table.size(), 12u);
  int with_cycles = 0;
  for (const auto& r : table) {
    EXPECT_GT(r["paper_hz"].get<double>(), 0.0);
    if (r["cycles_per_frame"].is_null()) continue;
    ++with_cycles;
    EXPECT_EQ(r["method"], "robust");
    EXPECT_EQ(r["field_size"], 64);
    EXPECT_DOUBLE_EQ(r["cycles_per_frame"].get<double>(), 3000.0);
    EXPECT_DOUBLE_EQ(r["lookups_per_fragment"].get<double>(), 4.0);
  }
  EXPECT_EQ(with_cycles, 1) << "walls at 128 are not the paper's terrain";
}

}  // namespace

// ShadowsSampleTest: the committed shadows samples (scripts/make_samples: the city flown over at
// 320x240, 4 frames, 2,000 objects, mode clamped, litmaps of 256 and 128 lexels) replay exact: every
// draw's fragments and passed samples, the stencil buffer and both shadow masks equal GL's; and
// `nbsim shadows` runs on them with the ratio to GL's infinite reference beside the paper's.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "tests/common/run_nbsim.h"

namespace {

namespace fs = std::filesystem;
using nbsim::testing::CliResult;
using nbsim::testing::run_nbsim;

fs::path sample(const std::string& name) { return fs::path(NBSIM_SAMPLES) / name; }

class ShadowsSampleTest : public ::testing::TestWithParam<std::string> {};

// `nbsim compare` on the sample: every draw exact, stencil and depth buffers equal, 0 mask pixels differing.
TEST_P(ShadowsSampleTest, SampleReplaysExactly) {
  const fs::path t = sample(GetParam());
  ASSERT_TRUE(fs::exists(t)) << t << " missing: run scripts/make_samples";
  const CliResult r = run_nbsim("compare " + t.string() + " --json");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["frames"], 4);
  EXPECT_GT(j["draws"].get<int>(), 0);
  EXPECT_EQ(j["draws_exact"], j["draws"]) << "every draw's fragments and passed samples equal GL's";
  EXPECT_EQ(j["fragments_model"], j["fragments_gl"]);
  EXPECT_EQ(j["passed_model"], j["passed_gl"]);
  EXPECT_EQ(j["stencil_pixels_matching"], j["stencil_pixels"]) << "the stencil buffer equals GL's";
  EXPECT_EQ(j["depth_pixels_matching"], j["depth_pixels"]);
  ASSERT_TRUE(j.contains("shadows")) << "compare shows the shadows summary";
  const auto& s = j["shadows"];
  EXPECT_EQ(s["shadow_mode"], "clamped");
  EXPECT_EQ(s["scene"], "city");
  EXPECT_EQ(s["mask_diff"], 0) << "the model's mask equals GL's";
  EXPECT_EQ(s["mask_diff_infinite"], 0) << "and the infinite reference's";
  EXPECT_EQ(s["gl_mask_diff"], 0) << "GL's clamped mask equals GL's infinite mask";
  EXPECT_GT(s["mask_pixels"].get<int>(), 0) << "the sample has shadows to lose";
  EXPECT_EQ(s["zmin_mismatches"], 0) << "f32 full resolution: GL's z_min";
  EXPECT_EQ(s["zmax_mismatches"], 0) << "f32 full resolution: GL's z_max";
  EXPECT_EQ(s["lookup_mismatches"], 0);
  EXPECT_EQ(s["decision_mismatches"], 0);
  EXPECT_EQ(s["unsafe_culls"], 0);
  EXPECT_GT(s["gl_culled"].get<int>(), 0) << "the flyover culls casters";
}

INSTANTIATE_TEST_SUITE_P(Samples, ShadowsSampleTest,
                         ::testing::Values("shadows_city_fly_320_litmap256.nbt", "shadows_city_fly_320_litmap128.nbt"),
                         [](const ::testing::TestParamInfo<std::string>& p) {
                           return p.param.substr(p.param.rfind('_') + 1, p.param.size() - p.param.rfind('_') - 5);
                         });

// `nbsim shadows --json` on both samples: one row each, clamped below the infinite reference, the
// 128-lexel litmap culling fewer casters on this flyover (coarser z_min/z_max), both masks exact.
TEST(ShadowsSampleTableTest, RunsTheTableOnBothSamples) {
  const fs::path a = sample("shadows_city_fly_320_litmap256.nbt"), b = sample("shadows_city_fly_320_litmap128.nbt");
  const CliResult r = run_nbsim("shadows " + a.string() + " " + b.string() + " --json");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto rows = nlohmann::json::parse(r.out);
  ASSERT_EQ(rows.size(), 2u);
  for (const auto& row : rows) {
    EXPECT_EQ(row["shadow_mode"], "clamped");
    EXPECT_EQ(row["mask_diff"], 0);
    EXPECT_EQ(row["mask_diff_infinite"], 0);
    EXPECT_EQ(row["draws_exact"], row["draws"]);
    EXPECT_EQ(row["ratio_reference"], "reference_fill") << "the ratio comes from GL's infinite pass in the same trace";
    ASSERT_TRUE(row["ratio_to_infinite"].is_number());
    EXPECT_GT(row["ratio_to_infinite"].get<double>(), 0.0);
    EXPECT_LT(row["ratio_to_infinite"].get<double>(), 1.0) << "clamping cuts the fill";
  }
  const auto by_litmap = [&](const char* size) {
    for (const auto& row : rows)
      if (row["litmap_size"] == size) return row;
    ADD_FAILURE() << "no row with litmap_size " << size;
    return nlohmann::json();
  };
  EXPECT_GE(by_litmap("256")["gl_culled_per_frame"].get<double>(), by_litmap("128")["gl_culled_per_frame"].get<double>())
      << "on the sample, the 256-lexel litmap culls more casters";
  EXPECT_NEAR(by_litmap("256")["reference_fill_per_frame"].get<double>(),
              by_litmap("128")["reference_fill_per_frame"].get<double>(),
              1e-4 * by_litmap("256")["reference_fill_per_frame"].get<double>())
      << "the same infinite volumes (cut at clamp planes from each trace's litmaps: a few fragments apart)";
}

}  // namespace

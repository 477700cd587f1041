// CullReplayTest: `nbsim replay --set cull.mode=MODE` on the sample traces, one replay (one SystemC
// elaboration) per process: no mode ever culls a visible object, the N-buffer spends at most four
// lookups per bounds test, the occlusion-query boxes cost exactly GL's recorded fragments, and
// `nbsim table2` runs every mode and prints its JSON list, at either granularity.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <set>
#include <fstream>
#include <string>
#include <tuple>

#include "tests/common/run_nbsim.h"
#include "traces/format/reader.h"

namespace nbsim {
namespace {

using testing::run_nbsim;

std::string sample(const std::string& name) { return (std::filesystem::path(NBSIM_SAMPLES) / name).string(); }

// Replays `trace` in `mode` into a fresh folder; returns run.json's cull summary.
nlohmann::json replay_cull(const std::string& trace, const std::string& mode, const std::string& extra = "") {
  const auto out = nbsim::testing::scratch_path("nbsim_cull", mode);
  std::filesystem::remove_all(out);
  const auto r = run_nbsim("replay " + sample(trace) + " --set cull.mode=" + mode + " " + extra + " --out " + out.string());
  EXPECT_EQ(r.status, 0) << r.err;
  std::ifstream in(out / "run.json");
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  std::filesystem::remove_all(out);
  if (j.is_discarded() || !j["summary"].contains("cull")) {
    ADD_FAILURE() << "run.json without a cull summary for " << trace << " " << mode;
    return nlohmann::json::object();
  }
  return j["summary"]["cull"];
}

// (sample trace, cull mode) as strings: GoogleTest prints them as text (const char*s in a tuple
// print with their addresses, which then change the ctest names from build to build).
class CullReplayTest : public ::testing::TestWithParam<std::tuple<std::string, std::string>> {};

// A conservative mode never culls an object the ground truth shows visible, and it does decide.
TEST_P(CullReplayTest, NoFalseCulls) {
  const auto [trace, mode] = GetParam();
  const nlohmann::json c = replay_cull(trace, mode);
  ASSERT_FALSE(c.empty());
  EXPECT_EQ(c["frames"], 8u);
  EXPECT_EQ(c["frames_with_truth"], 8u) << "the samples carry ground truth in every frame";
  EXPECT_GT(c["candidates"].get<std::uint64_t>(), 0u);
  EXPECT_EQ(c["false_culls"], 0u) << mode << " culled a visible object";
  EXPECT_GT(c["culled"].get<std::uint64_t>(), 0u) << mode << " culled nothing: the test could not fail";
  EXPECT_LE(c["culled"].get<std::uint64_t>(), c["candidates_not_visible"].get<std::uint64_t>());
  EXPECT_GT(c["query_depth_tests"].get<std::uint64_t>(), 0u);
  EXPECT_GE(c["total_depth_tests"].get<std::uint64_t>(), c["query_depth_tests"].get<std::uint64_t>());
}

INSTANTIATE_TEST_SUITE_P(Samples, CullReplayTest,
                         ::testing::Combine(::testing::Values("city_small_oq.nbt", "city_small_nb_reversed.nbt"),
                                            ::testing::Values("oq", "oq_hier", "nb", "nb_hier", "hiz_tile", "hiz_pyramid")),
                         [](const auto& param_info) {
                           const std::string file = std::get<0>(param_info.param);
                           return file.substr(0, file.find('.')) + "_" + std::get<1>(param_info.param);
                         });

// The N-buffer answers every bounds test with at most four lookups, under every update policy.
TEST(CullReplayTest, NBufferAtMostFourLookupsPerTest) {
  for (const char* policy : {"eager", "batched", "lazy"}) {
    const nlohmann::json c = replay_cull("city_small_nb_reversed.nbt", "nb", std::string("--set nbuffer.update_policy=") + policy);
    ASSERT_FALSE(c.empty());
    EXPECT_LE(c["max_lookups_per_test"].get<std::uint64_t>(), 4u) << policy;
    EXPECT_LE(c["lookups"].get<std::uint64_t>(), 4 * c["bounds_tests"].get<std::uint64_t>()) << policy;
    EXPECT_GT(c["lookups"].get<std::uint64_t>(), 0u) << policy;
    EXPECT_EQ(c["false_culls"], 0u) << policy;
  }
}

// The model's occlusion-query boxes cost exactly the fragments GL counted for its BoundsQuery
// draws when the trace was captured with occlusion queries: the boxes are GL's, bit for bit.
TEST(CullReplayTest, OcclusionQueryBoxesCostGlsFragments) {
  std::uint64_t gl = 0;
  trace::FrameReader frames(sample("city_small_oq.nbt"));
  ASSERT_EQ(*frames.trace().property("test_mode"), "oq");
  while (auto f = frames.next())
    for (const auto& d : f->draws)
      if (d.role == trace::DrawRole::BoundsQuery) gl += d.gl.fragments;
  ASSERT_GT(gl, 0u);
  const nlohmann::json c = replay_cull("city_small_oq.nbt", "oq");
  ASSERT_FALSE(c.empty());
  EXPECT_EQ(c["box_depth_tests"].get<std::uint64_t>(), gl);
  EXPECT_EQ(c["query_depth_tests"].get<std::uint64_t>(), gl);
}

// Drawing every candidate culls nothing and costs no query depth tests.
TEST(CullReplayTest, ModeNoneCullsNothing) {
  const nlohmann::json c = replay_cull("city_small_oq.nbt", "none");
  ASSERT_FALSE(c.empty());
  EXPECT_EQ(c["culled"], 0u);
  EXPECT_EQ(c["query_depth_tests"], 0u);
  EXPECT_EQ(c["found_visible"], c["candidates"]);
}

// An unknown culling mode is the user's error: a message and exit status 2.
TEST(CullReplayTest, UnknownModeIsRefused) {
  const auto r = run_nbsim("replay " + sample("city_small_oq.nbt") + " --set cull.mode=nbuffer --out " + nbsim::testing::scratch_path("nbsim_cull", "bad").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(testing::has(r.err, "cull.mode")) << r.err;
}

// `nbsim table2 --json` runs the six modes and lists Table 2's columns, with no false culls.
// `nbsim table2 city_small_oq.nbt --json EXTRA`: the list of rows, or null (with a test failure).
nlohmann::json table2_rows(const std::string& extra = "") {
  const auto r = run_nbsim("table2 " + sample("city_small_oq.nbt") + " --json" + extra);
  EXPECT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
  EXPECT_TRUE(j.is_array() && j.size() == 6u) << r.out;
  return j.is_array() && j.size() == 6u ? j : nlohmann::json();
}

TEST(CullReplayTest, Table2PrintsJson) {
  const nlohmann::json j = table2_rows();
  ASSERT_FALSE(j.is_null());
  std::set<std::string> modes;
  for (const auto& row : j) {
    modes.insert(row["mode"].get<std::string>());
    for (const char* k : {"query_depth_tests_per_frame", "total_depth_tests_per_frame", "cycles_per_frame", "false_culls",
                          "culling_efficiency"})
      EXPECT_TRUE(row.contains(k)) << k;
    EXPECT_EQ(row["false_culls"], 0u) << row["mode"];
    EXPECT_GT(row["cycles_per_frame"].get<double>(), 0.0);
  }
  EXPECT_EQ(modes, (std::set<std::string>{"oq_hier", "oq", "nb_hier", "nb", "hiz_tile", "hiz_pyramid"}));
  EXPECT_LT(j[3]["query_depth_tests_per_frame"].get<double>(), j[1]["query_depth_tests_per_frame"].get<double>())
      << "the N-buffer should need fewer query depth tests than occlusion queries";
}

// `nbsim table2 --set cull.granularity=primitive` runs every row: the modes with a depth-query structure
// test triangles, the occlusion-query rows stay at object granularity, and no row culls a visible object.
TEST(CullReplayTest, Table2PrimitiveGranularity) {
  const nlohmann::json j = table2_rows(" --set cull.granularity=primitive");
  ASSERT_FALSE(j.is_null());
  for (const auto& row : j) {
    const std::string mode = row["mode"].get<std::string>();
    EXPECT_EQ(row["granularity"], mode.starts_with("oq") ? "object" : "primitive") << mode;
    EXPECT_EQ(row["false_culls"], 0u) << mode;
  }
}

}  // namespace
}  // namespace nbsim

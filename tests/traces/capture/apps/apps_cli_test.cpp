// `nbsim capture apps` (the technique's renderer capture: a program that never asked for culling)
// replayed by the model: every draw replayed and compared with GL's samples passed, and every
// final depth image equal to GL's, on two scenes and paths.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <fstream>
#include <string>

#include "tests/common/run_nbsim.h"

namespace {

using nbsim::testing::run_nbsim;

TEST(AppsCliTest, NativeCaptureReplaysEveryDrawExactly) {
  for (const std::string& where : {std::string("--scene city --objects 400 --path walk"), std::string("--scene boxes --path fly")}) {
    SCOPED_TRACE(where);
    const auto dir = nbsim::testing::scratch_dir("nbsim_apps_cli");
    const std::string trace = (dir / "apps.nbt").string();
    const auto c = run_nbsim("capture apps " + where + " --size 96x64 --frames 3 -o " + trace);
    ASSERT_EQ(c.status, 0) << c.out << c.err;
    const auto r = run_nbsim("replay " + trace + " --out " + (dir / "out").string());
    ASSERT_EQ(r.status, 0) << r.err;
    const auto run = nlohmann::json::parse(std::ifstream(dir / "out" / "run.json"));
    const auto& s = run["summary"]["apps"];
    EXPECT_GT(s["draws"].get<int>(), 3);
    EXPECT_EQ(s["compared"], s["draws"]) << "a program of the project's own: nothing flagged, nothing stale";
    EXPECT_EQ(s["mismatched"], 0);
    EXPECT_EQ(s["frames_depth_compared"], 3);
    EXPECT_EQ(s["depth_mismatches"], 0);
    std::ifstream log(dir / "out" / "app_draws.csv");
    std::string header;
    std::getline(log, header);
    EXPECT_EQ(header, "frame,draw,framebuffer,reason,stale,depth_change,may_discard,triangles,fragments,depth_tests,samples,gl_samples,match,"
                      "query_depth_tests");
  }
}

}  // namespace

// The apps program in every cull mode on the committed apps sample (a recorded program's frames):
// no draw GL drew samples of is culled, every drawn draw still equals GL's samples and every final
// depth GL's; the drawn depth tests fall by exactly what the culled draws cost in a plain replay;
// the full-resolution occlusion query culls at least what any conservative structure culls; the
// hierarchical modes are refused by name.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "tests/common/run_nbsim.h"

namespace {

using nbsim::testing::run_nbsim;

const std::string kSample = std::string(NBSIM_SAMPLES) + "/apps_glmark2_ideas_160.nbt";

// app_draws.csv: per (frame, draw), its reason column and depth tests.
std::map<std::pair<int, int>, std::pair<std::string, std::uint64_t>> draws_of(const std::filesystem::path& csv) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  std::map<std::pair<int, int>, std::pair<std::string, std::uint64_t>> out;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
    if (f.size() < 10) continue;
    out[{std::stoi(f[0]), std::stoi(f[1])}] = {f[3], std::stoull(f[9])};
  }
  return out;
}

TEST(AppsCullReplayTest, EveryModeCullsOnlyHiddenDrawsAndKeepsTheReplayExact) {
  const auto dir = nbsim::testing::scratch_dir("nbsim_apps_cull");
  const auto run = [&](const std::string& name, const std::string& sets) {
    const auto r = run_nbsim("replay " + kSample + " " + sets + " --out " + (dir / name).string());
    EXPECT_EQ(r.status, 0) << name << ": " << r.err;
    return nlohmann::json::parse(std::ifstream(dir / name / "run.json"))["summary"]["apps"];
  };
  const auto plain = run("trace", "");
  const auto plain_draws = draws_of(dir / "trace" / "app_draws.csv");
  std::map<std::string, std::uint64_t> culled;
  for (const std::string mode : {"oq", "nb", "hiz_tile", "hiz_pyramid", "nb+primitive", "nb+on_demand"}) {
    SCOPED_TRACE(mode);
    std::string sets = "--set cull.mode=" + mode.substr(0, mode.find('+'));
    if (mode == "nb+primitive") sets += " --set cull.granularity=primitive";
    if (mode == "nb+on_demand") sets += " --set nbuffer.update_policy=on_demand";
    const auto s = run(mode, sets);
    const auto& c = s["cull"];
    EXPECT_EQ(c["false_culls"], 0);
    EXPECT_EQ(s["mismatched"], 0);
    EXPECT_EQ(s["depth_mismatches"], 0);
    EXPECT_EQ(s["frames_depth_compared"], plain["frames_depth_compared"]);
    EXPECT_GT(c["tested"].get<std::uint64_t>(), 100u);
    EXPECT_GT(c["culled"].get<std::uint64_t>(), 0u) << "the sample's frames hide draws";
    EXPECT_LE(c["culled"].get<std::uint64_t>(), c["tested_hidden"].get<std::uint64_t>());
    culled[mode] = c["culled"].get<std::uint64_t>();
    EXPECT_EQ(c["total_depth_tests"].get<std::uint64_t>(),
              s["depth_tests"].get<std::uint64_t>() + c["query_depth_tests"].get<std::uint64_t>() + c["update_texels"].get<std::uint64_t>());
    if (mode == "nb+primitive") {
      EXPECT_GT(c["primitives_culled"].get<std::uint64_t>(), 0u);
      continue;
    }
    // The drawn depth tests are the plain replay's less the culled draws'.
    std::uint64_t saved = 0, count = 0;
    for (const auto& [key, v] : draws_of(dir / mode / "app_draws.csv"))
      if (v.first == "culled") saved += plain_draws.at(key).second, ++count;
    EXPECT_EQ(count, culled[mode]);
    EXPECT_EQ(s["depth_tests"].get<std::uint64_t>() + saved, plain["depth_tests"].get<std::uint64_t>());
  }
  for (const char* mode : {"nb", "hiz_tile", "hiz_pyramid"}) EXPECT_GE(culled["oq"], culled[mode]) << mode;
  EXPECT_EQ(culled["nb"], culled["nb+on_demand"]) << "an update policy changes the cost, never the answers";

  const auto refused = run_nbsim("replay " + kSample + " --set cull.mode=nb_hier --out " + (dir / "hier").string());
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.err.find("BVH"), std::string::npos) << refused.err;
}

}  // namespace

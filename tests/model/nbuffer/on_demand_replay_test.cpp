// OnDemandReplayTest: the on-demand N-buffer on the samples of every technique with an N-buffer unit
// (occlusion culling's `nbuffer`, particles' `nbuffer`, shadows' `litmap_min` and `litmap_max`),
// replayed eager and on demand through `nbsim compare`: every decision is the same (culled objects,
// sprites and casters, false culls, popping, GL mismatches), and the upkeep (texels computed for
// the levels) is smaller on these samples; relief's N-buffer walk reads what an on-demand build of
// the heightfield's levels computes.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/common/run_nbsim.h"

namespace nbsim {
namespace {

using testing::CliResult;
using testing::run_nbsim;

nlohmann::json summary(const std::string& args, const char* group) {
  const CliResult r = run_nbsim("compare --json " + args);
  EXPECT_EQ(r.status, 0) << args << ": " << r.err;
  return nlohmann::json::parse(r.out)[group];
}

struct Sample {
  const char* trace;
  const char* sets;         // the run's keys besides the policy
  std::vector<const char*> units;  // the N-buffer instances
  const char* group;        // the summary's group
  std::vector<const char*> decisions;
  const char* upkeep;       // texels computed for the levels, a frame
};

TEST(OnDemandReplayTest, SamplesDecideAsEager) {
  const std::string samples = NBSIM_SAMPLES;
  const Sample cases[] = {
      {"city_small_oq.nbt", "--set cull.mode=nb_hier", {"nbuffer"}, "cull", {"culled", "found_visible", "false_culls", "undrawable", "query_depth_tests"},
       "update_texels_per_frame"},
      {"city_walk_512.nbt", "--set cull.mode=nb", {"nbuffer"}, "cull", {"culled", "false_culls", "undrawable", "query_depth_tests"},
       "update_texels_per_frame"},
      {"particles_walk_256.nbt", "", {"nbuffer"}, "particles", {"culled", "false_culls", "popping", "decision_mismatches", "lookup_mismatches"},
       "build_texels_per_frame"},
      {"shadows_city_fly_320_litmap128.nbt", "", {"litmap_min", "litmap_max"}, "shadows",
       {"culled", "decision_mismatches", "zmin_mismatches", "zmax_mismatches", "unsafe_culls", "mask_diff", "lookup_mismatches"},
       "build_texels_per_frame"}};
  for (const Sample& s : cases) {
    SCOPED_TRACE(s.trace);
    const std::string base = samples + "/" + s.trace + " " + s.sets;
    std::string on_demand = base;
    for (const char* unit : s.units) on_demand += std::string(" --set ") + unit + ".update_policy=on_demand";
    const nlohmann::json e = summary(base, s.group), o = summary(on_demand, s.group);
    for (const char* k : s.decisions) EXPECT_EQ(e[k], o[k]) << k;
    EXPECT_LT(o[s.upkeep].get<double>(), e[s.upkeep].get<double>()) << "the upkeep follows the queries";
  }
}

// Relief's N-buffer walk reads the heightfield's levels as GL built them in full; the replay
// computes every texel it read on demand as well (from a cleared N-buffer, each from the level
// below, recursively, kept for the frame) and compares: the same values, for part of the texels.
TEST(OnDemandReplayTest, ReliefWalksReadWhatAnOnDemandBuildComputes) {
  const nlohmann::json m = summary(std::string(NBSIM_SAMPLES) + "/relief_fbm_64.nbt", "relief")["methods"]["nbuffer"];
  EXPECT_EQ(m["levels_on_demand_mismatches"].get<long>(), 0);
  EXPECT_GT(m["levels_on_demand_texels"].get<long>(), 0);
  EXPECT_LT(m["levels_on_demand_texels"].get<long>(), m["levels_eager_texels"].get<long>()) << "the walks read part of the levels";
  EXPECT_EQ(m["levels_eager_texels"].get<long>(), 4 * 5 * 64 * 64) << "four frames of five levels above 0 at 64x64";
}

}  // namespace
}  // namespace nbsim

// ReplayCliTest: `nbsim replay`, `nbsim compare` and `nbsim config` from the outside: the counter
// comparison passes on the sample traces and on a fresh capture, unit latencies change cycles but
// not depth-test counts, and bad configs are refused.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "tests/common/run_nbsim.h"

namespace {

namespace fs = std::filesystem;
using nbsim::testing::CliResult;
using nbsim::testing::has;
using nbsim::testing::run_nbsim;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("nbsim_replay_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

std::string sample(const char* name) { return (fs::path(NBSIM_SAMPLES) / name).string(); }

nlohmann::json read_json(const fs::path& f) {
  std::ifstream in(f);
  return nlohmann::json::parse(in);
}

// The model's fragments, passed samples and depth match GL on every sample trace.
TEST(ReplayCliTest, CompareSamplesWithinThresholds) {
  for (const char* s : {"city_small_oq.nbt", "city_small_nb_reversed.nbt", "city_walk_512.nbt"}) {
    const CliResult r = run_nbsim("compare " + sample(s) + " --json");
    ASSERT_EQ(r.status, 0) << s << ": " << r.out << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_TRUE(j["within_thresholds"].get<bool>()) << s;
    EXPECT_GT(j["draws"].get<long>(), 0) << s;
    EXPECT_EQ(j["fragments_model"], j["fragments_gl"]) << s;
    EXPECT_EQ(j["passed_model"], j["passed_gl"]) << s;
    EXPECT_EQ(j["depth_pixels_matching"], j["depth_pixels"]) << s;
  }
}

// A fresh capture on this machine's Mesa compares within the thresholds too (flyover, flat queries).
TEST(ReplayCliTest, CompareFreshCapture) {
  const fs::path t = scratch("fresh.nbt");
  const CliResult c = run_nbsim("capture city --size 96x80 --frames 3 --objects 700 --path fly --mode oq_hier -o " + t.string());
  ASSERT_EQ(c.status, 0) << c.out << c.err;
  const CliResult r = run_nbsim("compare " + t.string());
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "within the thresholds")) << r.out;
}

// Changing a unit's latency changes the cycles but not one depth-test count.
TEST(ReplayCliTest, LatencyChangesCyclesNotCounts) {
  const std::string t = sample("city_small_oq.nbt");
  const fs::path a = scratch("base"), b = scratch("slow");
  ASSERT_EQ(run_nbsim("replay " + t + " --out " + a.string()).status, 0);
  const CliResult r = run_nbsim("replay " + t + " --out " + b.string() +
                                " --set depth.latency_cycles=400 --set geometry.latency_cycles=300 --set memory.latency_cycles=900");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto ja = read_json(a / "run.json"), jb = read_json(b / "run.json");
  EXPECT_GT(jb["summary"]["cycles"].get<long>(), ja["summary"]["cycles"].get<long>()) << "longer latencies, more cycles";
  EXPECT_EQ(ja["summary"]["depth_tests"], jb["summary"]["depth_tests"]);
  EXPECT_EQ(ja["summary"]["fragments_model"], jb["summary"]["fragments_model"]);
  EXPECT_EQ(ja["summary"]["passed_model"], jb["summary"]["passed_model"]);
  EXPECT_EQ(jb["config"]["depth"]["latency_cycles"], 400) << "run.json records the config used";
  std::ifstream draws(b / "draws.csv");
  std::string header;
  std::getline(draws, header);
  EXPECT_TRUE(has(header, "frame,draw,object,role") && has(header, "model_fragments,gl_fragments")) << header;
}

// config --defaults lists every key; bad keys and values are refused with exit 2.
TEST(ReplayCliTest, ConfigKeysAndRefusals) {
  const CliResult d = run_nbsim("config --defaults --json");
  ASSERT_EQ(d.status, 0) << d.err;
  const auto keys = nlohmann::json::parse(d.out);
  ASSERT_GT(keys.size(), 10u);
  for (const auto& k : keys) {
    EXPECT_FALSE(k["description"].get<std::string>().empty()) << k["key"];
  }
  const std::string t = sample("city_small_oq.nbt");
  struct Row { std::string args, message; };
  const Row rows[] = {
      {"--set depth.latency_cycle=3", "did you mean 'depth.latency_cycles'"},
      {"--set depth.latency_cycles=-5", "outside its limits"},
      {"--config /nonexistent.json", "cannot be read"},
  };
  for (const Row& row : rows) {
    const CliResult r = run_nbsim("compare " + t + " " + row.args);
    EXPECT_EQ(r.status, 2) << row.args << ": " << r.err;
    EXPECT_TRUE(has(r.err, row.message)) << row.args << ": " << r.err;
  }
  const fs::path bad = scratch("bad.json");
  std::ofstream(bad) << R"({"depth": {"tests_per_cycle": "fast"}})";
  const CliResult r = run_nbsim("compare " + t + " --config " + bad.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "must be a number")) << r.err;
}

// A damaged trace is refused by replay with exit 2 and the chunk named.
TEST(ReplayCliTest, RefusesDamagedTrace) {
  const fs::path t = scratch("damaged.nbt");
  fs::copy_file(sample("city_small_oq.nbt"), t, fs::copy_options::overwrite_existing);
  fs::resize_file(t, fs::file_size(t) / 2);
  const CliResult r = run_nbsim("compare " + t.string());
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "chunk")) << r.err;
}

}  // namespace

// TraceRepeatCliTest: `nbsim trace repeat` from the outside: the long trace it writes is sound, is
// numbered and counted as the format requires, replays frame for frame like the frames it repeats,
// and bad input (a frame count below 1, a damaged trace, an unwritable output) is refused cleanly.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/common/run_nbsim.h"

namespace {

namespace fs = std::filesystem;
using nbsim::testing::CliResult;
using nbsim::testing::has;
using nbsim::testing::run_nbsim;

fs::path scratch(const std::string& name) { return nbsim::testing::scratch_path("nbsim_repeat", name); }

// 8 frames numbered 0 .. 7 at 128x96, occlusion culling: replays in a few hundredths of a second.
std::string sample() { return (fs::path(NBSIM_SAMPLES) / "city_small_oq.nbt").string(); }
constexpr int kSampleFrames = 8;

nlohmann::ordered_json info_json(const fs::path& trace) {
  const CliResult r = run_nbsim("trace info --json " + trace.string());
  EXPECT_EQ(r.status, 0) << r.err;
  return nlohmann::ordered_json::parse(r.out);
}

std::vector<std::vector<std::string>> read_csv(const fs::path& file) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> row;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) row.push_back(cell);
    rows.push_back(std::move(row));
  }
  return rows;
}

// --help names the options and exits 0.
TEST(TraceRepeatCliTest, HelpExitsZero) {
  const CliResult r = run_nbsim("trace repeat --help");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has(r.out, "--frames") && has(r.out, "--out")) << r.out;
}

// 20 frames of an 8-frame trace (two passes and a half): verify accepts it, and info shows the
// frame numbers pass * 8 + n, the header's new frame count and where the frames came from.
TEST(TraceRepeatCliTest, WritesSoundRenumberedTrace) {
  const fs::path out = scratch("repeat20.nbt");
  const CliResult r = run_nbsim("trace repeat " + sample() + " --frames 20 -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has(r.out, "20 frames")) << r.out;
  const CliResult v = run_nbsim("trace verify " + out.string());
  ASSERT_EQ(v.status, 0) << "the repeated trace must be sound: " << v.err;
  EXPECT_TRUE(has(v.out, "20 frames")) << v.out;

  const auto in = info_json(sample()), rep = info_json(out);
  ASSERT_EQ(rep["frames"].size(), 20u);
  for (int i = 0; i < 20; ++i) {
    const auto& f = rep["frames"][static_cast<std::size_t>(i)];
    const auto& g = in["frames"][static_cast<std::size_t>(i % kSampleFrames)];
    EXPECT_EQ(f["frame"].get<int>(), i) << "pass p numbers input frame n as p * (last + 1) + n";
    for (const char* k : {"draws", "fragments", "samples_passed", "objects_visible", "covered_pixels", "depth", "levels"})
      EXPECT_EQ(f[k], g[k]) << "frame " << i << " must repeat input frame " << i % kSampleFrames << "'s " << k;
  }
  EXPECT_EQ(rep["totals"]["frames"].get<int>(), 20);
  EXPECT_EQ(rep["properties"]["frames"].get<std::string>(), "20") << "the header's frame count is the new trace's";
  EXPECT_TRUE(has(rep["properties"]["repeated_from"].get<std::string>(), "city_small_oq.nbt (8 frames)"))
      << rep["properties"].dump();
  EXPECT_EQ(rep["properties"]["viewport"], in["properties"]["viewport"]);
  EXPECT_EQ(rep["scene"], in["scene"]) << "the scene is written once, as the input has it";
}

// The replay of the long trace gives every frame the counts of the input frame it repeats (cycles
// aside: a frame's cycles depend on the frame before it, which differs at each pass's start).
TEST(TraceRepeatCliTest, ReplaysLikeTheRepeatedFrames) {
  const fs::path out = scratch("repeat17.nbt");
  ASSERT_EQ(run_nbsim("trace repeat " + sample() + " --frames 17 --out " + out.string()).status, 0);
  const fs::path a = scratch("replay_in"), b = scratch("replay_rep");
  ASSERT_EQ(run_nbsim("replay " + sample() + " --out " + a.string()).status, 0);
  ASSERT_EQ(run_nbsim("replay " + out.string() + " --out " + b.string()).status, 0);
  const auto in = read_csv(a / "frames.csv"), rep = read_csv(b / "frames.csv");
  ASSERT_EQ(in.size(), 1u + kSampleFrames);
  ASSERT_EQ(rep.size(), 1u + 17);
  ASSERT_EQ(in[0], rep[0]);
  const std::vector<std::string>& header = in[0];
  for (std::size_t i = 1; i < rep.size(); ++i) {
    const auto& r = rep[i];
    const auto& g = in[1 + (i - 1) % kSampleFrames];
    ASSERT_EQ(r.size(), header.size());
    EXPECT_EQ(r[0], std::to_string(i - 1)) << "frame number";
    for (std::size_t c = 1; c < header.size(); ++c) {
      if (header[c] == "end_cycle" || header[c] == "cycles") continue;
      EXPECT_EQ(r[c], g[c]) << "frame " << i - 1 << "'s " << header[c] << " must be the repeated frame's";
    }
  }
}

// A frame count below 1 is refused with status 2 and no file.
TEST(TraceRepeatCliTest, RefusesFewerThanOneFrame) {
  const fs::path out = scratch("zero.nbt");
  const CliResult r = run_nbsim("trace repeat " + sample() + " --frames 0 -o " + out.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "--frames 0")) << r.err;
  EXPECT_FALSE(fs::exists(out)) << "nothing written for a refused count";
  EXPECT_NE(run_nbsim("trace repeat " + sample() + " --frames -3 -o " + out.string()).status, 0);
  EXPECT_FALSE(fs::exists(out));
}

// A damaged input is refused naming the chunk, before an output file is left behind.
TEST(TraceRepeatCliTest, RefusesDamagedInput) {
  const fs::path bad = scratch("damaged.nbt"), out = scratch("from_damaged.nbt");
  fs::copy_file(sample(), bad, fs::copy_options::overwrite_existing);
  {
    std::fstream f(bad, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(fs::file_size(bad) / 2));
    const char junk[8] = {'\x55', '\x55', '\x55', '\x55', '\x55', '\x55', '\x55', '\x55'};
    f.write(junk, sizeof junk);
  }
  const CliResult r = run_nbsim("trace repeat " + bad.string() + " --frames 30 -o " + out.string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_TRUE(has(r.err, bad.string()) && has(r.err, "chunk")) << r.err;
  EXPECT_FALSE(fs::exists(out)) << "no half-written trace";

  fs::resize_file(bad, fs::file_size(bad) - 100);  // truncated as well
  EXPECT_EQ(run_nbsim("trace repeat " + bad.string() + " --frames 3 -o " + out.string()).status, 2);
  EXPECT_FALSE(fs::exists(out));
  const CliResult missing = run_nbsim("trace repeat " + scratch("none.nbt").string() + " --frames 3 -o " + out.string());
  EXPECT_EQ(missing.status, 2);
  EXPECT_TRUE(has(missing.err, "does not exist")) << missing.err;
}

// An output that cannot be created, or that is the input itself, is refused with status 2.
TEST(TraceRepeatCliTest, RefusesUnwritableOutput) {
  const fs::path out = scratch("no_such_folder") / "x.nbt";
  const CliResult r = run_nbsim("trace repeat " + sample() + " --frames 3 -o " + out.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "cannot create trace") && has(r.err, out.string())) << r.err;

  const fs::path copy = scratch("self.nbt");
  fs::copy_file(sample(), copy, fs::copy_options::overwrite_existing);
  const CliResult self = run_nbsim("trace repeat " + copy.string() + " --frames 3 -o " + copy.string());
  EXPECT_EQ(self.status, 2);
  EXPECT_TRUE(has(self.err, "is the input trace")) << self.err;
  EXPECT_EQ(run_nbsim("trace verify " + copy.string()).status, 0) << "the input must be left as it was";
}

}  // namespace

// The interposer inside apitrace's eglretrace, on the committed glmark2 traces: eglretrace's own
// image checksums are the same with the library recording as without it, and what it records
// replays in the model with every compared draw's samples passed equal to GL's.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "tests/common/run_nbsim.h"

namespace {

using nbsim::testing::run_nbsim;
using nbsim::testing::shell_output;

const std::filesystem::path kSamples = NBSIM_APITRACE_SAMPLES;

bool have_eglretrace() { return std::system("command -v eglretrace > /dev/null 2>&1") == 0; }

TEST(InterposerTest, ReplayImagesUnchangedByTheRecording) {
  if (!have_eglretrace()) GTEST_SKIP() << "eglretrace not installed (apt install apitrace)";
  const std::string trace = (kSamples / "glmark2_shadow_160x120.trace").string();
  const auto dir = nbsim::testing::scratch_dir("nbsim_interposer");
  const std::string replay = "WAFFLE_PLATFORM=surfaceless_egl eglretrace --headless --snapshot-format=MD5 -s - " + trace + " 2>/dev/null";
  const std::string plain = shell_output(replay);
  const std::string recorded =
      shell_output("NBSIM_IP_OUT=" + (dir / "r.raw").string() + " LD_PRELOAD=" + std::string(NBSIM_INTERPOSER) + " " + replay);
  EXPECT_GT(std::count(plain.begin(), plain.end(), '\n'), 50) << "one checksum a frame";
  EXPECT_EQ(plain, recorded);
  EXPECT_GT(std::filesystem::file_size(dir / "r.raw"), 1000u) << "the library recorded";
}

TEST(InterposerTest, GlmarkScenesReplayDrawByDraw) {
  if (!have_eglretrace()) GTEST_SKIP() << "eglretrace not installed (apt install apitrace)";
  struct Sample {
    const char* file;
    bool flagged;  // some draws are flagged (a depth format the model does not store, lines, discard)
  };
  for (const Sample& s : {Sample{"glmark2_shadow_160x120.trace", true}, Sample{"glmark2_ideas_160x120.trace", true},
                          Sample{"glmark2_desktop_160x120.trace", false}}) {
    SCOPED_TRACE(s.file);
    const auto dir = nbsim::testing::scratch_dir("nbsim_interposer");
    const std::string out = (dir / "app.nbt").string();
    const auto c = run_nbsim("capture apitrace " + (kSamples / s.file).string() + " --frames 2:21 -o " + out);
    ASSERT_EQ(c.status, 0) << c.out << c.err;
    EXPECT_NE(c.out.find("recorded 20 frames"), std::string::npos) << c.out;
    const auto r = run_nbsim("replay " + out + " --out " + (dir / "run").string());
    ASSERT_EQ(r.status, 0) << r.err;
    const auto run = nlohmann::json::parse(std::ifstream(dir / "run" / "run.json"));
    const auto& a = run["summary"]["apps"];
    EXPECT_EQ(a["frames"], 20);
    EXPECT_GT(a["compared"].get<int>(), 0);
    EXPECT_EQ(a["mismatched"], 0) << "every compared draw passes GL's samples";
    EXPECT_EQ(a["depth_mismatches"], 0);
    EXPECT_EQ(a["flagged"].get<int>() > 0, s.flagged) << a.dump();
    EXPECT_EQ(a["compared"].get<int>() + a["after_stale"].get<int>() + a["flagged"].get<int>(), a["draws"].get<int>());
  }
}

}  // namespace

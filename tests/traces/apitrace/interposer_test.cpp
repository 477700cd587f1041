// The interposer inside apitrace's eglretrace, on the committed glmark2 traces: eglretrace's own
// image checksums are the same with the library recording as without it, and what it records
// replays in the model with every compared draw's samples passed equal to GL's.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "model/scene/frame.h"
#include "tests/common/run_nbsim.h"
#include "tests/common/tools.h"
#include "traces/format/reader.h"

namespace {

using nbsim::testing::have_apitrace;
using nbsim::testing::have_eglretrace;
using nbsim::testing::run_nbsim;
using nbsim::testing::shell_output;

const std::filesystem::path kSamples = NBSIM_APITRACE_SAMPLES;

std::vector<nbsim::scene::Frame> frames_of(const std::filesystem::path& trace) {
  nbsim::trace::FrameReader r(trace);
  std::vector<nbsim::scene::Frame> out;
  while (auto f = r.next()) out.push_back(std::move(*f));
  return out;
}

bool same_floats(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

// The self-check that needs no program: the project's own capture, recorded by apitrace while it
// draws its frames as a program would (`--as-program`: no feedback, queries or ground truth, a
// frame marker at each frame's end), then captured through the interposer, gives the native
// capture's draws: the same clip positions bit for bit, depth state, GL samples passed and final
// depth, frame by frame; and both replay alike in the model.
TEST(InterposerTest, NativeCaptureRecordedThroughApitraceIsTheSame) {
  if (!have_eglretrace() || !have_apitrace()) GTEST_SKIP() << "apitrace not installed (apt install apitrace)";
#if defined(__SANITIZE_ADDRESS__)
  // apitrace preloads its tracer into the program it records, and an AddressSanitizer binary refuses
  // a library loaded before its runtime: the check runs in the plain build.
  GTEST_SKIP() << "apitrace cannot record an AddressSanitizer build of nbsim (its tracer is preloaded before the runtime)";
#endif
  const auto dir = nbsim::testing::scratch_dir("nbsim_interposer_self");
  const std::string scene = " --scene boxes --path fly --size 96x64 --frames 4 --seed 5";
  const auto native = run_nbsim("capture apps" + scene + " -o " + (dir / "native.nbt").string());
  ASSERT_EQ(native.status, 0) << native.err;
  const std::string record = "cd " + dir.string() + " && apitrace trace --api egl -o program.trace " + std::string(NBSIM_EXE) +
                             " capture apps" + scene + " --as-program yes -o plain.nbt > apitrace.log 2>&1";
  ASSERT_EQ(std::system(record.c_str()), 0) << shell_output("cat " + (dir / "apitrace.log").string());
  const auto interposed = run_nbsim("capture apitrace " + (dir / "program.trace").string() + " -o " + (dir / "interposed.nbt").string());
  ASSERT_EQ(interposed.status, 0) << interposed.out << interposed.err;

  const auto a = frames_of(dir / "native.nbt"), b = frames_of(dir / "interposed.nbt");
  ASSERT_EQ(a.size(), 4u);
  ASSERT_EQ(b.size(), a.size());
  std::size_t draws = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    ASSERT_EQ(b[i].draws.size(), a[i].draws.size());
    for (std::size_t k = 0; k < a[i].draws.size(); ++k, ++draws) {
      const auto &x = a[i].draws[k], &y = b[i].draws[k];
      EXPECT_EQ(x.clip_positions.size(), y.clip_positions.size()) << "draw " << k;
      EXPECT_TRUE(x.clip_positions.size() == y.clip_positions.size() &&
                  std::memcmp(x.clip_positions.data(), y.clip_positions.data(), x.clip_positions.size() * sizeof(x.clip_positions[0])) == 0)
          << "draw " << k << ": clip positions differ";
      EXPECT_EQ(x.gl.samples_passed, y.gl.samples_passed) << "draw " << k;
      EXPECT_EQ(x.state.func, y.state.func) << "draw " << k;
      EXPECT_EQ(x.state.write, y.state.write) << "draw " << k;
      EXPECT_EQ(x.state.cull, y.state.cull) << "draw " << k;
    }
    const auto *da = a[i].depth("final"), *db = b[i].depth("final");
    ASSERT_TRUE(da && db);
    EXPECT_TRUE(same_floats(da->texels, db->texels)) << "final depth differs";
  }
  EXPECT_GT(draws, 20u);
  for (const char* t : {"native", "interposed"}) {
    const auto r = run_nbsim("compare " + (dir / (std::string(t) + ".nbt")).string() + " --json");
    ASSERT_EQ(r.status, 0) << t << ": " << r.err;
    const auto s = nlohmann::json::parse(r.out)["apps"];
    EXPECT_EQ(s["compared"].get<std::size_t>(), draws) << t;
    EXPECT_EQ(s["mismatched"], 0) << t;
    EXPECT_EQ(s["depth_mismatches"], 0) << t;
  }
}

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

// A fixed-function program (neverball: no GLSL program, VBOs and client arrays, user clip planes for
// its reflections) is captured by the interposer's pass of its own before each draw (the same draw
// with gl_Position = ftransform() under transform feedback, rasterization discarded): every draw is
// captured, and every draw the model replays passes GL's samples exactly; clip planes are flagged.
TEST(InterposerTest, FixedFunctionDrawsCapturedByTheirFtransformPass) {
  if (!have_eglretrace()) GTEST_SKIP() << "eglretrace not installed (apt install apitrace)";
  const auto dir = nbsim::testing::scratch_dir("nbsim_interposer_ff");
  const std::string out = (dir / "neverball.nbt").string();
  const auto c = run_nbsim("capture apitrace " + (kSamples / "neverball_800x600.trace").string() + " --frames 10:12 -o " + out);
  ASSERT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_NE(c.out.find("not: fixed function 0,"), std::string::npos) << c.out;
  const auto r = run_nbsim("compare " + out + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto s = nlohmann::json::parse(r.out)["apps"];
  EXPECT_EQ(s["flagged_by_reason"].value("not_captured", 0), 0);
  EXPECT_GT(s["compared"].get<int>(), 500);
  EXPECT_EQ(s["mismatched"], 0);
  EXPECT_GT(s["flagged_by_reason"].value("clip_distance", 0), 0) << "the reflections' clip planes";
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

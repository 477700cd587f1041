// `nbsim capture apitrace`: each bad input (a missing or damaged apitrace trace, a frame range
// the trace does not have or cannot be read, a missing replayer or interposer) is refused with exit
// status 2 and a message naming it, and leaves no trace and no recording behind.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/common/run_nbsim.h"
#include "tests/common/tools.h"

namespace {

using nbsim::testing::have_eglretrace;
using nbsim::testing::run_nbsim;

const std::filesystem::path kSamples = NBSIM_APITRACE_SAMPLES;

TEST(ApitraceCliTest, BadInputIsRefusedWithNothingLeftBehind) {
  const auto dir = nbsim::testing::scratch_dir("nbsim_apitrace_cli");
  const std::string out = (dir / "out.nbt").string();
  const std::string sample = (kSamples / "glmark2_shadow_160x120.trace").string();
  struct Case {
    std::string args, message;
    bool needs_eglretrace;
  };
  // A damaged trace: the sample cut in half.
  const std::filesystem::path cut = dir / "cut.trace";
  {
    std::ifstream in(sample, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  }
  const std::filesystem::path junk = dir / "junk.trace";
  std::ofstream(junk) << "not an apitrace trace";
  const std::vector<Case> cases = {
      {"capture apitrace " + (dir / "missing.trace").string() + " -o " + out, "missing.trace", false},
      {"capture apitrace " + sample + " --frames 5 -o " + out, "--frames '5': expected FIRST:LAST", false},
      {"capture apitrace " + sample + " --frames 9:3 -o " + out, "--frames '9:3'", false},
      {"capture apitrace " + sample + " --eglretrace /nonexistent/eglretrace -o " + out, "not found", false},
      {"capture apitrace " + sample + " --interposer /nonexistent/lib.so -o " + out, "interposer library '/nonexistent/lib.so' is not there", false},
      {"capture apitrace " + junk.string() + " -o " + out, "eglretrace could not replay", true},
      {"capture apitrace " + sample + " --frames 5000:5001 -o " + out, "holds no frame", true},
      // Cut traces replay up to the cut (apitrace reads what is there): the frames past it are refused.
      {"capture apitrace " + cut.string() + " --frames 900:901 -o " + out, "holds no frame", true},
      // A fixed-function program (glxgears): immediate mode in display lists, named.
      {"capture apitrace " + (kSamples / "glxgears_160x120.trace").string() + " -o " + out,
       "GL features the interposer does not handle: glBegin (immediate mode) (18 times), glCallList (display lists) (18 times)", true},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    if (c.needs_eglretrace && !have_eglretrace()) continue;
    const auto r = run_nbsim(c.args);
    EXPECT_EQ(r.status, 2) << r.out << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out));
    EXPECT_FALSE(std::filesystem::exists(out + ".partial"));
    EXPECT_FALSE(std::filesystem::exists(out + ".recording"));
  }
}

// --allow-unhandled keeps the trace of such a program, its frames marked, and the model counts them.
TEST(ApitraceCliTest, UnhandledFeaturesAreKeptWhenAllowed) {
  if (!have_eglretrace()) GTEST_SKIP() << "eglretrace not installed (apt install apitrace)";
  const auto dir = nbsim::testing::scratch_dir("nbsim_apitrace_unhandled");
  const std::string out = (dir / "gears.nbt").string();
  const auto c = run_nbsim("capture apitrace " + (kSamples / "glxgears_160x120.trace").string() + " --allow-unhandled -o " + out);
  ASSERT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_NE(c.out.find("not captured: glBegin (immediate mode)"), std::string::npos) << c.out;
  const auto r = run_nbsim("compare " + out + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("\"unhandled_frames\":6"), std::string::npos) << r.out.substr(0, 2000);
}

TEST(ApitraceCliTest, HelpNamesWhatItNeeds) {
  const auto r = run_nbsim("capture apitrace --help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("eglretrace"), std::string::npos);
  EXPECT_NE(r.out.find("--frames"), std::string::npos);
  EXPECT_NE(r.out.find("OpenGL ES"), std::string::npos);
}

}  // namespace

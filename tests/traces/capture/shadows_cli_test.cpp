// ShadowsCliTest: `nbsim capture shadows` from the outside: bad modes, litmap sizes and lights (a
// degenerate light frustum; a light inside a caster is shadows_test's) exit 2 naming the problem before any file is
// written; a capture prints its counts, and `trace verify`, `info --json` and `dump --records` read
// its SHDC record, light and stencil images back.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/common/run_nbsim.h"

namespace nbsim {
namespace {

namespace fs = std::filesystem;
using testing::CliResult;
using testing::has;
using testing::run_nbsim;

// Bad arguments exit 2 with a message naming them, and write nothing.
TEST(ShadowsCliTest, BadArgumentsExitTwo) {
  const fs::path out = testing::scratch_path("nbsim_shadows_cli_bad", "never.nbt");
  struct Case {
    const char* args;
    const char* message;
  };
  for (const Case& c : {Case{"--shadow-mode zpass", "--shadow-mode 'zpass' is not one of infinite, culled, clamped"},
                        Case{"--litmap 8", "--litmap 8 is out of range (16 to 4096)"},
                        Case{"--litmap 8192", "--litmap 8192 is out of range (16 to 4096)"},
                        Case{"--light-fov 180", "--light-fov 180 is out of range (1 to 179)"},
                        Case{"--light 1,2,3", "does not have six numbers"},
                        Case{"--light 1,2,x,4,5,6", "'x' is not a number"},
                        Case{"--light 10,50,10,10,50,10", "the light camera's frustum is degenerate"},
                        Case{"--light 60,400,60,60,400,60.0000000001", "the light camera's frustum is degenerate"},
                        Case{"--reversed-z", "drop --reversed-z"}}) {
    const CliResult r = run_nbsim(std::string("capture shadows --scene boxes --path fly --size 32x24 --frames 1 ") + c.args + " -o " +
                                  out.string());
    EXPECT_EQ(r.status, 2) << c.args << ": " << r.err;
    EXPECT_TRUE(has(r.err, c.message)) << c.args << ": " << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.args << " wrote a file";
  }
  fs::remove_all(out.parent_path());
}

// A capture prints its shadow counts; the trace verifies, `info --json` lists the SHDC record and
// the depth format carries stencil, `dump --records` decodes SHDC and the volume draws.
TEST(ShadowsCliTest, CaptureRoundTripsThroughTheReader) {
  const fs::path out = testing::scratch_path("nbsim_shadows_cli", "s.nbt");
  const CliResult c = run_nbsim("capture shadows --scene boxes --path fly --size 64x48 --frames 2 --litmap 64 -o " + out.string());
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_TRUE(has(c.out, "fill ")) << c.out;
  EXPECT_TRUE(has(c.out, "mask_diff_pixels 0")) << c.out;
  const CliResult verify = run_nbsim("trace verify " + out.string());
  EXPECT_EQ(verify.status, 0) << verify.out << verify.err;
  const CliResult info = run_nbsim("trace info " + out.string() + " --json");
  ASSERT_EQ(info.status, 0) << info.err;
  EXPECT_TRUE(has(info.out, "\"SHDC\"")) << info.out;
  EXPECT_TRUE(has(info.out, "DEPTH24_STENCIL8")) << info.out;
  const CliResult dump = run_nbsim("trace dump " + out.string() + " --frame 1 --records");
  ASSERT_EQ(dump.status, 0) << dump.err;
  EXPECT_TRUE(has(dump.out, "SHDC ShadowCasters")) << dump.out;
  EXPECT_TRUE(has(dump.out, "(shadow_volume)")) << dump.out;
  fs::remove_all(out.parent_path());
}

}  // namespace
}  // namespace nbsim

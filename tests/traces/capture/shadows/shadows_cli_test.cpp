// ShadowsCliTest: `nbsim capture shadows` from the outside: bad modes, litmap sizes and lights (a
// degenerate light frustum, a light inside a caster, litmaps above the trace format's per-frame
// limit) exit 2 naming the problem before any file is written; a capture prints its counts, and `trace verify`, `info --json` and `dump --records` read
// its SHDC record, light and stencil images back.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/common/refused.h"
#include "tests/common/run_nbsim.h"
#include "traces/capture/scenes.h"

namespace nbsim {
namespace {

namespace fs = std::filesystem;
using testing::CliResult;
using testing::has;
using testing::run_nbsim;

// Bad arguments exit 2 with a message naming them, and write nothing.
TEST(ShadowsCliTest, BadArgumentsExitTwo) {
  const fs::path out = testing::scratch_path("nbsim_shadows_cli_bad", "never.nbt");
  testing::expect_refused("capture shadows --scene boxes --path fly --size 32x24 --frames 1 ",
                          {{"--shadow-mode zpass", "--shadow-mode 'zpass' is not one of infinite, culled, clamped"},
                           {"--litmap 8", "--litmap 8 is out of range (16 to 4096)"},
                           {"--litmap 8192", "--litmap 8192 is out of range (16 to 4096)"},
                           {"--light-fov 180", "--light-fov 180 is out of range (1 to 179)"},
                           {"--light 1,2,3", "does not have six numbers"},
                           {"--light 1,2,x,4,5,6", "'x' is not a number"},
                           {"--light 10,50,10,10,50,10", "the light camera's frustum is degenerate"},
                           {"--light 60,400,60,60,400,60.0000000001", "the light camera's frustum is degenerate"},
                           {"--reversed-z", "drop --reversed-z"},
                           {"--litmap 1000", "above the trace format's per-frame limit"},
                           {"--litmap 4096 --levels-every 0", "--litmap 4096: the two 4096x4096 litmaps come to"}},
                          " -o " + out.string(), out);
  fs::remove_all(out.parent_path());
}

// The review's case: --litmap 1000 at 160x120 (its litmaps and N-buffer levels come to about 88 MB
// a frame, the format allows 64 MiB + 128 bytes a pixel) exits 2 naming the limit, before writing
// anything; a light inside a caster exits 2 through the command line too.
TEST(ShadowsCliTest, FrameBudgetAndLightInsideACasterExitTwo) {
  const fs::path out = testing::scratch_path("nbsim_shadows_cli_budget", "never.nbt");
  const CliResult big = run_nbsim("capture shadows --scene boxes --path fly --size 160x120 --frames 2 --litmap 1000 -o " + out.string());
  EXPECT_EQ(big.status, 2) << big.out << big.err;
  EXPECT_TRUE(has(big.err, "--litmap 1000: the two 1000x1000 litmaps and both N-buffers'")) << big.err;
  EXPECT_TRUE(has(big.err, "above the trace format's per-frame limit of 69566464 bytes (64 MiB + 128 bytes a pixel of the 160x120 viewport)"))
      << big.err;
  EXPECT_FALSE(fs::exists(out)) << "nothing written";
  EXPECT_FALSE(fs::exists(out.string() + ".partial"));
  const capture::CaptureScene scene = capture::find_scene("boxes").make(capture::OptionValues{{"boxes", "3"}, {"seed", "7"}});
  const scene::Aabb& b = scene.scene.objects[2];
  const std::string light = std::to_string(0.5f * (b.lo[0] + b.hi[0])) + "," + std::to_string(0.5f * (b.lo[1] + b.hi[1])) + "," +
                            std::to_string(0.5f * (b.lo[2] + b.hi[2])) + ",0,0,0";
  const CliResult inside = run_nbsim("capture shadows --scene boxes --boxes 3 --seed 7 --path fly --size 32x24 --frames 1 --light " + light +
                                     " -o " + out.string());
  EXPECT_EQ(inside.status, 2) << inside.out << inside.err;
  EXPECT_TRUE(has(inside.err, "is inside caster object 2")) << inside.err;
  EXPECT_FALSE(fs::exists(out));
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

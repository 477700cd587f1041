// BenchReplayCliTest: `nbsim bench replay` from the outside, for particles, shadows and ldi: one JSON
// object with llvmpipe's time, the model's replay time and their ratio, measured in the same run
// (the ratio is printed and recorded, never asserted: it depends on the machine), and bad
// arguments refused with exit 2.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "tests/common/refused.h"
#include "tests/common/run_nbsim.h"

namespace nbsim {
namespace {

using testing::CliResult;
using testing::has;
using testing::run_nbsim;

// A small particles capture replayed in the same run, three pairs (the default): the ratio is
// the median pair's, every pair's is listed, and the replay is exact.
TEST(BenchReplayCliTest, ParticlesRatioPrinted) {
  const CliResult r = run_nbsim("bench replay --technique particles --size 128x96 --frames 2 --particles 2000 --sprite 24");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("bench"), "replay");
  EXPECT_EQ(j.at("technique"), "particles");
  EXPECT_EQ(j.at("mode"), "nb") << "the particles default mode";
  EXPECT_EQ(j.at("frames"), 2);
  EXPECT_EQ(j.at("options").at("particles"), "2000") << "a capture option over the preset";
  EXPECT_EQ(j.at("options").at("sprite"), "24");
  EXPECT_EQ(j.at("options").at("levels-every"), "0") << "the preset's";
  EXPECT_EQ(j.at("scene"), "city");
  EXPECT_EQ(j.at("path"), "walk");
  EXPECT_GT(j.at("gl_ms").get<double>(), 0.0) << "llvmpipe's technique passes are timed";
  EXPECT_GT(j.at("replay_ms").get<double>(), 0.0);
  EXPECT_GT(j.at("ratio").get<double>(), 0.0);
  EXPECT_EQ(j.at("repetitions"), 3);
  std::vector<double> ratios = j.at("ratios").get<std::vector<double>>();
  ASSERT_EQ(ratios.size(), 3u);
  std::sort(ratios.begin(), ratios.end());
  EXPECT_EQ(j.at("ratio").get<double>(), ratios[1]) << "the median pair's ratio";
  EXPECT_DOUBLE_EQ(j.at("ratio").get<double>(), j.at("replay_ms").get<double>() / j.at("gl_ms").get<double>())
      << "gl_ms and replay_ms are the median pair's";
  EXPECT_EQ(j.at("draws_exact"), j.at("draws")) << "every draw's fragments and passed samples equal GL's";
  EXPECT_TRUE(j.at("within_thresholds").get<bool>());
  ASSERT_TRUE(j.at("particles_summary").is_object()) << r.out;
  const std::string ratio = std::to_string(j.at("ratio").get<double>());
  ::testing::Test::RecordProperty("particles_replay_ratio", ratio);
  std::printf("bench replay particles 128x96, 2 frames, 2000 particles: ratio %s (gl %.1f ms, replay %.1f ms)\n", ratio.c_str(),
              j.at("gl_ms").get<double>(), j.at("replay_ms").get<double>());
}

// A small shadows capture (boxes, flown over) replayed in the same run: the volume draws with their
// stencil state are exact and the stencil buffer equals GL's (within_thresholds covers it).
TEST(BenchReplayCliTest, ShadowsRatioPrinted) {
  const CliResult r = run_nbsim("bench replay --technique shadows --scene boxes --size 128x96 --frames 2 --repetitions 1");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("technique"), "shadows");
  EXPECT_EQ(j.at("mode"), "clamped") << "the shadows default mode";
  EXPECT_EQ(j.at("scene"), "boxes");
  EXPECT_GT(j.at("gl_ms").get<double>(), 0.0);
  EXPECT_GT(j.at("ratio").get<double>(), 0.0);
  EXPECT_EQ(j.at("ratios").size(), 1u);
  EXPECT_GT(j.at("draws").get<int>(), 0);
  EXPECT_EQ(j.at("draws_exact"), j.at("draws"));
  EXPECT_TRUE(j.at("within_thresholds").get<bool>());
  ASSERT_TRUE(j.at("shadows_summary").is_object()) << r.out;
  EXPECT_FALSE(j.at("shadows_summary").contains("per_frame"));
}

// Bad arguments exit 2 with a message naming them.
TEST(BenchReplayCliTest, BadArgumentsExitTwo) {
  testing::expect_refused("bench replay --size 32x24 --frames 1 ",
                          {{"--technique raytracing", "unknown technique 'raytracing'"},
                           {"--technique shadows --mode nb", "--shadow-mode 'nb' is not one of infinite, culled, clamped"},
                           {"--technique particles --scene boxes", "camera path 'walk' needs a scene with streets"},
                           {"--technique shadows --scene forest", "forest"},
                           {"--technique particles --mode oq", "--mode 'oq' is not one of none, center, nb, hiz"},
                           {"--mode hiz", "--mode 'hiz' is not one of oq, oq_hier"},
                           {"--particles 500", "option --particles is not an option of city, walk, occlusion_culling"},
                           {"--technique particles --particles 0", "--particles 0 is out of range"},
                           {"--technique particles --sprite 32", "--sprite '32' is not one of 16, 24, atten"},
                           {"--shape knot", "option --shape is not an option of city, walk, occlusion_culling"},
                           {"--technique ldi --shape teapot", "teapot"},
                           {"--technique occlusion_culling --size 8", "--size"},
                           {"--technique ldi --ldi-size 0", "--ldi-size"},
                           {"--repetitions 0", "--repetitions"}});
}

// The LDI bench is the clipping application (three knots, LDIs of 64x64, in the city's walk at the
// preset's 512x512) replayed in the same run: every clipping draw's counters, discards and final
// depth buffer equal GL's (within_thresholds covers them).
TEST(BenchReplayCliTest, LdiRatioPrinted) {
  const CliResult r = run_nbsim("bench replay --technique ldi --frames 2 --ldi-size 64 --repetitions 1");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("technique"), "ldi");
  EXPECT_EQ(j.at("mode"), "all") << "the ldi bench's default reader, the paper's";
  EXPECT_EQ(j.at("options").at("ldi-size"), "64");
  EXPECT_TRUE(j.at("within_thresholds").get<bool>());
  const nlohmann::json& s = j.at("ldi_summary");
  EXPECT_EQ(s.at("clip_frames"), 2);
  EXPECT_EQ(s.at("clip_fragments"), s.at("gl_clip_fragments"));
  EXPECT_EQ(s.at("clip_samples"), s.at("gl_clip_samples"));
  EXPECT_EQ(s.at("clip_discarded"), s.at("gl_clip_discarded"));
  EXPECT_EQ(s.at("clip_draw_mismatches"), 0);
  EXPECT_EQ(s.at("clip_depth_mismatches"), 0);
  const std::string ratio = std::to_string(j.at("ratio").get<double>());
  ::testing::Test::RecordProperty("ldi_replay_ratio", ratio);
  std::printf("bench replay ldi clipping (knots, LDIs 64x64), 2 frames: ratio %s (gl %.1f ms, replay %.1f ms)\n", ratio.c_str(),
              j.at("gl_ms").get<double>(), j.at("replay_ms").get<double>());
}

}  // namespace
}  // namespace nbsim

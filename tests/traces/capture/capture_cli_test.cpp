// CaptureCliTest: `nbsim capture` from the outside. The new spelling (TECHNIQUE --scene --path) and
// the old one (`capture city`) record identical traces; --help lists the techniques, scenes and
// paths from their tables; bad names and option values exit 2 with a message naming them; a level
// file's scene replays draw by draw.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cstring>
#include <filesystem>
#include <string>

#include "tests/common/bsp_writer.h"
#include "tests/common/refused.h"
#include "tests/common/run_nbsim.h"
#include "traces/format/reader.h"

namespace nbsim {
namespace {

namespace fs = std::filesystem;
using testing::CliResult;
using testing::has;
using testing::run_nbsim;

// Every record of two traces is equal (header properties but the command line, scene, each frame's
// draws with GL's counters and clip positions, depth images, levels and ground truth); GL's host
// time may differ.
void expect_same_trace(const fs::path& a, const fs::path& b) {
  trace::FrameReader ra(a), rb(b);
  auto props = [](const trace::TraceReader& r) {
    trace::Properties p;
    for (const auto& kv : r.properties())
      if (kv.first != "command_line") p.push_back(kv);
    return p;
  };
  EXPECT_EQ(props(ra.trace()), props(rb.trace())) << "header properties";
  ASSERT_NE(ra.trace().scene(), nullptr);
  ASSERT_NE(rb.trace().scene(), nullptr);
  EXPECT_EQ(ra.trace().scene()->objects.size(), rb.trace().scene()->objects.size());
  int frames = 0;
  while (true) {
    auto fa = ra.next();
    auto fb = rb.next();
    ASSERT_EQ(fa.has_value(), fb.has_value()) << "frame count";
    if (!fa) break;
    ++frames;
    ASSERT_EQ(fa->draws.size(), fb->draws.size()) << "frame " << frames;
    for (std::size_t i = 0; i < fa->draws.size(); ++i) {
      const auto& x = fa->draws[i];
      const auto& y = fb->draws[i];
      EXPECT_EQ(x.role, y.role);
      EXPECT_EQ(x.object, y.object);
      EXPECT_EQ(x.node, y.node);
      EXPECT_EQ(x.gl.fragments, y.gl.fragments) << "draw " << i;
      EXPECT_EQ(x.gl.samples_passed, y.gl.samples_passed) << "draw " << i;
      EXPECT_EQ(x.gl.clip_prims_in, y.gl.clip_prims_in) << "draw " << i;
      EXPECT_EQ(x.gl.clip_prims_out, y.gl.clip_prims_out) << "draw " << i;
      EXPECT_EQ(x.clip_positions, y.clip_positions) << "draw " << i;
      EXPECT_EQ(x.bounds.visible, y.bounds.visible) << "draw " << i;
    }
    ASSERT_EQ(fa->depths.size(), fb->depths.size());
    for (std::size_t i = 0; i < fa->depths.size(); ++i) EXPECT_EQ(fa->depths[i].texels, fb->depths[i].texels);
    ASSERT_EQ(fa->levels.size(), fb->levels.size());
    for (std::size_t i = 0; i < fa->levels.size(); ++i) EXPECT_EQ(fa->levels[i].texels, fb->levels[i].texels);
    ASSERT_TRUE(fa->truth && fb->truth);
    EXPECT_EQ(fa->truth->visible_pixels, fb->truth->visible_pixels);
    EXPECT_EQ(fa->truth->ids, fb->truth->ids);
  }
  EXPECT_EQ(frames, 3);
}

// `capture city --mode M` and `capture occlusion_culling --scene city --mode M` record the same
// trace, and the same command line (the new spelling, every option spelled out).
TEST(CaptureCliTest, OldAndNewSpellingsGiveIdenticalTraces) {
  const fs::path old_file = testing::scratch_path("nbsim_capture_cli", "old.nbt");
  const fs::path new_file = testing::scratch_path("nbsim_capture_cli", "new.nbt");
  const std::string common = " --size 64x48 --frames 3 --path fly --seed 2 --objects 300 --mode nb_hier --levels-every 1";
  const CliResult o = run_nbsim("capture city" + common + " -o " + old_file.string());
  ASSERT_EQ(o.status, 0) << o.err;
  const CliResult n = run_nbsim("capture occlusion_culling --scene city" + common + " -o " + new_file.string());
  ASSERT_EQ(n.status, 0) << n.err;
  expect_same_trace(old_file, new_file);
  const trace::TraceReader r(old_file);
  ASSERT_NE(r.property("command_line"), nullptr);
  EXPECT_EQ(*r.property("command_line"),
            "nbsim capture occlusion_culling --scene city --path fly --size 64x48 --frames 3 --seed 2 --objects 300 "
            "--mode nb_hier --levels-every 1 --covering paper --align top -o " + old_file.string());
  EXPECT_EQ(*r.property("technique"), "occlusion_culling");
  fs::remove_all(old_file.parent_path());
}

// --help lists every technique, scene and camera path with its description, and the old spelling.
TEST(CaptureCliTest, HelpListsTheTables) {
  const CliResult r = run_nbsim("capture --help");
  EXPECT_EQ(r.status, 0) << r.err;
  for (const char* part : {"occlusion_culling", "Occlusion culling with occlusion queries", "city", "Procedural city", "walk",
                           "Street-level walkthrough", "fly", "Flyover", "old spelling"})
    EXPECT_TRUE(has(r.out, part)) << "capture --help lacks '" << part << "':\n" << r.out;
  const CliResult t = run_nbsim("capture occlusion_culling --help");
  EXPECT_EQ(t.status, 0) << t.err;
  for (const char* part : {"--scene", "--path", "--mode", "--levels-every", "--seed", "--objects", "Procedural city"})
    EXPECT_TRUE(has(t.out, part)) << "capture occlusion_culling --help lacks '" << part << "':\n" << t.out;
  const CliResult c = run_nbsim("capture city --help");
  EXPECT_EQ(c.status, 0) << c.err;
  EXPECT_TRUE(has(c.out, "--mode")) << c.out;
}

// Unknown techniques, scenes, paths and bad option values exit 2, naming the problem and the
// known names, before any file is written.
TEST(CaptureCliTest, BadInputExitsTwo) {
  const fs::path out = testing::scratch_path("nbsim_capture_cli_bad", "never.nbt");
  testing::expect_refused("",
                          {{"capture raytracing --frames 1", "occlusion_culling"},
                           {"capture occlusion_culling --scene forest --frames 1", "known scenes are city"},
                           {"capture occlusion_culling --path orbit --frames 1", "known camera paths are walk, fly"},
                           {"capture occlusion_culling --mode zbuffer --frames 1", "oq, oq_hier, nb, nb_hier, none"},
                           {"capture city --objects 1 --frames 1", "--objects 1 is out of range"},
                           {"capture occlusion_culling --levels-every often --frames 1", "--levels-every 'often' is not an integer"},
                           {"capture occlusion_culling --size 0x5 --frames 1", "--size"}},
                          " -o " + out.string(), out);
  fs::remove_all(out.parent_path());
}

// A level file's scene (the room of tests/common/bsp_writer.h) walked along `tour` replays with
// every draw, fragment, passed sample and depth pixel equal to GL's, as the city does; a level
// path refuses the walk and a missing or damaged level file by name.
TEST(CaptureCliTest, LevelTourReplaysDrawByDraw) {
  const fs::path room = testing::scratch_path("nbsim_capture_cli_level", "room.bsp");
  const fs::path out = testing::scratch_path("nbsim_capture_cli_level", "room.nbt");
  testing::write_bsp(testing::room_map(), room);
  const CliResult c = run_nbsim("capture occlusion_culling --scene q3bsp --bsp " + room.string() +
                                " --path tour --size 96x64 --frames 12 -o " + out.string());
  ASSERT_EQ(c.status, 0) << c.err;
  const CliResult r = run_nbsim("compare " + out.string() + " --json");
  ASSERT_EQ(r.status, 0) << r.err << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_GT(j.at("draws").get<int>(), 12);
  EXPECT_EQ(j.at("draws_exact"), j.at("draws")) << r.out;
  EXPECT_EQ(j.at("depth_pixels_matching"), j.at("depth_pixels")) << r.out;
  EXPECT_TRUE(j.at("within_thresholds").get<bool>()) << r.out;
  fs::path damaged = room;
  damaged.replace_filename("short.bsp");
  fs::copy_file(room, damaged, fs::copy_options::overwrite_existing);
  fs::resize_file(damaged, 200);
  const fs::path never = out.parent_path() / "never.nbt";
  const std::string room_arg = " --bsp " + room.string(), damaged_arg = " --bsp " + damaged.string();
  testing::expect_refused("capture occlusion_culling --scene q3bsp",
                          {{" --path tour", "scene q3bsp needs --bsp"},
                           {" --bsp /nonexistent.bsp --path tour", "'/nonexistent.bsp' cannot be read"}},
                          " --frames 1 -o " + never.string(), never);
  testing::expect_refused("capture occlusion_culling --scene q3bsp", {{" --path walk", "use --path tour or fly"}},
                          room_arg + " --frames 1 -o " + never.string(), never);
  testing::expect_refused("capture occlusion_culling --scene q3bsp", {{" --path tour", "outside the file"}},
                          damaged_arg + " --frames 1 -o " + never.string(), never);
  testing::expect_refused("", {{"capture occlusion_culling --scene city --path tour", "needs a scene with waypoints"}},
                          " --frames 1 -o " + never.string(), never);
  fs::remove_all(out.parent_path());
}

}  // namespace
}  // namespace nbsim

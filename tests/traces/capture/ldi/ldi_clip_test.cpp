// LdiClipTest: the LDI applications in a scene (`nbsim capture ldi --application clip|lens`) from the
// outside: a capture along a camera path replays with every draw's counters, every discarded
// fragment (count and sums), every reader's fetches and the final depth buffer equal to GL's, for
// volumes placed automatically and volumes given by hand (other shapes, a mesh file, each reader,
// the lens's second pass); the misclassification against the exact reference is reported per
// frame; bad volumes and settings exit 2 and write nothing.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/common/refused.h"
#include "tests/common/run_nbsim.h"

namespace nbsim {
namespace {

namespace fs = std::filesystem;
using testing::CliResult;
using testing::has;
using testing::run_nbsim;

const char* kClip = "capture ldi --scene city --objects 400 --size 160x120 --grid 4x4 ";

nlohmann::json compare(const fs::path& trace) {
  const CliResult r = run_nbsim("compare --json " + trace.string());
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  return nlohmann::json::parse(r.out)["ldi"];
}

// Every count of the model equals GL's, nothing differs.
void expect_exact(const nlohmann::json& l) {
  EXPECT_GT(l["clip_frames"], 0);
  EXPECT_GT(l["clip_draws"], 0);
  EXPECT_EQ(l["clip_fragments"], l["gl_clip_fragments"]);
  EXPECT_EQ(l["clip_samples"], l["gl_clip_samples"]);
  EXPECT_EQ(l["clip_discarded"], l["gl_clip_discarded"]);
  EXPECT_EQ(l["clip_fetches"], l["gl_clip_fetches"]);
  EXPECT_EQ(l["clip_draw_mismatches"], 0);
  EXPECT_EQ(l["clip_decision_mismatches"], 0);
  EXPECT_EQ(l["clip_depth_mismatches"], 0);
  EXPECT_EQ(l["clip_volume_mismatches"], 0);
  EXPECT_EQ(l["clip_classified"].get<std::uint64_t>() + l["clip_near_surface"].get<std::uint64_t>(), l["clip_fragments"]);
  EXPECT_EQ(l["clip_depth_tests"].get<std::uint64_t>() + l["clip_discarded"].get<std::uint64_t>(), l["clip_fragments"])
      << "a discarded fragment saves its depth test";
}

std::string fmt_volume(double x, double y, double z, double size) {
  std::ostringstream s;
  s.precision(17);
  s << x << ',' << y << ',' << z << ',' << size;
  return s.str();
}

// The volumes' centres and sizes as placed (the LDIV records of frame 0).
std::vector<std::array<double, 4>> placed_volumes(const fs::path& trace) {
  const CliResult r = run_nbsim("trace dump --records --frame 0 " + trace.string());
  EXPECT_EQ(r.status, 0) << r.err;
  std::vector<std::array<double, 4>> out;
  std::istringstream in(r.out);
  std::array<double, 4> v{};
  int got = 0;
  const std::regex field(R"(^\s+(center_x|center_y|center_z|size): (\S+))");
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (!std::regex_search(line, m, field)) continue;
    const std::string k = m[1];
    const int at = k == "center_x" ? 0 : k == "center_y" ? 1 : k == "center_z" ? 2 : 3;
    v[static_cast<std::size_t>(at)] = std::stod(m[2]);
    if (++got % 4 == 0) out.push_back(v);
  }
  return out;
}

TEST(LdiClipTest, AutomaticVolumesAlongAWalkReplayExactly) {
  const fs::path dir = testing::scratch_path("nbsim_ldi_clip_auto", "x").parent_path();
  const fs::path out = dir / "clip.nbt";
  const CliResult c = run_nbsim(std::string(kClip) + "--path walk --frames 2 --ldi-size 48 --application clip --shape knot -o " + out.string());
  ASSERT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_TRUE(has(c.out, "clip_discarded")) << c.out;
  const nlohmann::json l = compare(out);
  expect_exact(l);
  EXPECT_GT(l["clip_discarded"], 0) << "the knots clip something";
  EXPECT_EQ(l["ldi_reader"], "all");
  EXPECT_EQ(l["clip_fetches"], l["clip_fetches_all"]) << "the paper's reader by default";
  EXPECT_EQ(l["clip_volumes"], 3);
  // Per frame (run.json): the misclassification and the fragments it is out of.
  const CliResult rep = run_nbsim("replay " + out.string() + " --out " + (dir / "run").string());
  ASSERT_EQ(rep.status, 0) << rep.err;
  const nlohmann::json run = nlohmann::json::parse(std::ifstream(dir / "run" / "run.json"));
  ASSERT_EQ(run["frames"].size(), 2u);
  std::uint64_t misclassified = 0, classified = 0;
  for (const nlohmann::json& f : run["frames"]) {
    EXPECT_GT(f["clip_classified"], 0);
    misclassified += f["clip_misclassified"].get<std::uint64_t>();
    classified += f["clip_classified"].get<std::uint64_t>();
  }
  EXPECT_EQ(misclassified, l["clip_misclassified"]);
  EXPECT_EQ(classified, l["clip_classified"]);
  fs::remove_all(dir);
}

// Volumes by hand where the automatic ones stood: other shapes, a mesh file, each reader, and the
// lens's second pass (objects flattened, kept inside the volumes).
TEST(LdiClipTest, VolumesByHandEveryReaderAndTheLens) {
  const fs::path dir = testing::scratch_path("nbsim_ldi_clip_hand", "x").parent_path();
  const fs::path first = dir / "auto.nbt";
  ASSERT_EQ(run_nbsim(std::string(kClip) + "--path ground --frames 1 --ldi-size 48 --application clip -o " + first.string()).status, 0);
  const std::vector<std::array<double, 4>> at = placed_volumes(first);
  ASSERT_EQ(at.size(), 3u);
  fs::create_directories(dir);
  // An octahedron, closed, as an OBJ file.
  std::ofstream(dir / "octa.obj") << "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n"
                                     "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";
  const auto spot = [&](std::size_t k, double grow) {
    return fmt_volume(at[k][0], at[k][1], at[k][2], at[k][3] * grow);
  };
  const std::string volumes = "nested:2@" + spot(0, 1.2) + ";mesh:" + (dir / "octa.obj").string() + "@" + spot(1, 1.0) + ";sphere@" + spot(2, 0.8);
  std::uint64_t discarded_clip = 0;
  for (const char* reader : {"layers", "ranges", "all"}) {
    for (const char* application : {"clip", "lens"}) {
      SCOPED_TRACE(std::string(reader) + " " + application);
      const fs::path out = dir / (std::string(reader) + application + ".nbt");
      const CliResult c = run_nbsim(std::string(kClip) + "--path ground --frames 2 --ldi-size 48 --application " + application + " --reader " + reader +
                                    " --volumes '" + volumes + "' -o " + out.string());
      ASSERT_EQ(c.status, 0) << c.out << c.err;
      const nlohmann::json l = compare(out);
      expect_exact(l);
      EXPECT_EQ(l["clip_fetches"], l[std::string("clip_fetches_") + reader]);
      EXPECT_LE(l["clip_fetches_layers"].get<std::uint64_t>(), l["clip_fetches_all"].get<std::uint64_t>());
      if (std::string(application) == "clip") discarded_clip = l["clip_discarded"];
      else EXPECT_GT(l["clip_discarded"].get<std::uint64_t>(), discarded_clip) << "the focus pass discards outside the volumes";
    }
  }
  fs::remove_all(dir);
}

TEST(LdiClipTest, BadVolumesExitTwoAndWriteNothing) {
  const fs::path out = testing::scratch_path("nbsim_ldi_clip_bad", "never.nbt");
  const fs::path dir = out.parent_path();
  fs::create_directories(dir);
  std::ofstream(dir / "open.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n";
  const std::string o = " -o " + out.string();
  testing::expect_refused(
      std::string(kClip) + "--path walk --frames 1 --application clip ",
      {{"--volumes 'sphere@100000,0,100000,10'", "lies outside the scene's bounds"},
       {"--volumes 'sphere@100,5,100,20;knot@110,5,100,20'", "overlap"},
       {("--volumes 'mesh:" + (dir / "open.obj").string() + "@100,5,100,20'").c_str(), "not closed"},
       {"--volumes 'sphere@1,2,3'", "is not SHAPE@X,Y,Z,SIZE"},
       {"--volumes 'cube@1,2,3,4'", "unknown shape 'cube'"},
       {"--volumes 'sphere@0,0,0,5;sphere@10,0,0,5;sphere@20,0,0,5;sphere@30,0,0,5;sphere@40,0,0,5'", "at most 4"},
       {"--ldi-size 16384 --max-layers 64", "the limit is 1024 MiB"},
       {"--points 10", "--points is for --application shape"},
       {"--lens-height 0.5", "--lens-height is for --application lens"},
       {"--reader fast", "--reader"},
       {"--reversed-z", "reversed Z is not supported"}},
      o, out);
  testing::expect_refused("capture ldi --shape knot --ldi-size 32 --frames 1 ",
                          {{"--volumes auto --reader layers", "--reader is for --application clip or lens"}}, o, out);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace nbsim

// LdiCliTest: `nbsim capture ldi` from the outside: unusable meshes (empty, not closed, degenerate
// triangles), a zero viewpoint grid and an LDI deeper than --max-layers exit 2 naming the problem and
// write no file; a small capture prints its counts and `trace info` / `trace dump` read it back; the
// three parity readers (early exit, compressed, every layer) answer as GL's on shapes of growing
// depth complexity, the paper's reader at d fetches a point in the crop.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/common/refused.h"
#include "tests/common/run_nbsim.h"

namespace nbsim {
namespace {

namespace fs = std::filesystem;
using testing::CliResult;
using testing::has;
using testing::run_nbsim;

const char* kPrefix = "capture ldi --scene boxes --boxes 0 --path fly --size 8x8 --frames 1 --ldi-size 32 --grid 2x2 --points 64 ";

fs::path write_obj(const fs::path& dir, const std::string& name, const std::string& text) {
  fs::create_directories(dir);
  const fs::path p = dir / name;
  std::ofstream(p) << text;
  return p;
}

// A tetrahedron's four corners and its four outward faces (closed).
const std::string kTetra = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

// Each bad input exits 2 with a message naming its problem, before any output file exists.
TEST(LdiCliTest, BadInputExitsTwoAndWritesNothing) {
  const fs::path out = testing::scratch_path("nbsim_ldi_cli_bad", "never.nbt");
  const fs::path dir = out.parent_path() / "meshes";
  const fs::path open = write_obj(dir, "open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n");
  const fs::path empty = write_obj(dir, "empty.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  const fs::path degenerate = write_obj(dir, "degenerate.obj", kTetra + "v 2 2 2\nv 3 3 3\nv 4 4 4\nf 5 6 7\nf 5 7 6\n");
  const std::string o = " -o " + out.string();
  testing::expect_refused(kPrefix, {{("--mesh " + open.string()).c_str(), "not closed (a hole)"}}, o, out);
  testing::expect_refused(kPrefix, {{("--mesh " + empty.string()).c_str(), "no triangle"}}, o, out);
  testing::expect_refused(kPrefix, {{("--mesh " + degenerate.string()).c_str(), "is degenerate"}}, o, out);
  testing::expect_refused("capture ldi --scene boxes --boxes 0 --path fly --size 8x8 --frames 1 --ldi-size 32 --points 64 ",
                          {{"--grid 0x8", "--grid 0x8: each side must be 1 to 1024"},
                           {"--grid 8x0", "--grid 8x0: each side must be 1 to 1024"},
                           {"--grid 8", "is not HxV"}},
                          o, out);
  testing::expect_refused(kPrefix,
                          {{"--epsilon -1", "--epsilon '-1' is not a number in [0, 1)"},
                           {"--shape cube", "unknown shape 'cube'"},
                           {"--shape sphere --mesh x.obj", "give --shape or --mesh, not both"},
                           {"--mesh /nonexistent/x.obj", "/nonexistent/x.obj"},
                           {"--shape nested --shape-param 3 --max-layers 4", "more than max_layers = 4 layers"},
                           {"--max-layers 4096", "--max-layers 4096 is out of range"}},
                          o, out);
  fs::remove_all(out.parent_path());
}

// A closed mesh file is captured; the capture prints its counts (no misclassification of the
// sphere's clear points is required here: the counts are checked in LdiBuildTest) and the trace
// reads back with its LDIL and LDIT records and properties.
TEST(LdiCliTest, CaptureOfAMeshFileReadsBack) {
  const fs::path out = testing::scratch_path("nbsim_ldi_cli_ok", "tetra.nbt");
  const fs::path tetra = write_obj(out.parent_path(), "tetra.obj", kTetra);
  const CliResult r = run_nbsim(std::string(kPrefix) + "--mesh " + tetra.string() + " -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "ldi_layers 2")) << r.out;
  EXPECT_TRUE(has(r.out, "test_points 64")) << r.out;
  const CliResult info = run_nbsim("trace info " + out.string());
  ASSERT_EQ(info.status, 0) << info.err;
  EXPECT_TRUE(has(info.out, "ldi_size")) << info.out;
  EXPECT_TRUE(has(info.out, "mesh_triangles")) << info.out;
  const CliResult verify = run_nbsim("trace verify " + out.string());
  EXPECT_EQ(verify.status, 0) << verify.out << verify.err;
  const CliResult dump = run_nbsim("trace dump --frame 0 --records " + out.string());
  ASSERT_EQ(dump.status, 0) << dump.err;
  EXPECT_TRUE(has(dump.out, "LDIL")) << dump.out.substr(0, 2000);
  EXPECT_TRUE(has(dump.out, "LDIT")) << dump.out.substr(0, 2000);
  fs::remove_all(out.parent_path());
}

// An LDI capture draws no scene: it builds none (the header's scene and path are "none", no object),
// refuses --scene, --path and the scene's options naming why, and still takes the spelling the
// sample was recorded with (its recorded command line replays to the same LDI and answers).
TEST(LdiCliTest, NoSceneBuilt) {
  const fs::path dir = testing::scratch_path("nbsim_ldi_cli_noscene", "x").parent_path();
  const fs::path out = dir / "knot.nbt";
  const CliResult c = run_nbsim("capture ldi --shape knot --ldi-size 32 --grid 2x2 --points 64 --frames 1 -o " + out.string());
  ASSERT_EQ(c.status, 0) << c.out << c.err;
  const CliResult info = run_nbsim("trace info " + out.string());
  ASSERT_EQ(info.status, 0) << info.err;
  EXPECT_TRUE(has(info.out, "scene: none")) << info.out;
  EXPECT_TRUE(has(info.out, "path: none")) << info.out;
  EXPECT_TRUE(has(info.out, "0 objects")) << info.out;
  EXPECT_FALSE(has(info.out, "--scene")) << "the recorded command line names no scene: " << info.out;
  for (const char* bad : {"--scene city", "--path walk", "--objects 10", "--scene boxes --boxes 3 --path fly"}) {
    const CliResult r = run_nbsim(std::string("capture ldi --shape knot --ldi-size 32 --frames 1 ") + bad + " -o " + (dir / "bad.nbt").string());
    EXPECT_EQ(r.status, 2) << bad << ": " << r.out << r.err;
    EXPECT_TRUE(has(r.err, "draws no scene")) << bad << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir / "bad.nbt")) << bad;
  }
  // The sample's recorded spelling (the empty box scene along the fly path) is still taken.
  const fs::path sample = fs::path(NBSIM_SAMPLES) / "ldi_nested_128.nbt";
  const CliResult old = run_nbsim("capture ldi --scene boxes --path fly --size 8x8 --frames 2 --seed 1 --boxes 0 --shape nested --shape-param 3 "
                                  "--mesh none --ldi-size 128 --grid 8x8 --max-layers 64 --points 4096 --epsilon 1e-5 -o " +
                                  (dir / "again.nbt").string());
  ASSERT_EQ(old.status, 0) << old.out << old.err;
  const auto ldi_of = [](const fs::path& t) {
    const CliResult r = run_nbsim("compare --json " + t.string());
    EXPECT_EQ(r.status, 0) << r.out << r.err;
    return nlohmann::json::parse(r.out)["ldi"];
  };
  const nlohmann::json a = ldi_of(sample), b = ldi_of(dir / "again.nbt");
  for (const char* k : {"peel_passes", "peel_fragments", "peel_samples", "layers", "m_crop", "m_comp", "test_points", "fetches_layers",
                        "fetches_ranges", "misclassified_layers", "misclassified_ranges"})
    EXPECT_EQ(a[k], b[k]) << k << ": the sample's command line reproduces it";
  fs::remove_all(dir);
}

// Nested shells of 2 and 6 (depth complexity 4 and 12): every reader of the model answers as GL's
// at every point with GL's fetch counts; the paper's reader reads every layer (its fetches grow with
// d, O(d)) and the compressed one at most 1 + d/2 texels a point (O(d/2)).
TEST(LdiCliTest, ThreeReadersAnswerAsGl) {
  const fs::path dir = testing::scratch_path("nbsim_ldi_cli_readers", "x").parent_path();
  std::map<int, nlohmann::json> by_shells;
  for (const int shells : {2, 6}) {
    const fs::path out = dir / ("nested" + std::to_string(shells) + ".nbt");
    const CliResult c = run_nbsim("capture ldi --scene boxes --boxes 0 --path fly --size 8x8 --frames 1 --ldi-size 64 --grid 2x2 "
                                  "--points 512 --shape nested --shape-param " + std::to_string(shells) + " -o " + out.string());
    ASSERT_EQ(c.status, 0) << c.out << c.err;
    const CliResult r = run_nbsim("compare --json " + out.string());
    ASSERT_EQ(r.status, 0) << r.out << r.err;
    const nlohmann::json l = nlohmann::json::parse(r.out)["ldi"];
    SCOPED_TRACE(shells);
    EXPECT_EQ(l["all_points"], l["test_points"]);
    EXPECT_EQ(l["parity_mismatches_all"], 0);
    EXPECT_EQ(l["fetch_mismatches_all"], 0);
    EXPECT_EQ(l["parity_mismatches_layers"], 0);
    EXPECT_EQ(l["parity_mismatches_ranges"], 0);
    EXPECT_EQ(l["fetches_all"], l["gl_fetches_all"]);
    EXPECT_EQ(l["misclassified_all"], l["misclassified_layers"]) << "the same answers, so the same misclassification";
    EXPECT_GT(l["fetches_per_point_all"].get<double>(), l["fetches_per_point_ranges"].get<double>());
    EXPECT_EQ(l["layers"], 2 * shells);
    by_shells[shells] = l;
  }
  const auto per_point = [&](int shells, const char* reader) { return by_shells[shells][std::string("fetches_per_point_") + reader].get<double>(); };
  EXPECT_GT(per_point(6, "all") / per_point(2, "all"), 2.0) << "every layer read: the fetches follow d (4 -> 12)";
  EXPECT_LT(per_point(6, "ranges"), 1.0 + 12 / 2.0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace nbsim

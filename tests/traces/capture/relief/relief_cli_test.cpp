// ReliefCliTest: `nbsim capture relief` and `nbsim compare` / `nbsim relief` from the outside. The
// issue's hard cases captured on llvmpipe and replayed: the saddle, single-texel spikes and the 0 to
// 1 step at grazing angles, thin walls, a heightfield file and one baked from a mesh; every method's
// fragments, hits and per-fragment walks equal GL's, and the robust and N-buffer walks have no hit
// error. Bad input (an unknown field, an unsupported size, a heightfield file with NaN or a height
// out of range or not square, a radius file that does not match its field, bad methods or angles)
// exits 2 naming the problem and writes no trace.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/common/refused.h"
#include "model/nbuffer/covering.h"
#include "tests/common/run_nbsim.h"

namespace nbsim {
namespace {

namespace fs = std::filesystem;
using testing::CliResult;
using testing::has;
using testing::run_nbsim;

const char* kPrefix = "capture relief --scene boxes --boxes 0 --path fly --size 48x48 --frames 1 ";

// A little-endian PFM of one channel (bottom row first, as PFM stores it): nbsim images are y up.
fs::path write_pfm(const fs::path& file, int w, int h, const std::vector<float>& v) {
  fs::create_directories(file.parent_path());
  std::ofstream f(file, std::ios::binary);
  f << "Pf\n" << w << " " << h << "\n-1.0\n";
  f.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(float)));
  return file;
}

// Captures, compares, and returns compare's JSON summary (its "relief" object).
nlohmann::json capture_and_compare(const fs::path& trace, const std::string& options) {
  const CliResult c = run_nbsim(std::string(kPrefix) + options + " -o " + trace.string());
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  const CliResult r = run_nbsim("compare --json " + trace.string());
  EXPECT_EQ(r.status, 0) << options << "\n" << r.out << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << r.out;
  return j.is_discarded() ? nlohmann::json() : j["relief"];
}

void expect_exact_replay(const nlohmann::json& relief, const std::string& what) {
  ASSERT_TRUE(relief.is_object()) << what;
  ASSERT_EQ(relief["methods"].size(), 5u) << what;
  EXPECT_EQ(relief["scene_mismatches"], 0) << what << ": every scene draw's samples equal GL's";
  for (const auto& [name, m] : relief["methods"].items()) {
    SCOPED_TRACE(what + " " + name);
    EXPECT_GT(m["fragments"].get<std::uint64_t>(), 100u);
    EXPECT_EQ(m["fragments"], m["gl_fragments"]);
    EXPECT_EQ(m["samples"], m["gl_samples"]);
    EXPECT_EQ(m["walk_mismatches"], 0);
    EXPECT_EQ(m["pixel_mismatches"], 0);
    EXPECT_EQ(m["depth_mismatches"], 0) << "the depth buffer after each box draw equals GL's";
    EXPECT_EQ(m["capped"], 0);
    if (name == "nbuffer" || (name == "robust" && relief["relief_radius"] == "strict")) {
      EXPECT_EQ(m["errors"], 0) << "the N-buffer walk, and the robust search with the strict radius, are exact";
    }
    // Storage a texel, 4 bytes a value: heights; radii too (robust); every N-buffer level too (nbuffer).
    const int n = std::stoi(relief["relief_field_size"].get<std::string>());
    const double per_texel = m["storage_bytes_per_texel"].get<double>();
    const double values = name == "nbuffer" ? 1 + nbsim::nbuffer_level_count(n, n) : name.rfind("robust", 0) == 0 ? 2 : 1;
    EXPECT_EQ(per_texel, 4.0 * values);
  }
}

TEST(ReliefCliTest, HardCasesReplayExactly) {
  const fs::path dir = testing::scratch_path("nbsim_relief_cli", "x").parent_path();
  struct Case {
    const char* name;
    const char* options;
  };
  const Case cases[] = {
      // The strict radius on the cases that break a careless one (its robust search then has no hit error).
      {"saddle", "--field saddle --field-size 16 --angles 84 --radius strict"},
      {"spikes", "--field spikes --field-size 32 --field-param 20 --angles 87 --radius strict"},
      {"step", "--field step --field-size 32 --angles 89 --radius strict"},
      {"walls", "--field walls --field-size 32 --field-param 5 --angles 60 --radius strict"},
      {"fbm_head_on", "--field fbm --field-size 32 --angles 0"},
      {"shape", "--field-mesh shape:knot --field-size 40 --angles 70"},
      {"frustum", "--field-mesh shape:sphere --field-size 32 --frustum 1.5 --angles 40"},
      {"frustum_below", "--field fbm --field-size 24 --frustum 0.5 --angles 150"},
  };
  std::uint64_t exact_errors = 0;
  for (const Case& c : cases) {
    const nlohmann::json r = capture_and_compare(dir / (std::string(c.name) + ".nbt"), c.options);
    expect_exact_replay(r, c.name);
    if (r.is_object()) exact_errors += r["methods"]["exact"]["errors"].get<std::uint64_t>();
  }
  EXPECT_GT(exact_errors, 0u) << "the exact walk misses bilinear saddles somewhere in these fields (Figure 3)";
  fs::remove_all(dir);
}

// A box standing in the city, seen along the walk, with each of the box's depth outputs (the relief
// paper's section 4.4): the objects nearer than the box are drawn first, so the early depth test
// culls the box's hidden fragments before their walks (box, none), or cannot (exact: the shader
// writes the depth); the box's depth then hides part of the objects drawn after it (box, exact).
// In GL and in the model alike: every fragment, walk and scene draw, and the depth after each box.
TEST(ReliefCliTest, BoxInTheCity) {
  const fs::path dir = testing::scratch_path("nbsim_relief_cli_city", "x").parent_path();
  std::map<std::string, nlohmann::json> by_mode;
  for (const std::string mode : {"box", "exact", "none"}) {
    SCOPED_TRACE(mode);
    const fs::path trace = dir / ("city_" + mode + ".nbt");
    const CliResult c = run_nbsim("capture relief --scene city --objects 800 --path walk --size 160x120 --frames 4 --placement city "
                                  "--field fbm --field-size 32 --box-depth " + mode + " -o " + trace.string());
    ASSERT_EQ(c.status, 0) << c.out << c.err;
    const CliResult r = run_nbsim("compare --json " + trace.string());
    EXPECT_EQ(r.status, 0) << r.out << r.err;
    const nlohmann::json relief = nlohmann::json::parse(r.out)["relief"];
    expect_exact_replay(relief, "city " + mode);
    EXPECT_EQ(relief["relief_box_depth"], mode);
    EXPECT_GT(relief["scene_draws"].get<std::uint64_t>(), 100u);
    by_mode[mode] = relief["methods"]["nbuffer"];
  }
  const auto n = [&](const char* mode, const char* key) { return by_mode[mode][key].get<std::uint64_t>(); };
  EXPECT_LT(n("box", "fragments"), n("box", "rasterized")) << "buildings hide part of the box: walks saved";
  EXPECT_EQ(n("box", "fragments"), n("none", "fragments"));
  EXPECT_EQ(n("exact", "fragments"), n("exact", "rasterized")) << "a shader that writes depth walks every fragment";
  EXPECT_EQ(n("box", "depth_written"), n("box", "samples")) << "the box writes where its rays hit";
  EXPECT_EQ(n("none", "depth_written"), 0u);
  EXPECT_GT(n("box", "scene_after_draws"), 0u);
  EXPECT_GT(n("box", "scene_hidden"), 0u) << "the box's depth hides objects behind it";
  EXPECT_EQ(n("none", "scene_hidden"), 0u);
  EXPECT_EQ(n("box", "scene_after_samples") + n("box", "scene_hidden"), n("none", "scene_after_samples"));
  fs::remove_all(dir);
}

// The box's own camera with the exact depth: a frustum's hit depths through its projective map, and
// a box seen at a grazing angle; the depth GL kept equals the model's after every draw.
TEST(ReliefCliTest, ExactDepthOfItsOwnBox) {
  const fs::path dir = testing::scratch_path("nbsim_relief_cli_depth", "x").parent_path();
  for (const char* options : {"--field walls --field-size 32 --frustum 2 --angles 50 --box-depth exact",
                              "--field fbm --field-size 32 --angles 85 --box-depth exact"}) {
    const nlohmann::json r = capture_and_compare(dir / "exact.nbt", options);
    expect_exact_replay(r, options);
    if (r.is_object()) {
      for (const auto& [name, m] : r["methods"].items()) EXPECT_EQ(m["depth_written"], m["samples"]) << options << " " << name;
    }
  }
  fs::remove_all(dir);
}

TEST(ReliefCliTest, HeightfieldFileAndTable) {
  const fs::path dir = testing::scratch_path("nbsim_relief_cli_file", "x").parent_path();
  std::vector<float> h(40 * 40);
  for (int j = 0; j < 40; ++j)
    for (int i = 0; i < 40; ++i) h[static_cast<std::size_t>(j * 40 + i)] = 0.5f + 0.45f * std::sin(0.4f * static_cast<float>(i)) * std::cos(0.3f * static_cast<float>(j));
  const fs::path field = write_pfm(dir / "waves.pfm", 40, 40, h);
  const fs::path trace = dir / "waves.nbt";
  expect_exact_replay(capture_and_compare(trace, "--field-file " + field.string() + " --angles 75"), "waves.pfm");
  const CliResult t = run_nbsim("relief " + trace.string() + " --out " + (dir / "table").string());
  EXPECT_EQ(t.status, 0) << t.out << t.err;
  EXPECT_NE(t.out.find("N-buffer walk against the exact walk"), std::string::npos) << t.out;
  const nlohmann::json doc = nlohmann::json::parse(std::ifstream(dir / "table" / "relief.json"));
  EXPECT_EQ(doc["rows"].size(), 5u);
  EXPECT_EQ(doc["ranking"].size(), 5u);
  EXPECT_EQ(doc["nbuffer_vs_exact"].size(), 1u);
  EXPECT_TRUE(fs::exists(dir / "table" / "relief.csv"));
  fs::remove_all(dir);
}

// The paper's radius (--radius paper): fresh captures replay exactly for every method; with the
// minimum over directions and epsilon 0 the robust search stays exact, and a larger epsilon (the
// paper's maximum) makes it cheaper than with the strict radius, at some hit error.
TEST(ReliefCliTest, PaperRadiusReplaysExactly) {
  const fs::path dir = testing::scratch_path("nbsim_relief_cli_paper", "x").parent_path();
  const auto exact = [](const nlohmann::json& r, const std::string& what) {
    ASSERT_TRUE(r.is_object()) << what;
    for (const auto& [name, m] : r["methods"].items()) {
      EXPECT_EQ(m["walk_mismatches"], 0) << what << " " << name;
      EXPECT_EQ(m["pixel_mismatches"], 0) << what << " " << name;
      EXPECT_EQ(m["fragments"], m["gl_fragments"]) << what << " " << name;
    }
  };
  const std::string field = "--field fbm --field-size 40 --field-param 5 --seed 17 --angles 55 ";
  const nlohmann::json bound = capture_and_compare(dir / "min.nbt", field + "--radius paper --radius-combine min");
  exact(bound, "min");
  EXPECT_EQ(bound["methods"]["robust"]["errors"], 0) << "the minimum at epsilon 0 bounds the walk's rays";
  const nlohmann::json strict = capture_and_compare(dir / "strict.nbt", field + "--radius strict");
  const nlohmann::json paper = capture_and_compare(dir / "paper.nbt", field);
  exact(paper, "the default");
  EXPECT_EQ(paper["relief_radius"], "paper") << "the paper's radius is the default";
  EXPECT_EQ(paper["relief_radius_combine"], "max");
  const nlohmann::json loose = capture_and_compare(dir / "loose.nbt", field + "--radius paper --radius-epsilon 0.05");
  exact(loose, "epsilon 0.05");
  EXPECT_LT(loose["methods"]["robust"]["lookups"].get<double>(), strict["methods"]["robust"]["lookups"].get<double>())
      << "larger radii, fewer lookups";
  fs::remove_all(dir);
}

// Seen from its own camera the box draws no scene: none is built, and another scene or path than
// the old spelling's (--scene boxes --boxes 0 --path fly, kPrefix) is refused naming why.
TEST(ReliefCliTest, OwnCameraDrawsNoScene) {
  const fs::path dir = testing::scratch_path("nbsim_relief_cli_noscene", "x").parent_path();
  const CliResult c = run_nbsim("capture relief --size 48x48 --frames 1 --field fbm --field-size 16 -o " + (dir / "t.nbt").string());
  ASSERT_EQ(c.status, 0) << c.out << c.err;
  const CliResult info = run_nbsim("trace info " + (dir / "t.nbt").string());
  EXPECT_TRUE(has(info.out, "scene: none")) << info.out;
  for (const char* bad : {"--scene city", "--path walk", "--scene boxes --boxes 2"}) {
    const CliResult r = run_nbsim(std::string("capture relief --size 48x48 --frames 1 --field fbm --field-size 16 ") + bad + " -o " +
                                  (dir / "bad.nbt").string());
    EXPECT_EQ(r.status, 2) << bad;
    EXPECT_TRUE(has(r.err, "draws no scene (the box is seen from its own camera")) << bad << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir / "bad.nbt"));
  }
  fs::remove_all(dir);
}

TEST(ReliefCliTest, BadInputExitsTwoAndWritesNothing) {
  const fs::path out = testing::scratch_path("nbsim_relief_cli_bad", "never.nbt");
  const fs::path dir = out.parent_path() / "files";
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> ok(16 * 16, 0.25f), with_nan = ok, too_high = ok;
  with_nan[5 * 16 + 3] = nan;
  too_high[2 * 16 + 7] = 1.5f;
  ok[8 * 16 + 8] = 1.0f;  // a spike: radius 0 there
  const fs::path nan_file = write_pfm(dir / "nan.pfm", 16, 16, with_nan);
  const fs::path high_file = write_pfm(dir / "high.pfm", 16, 16, too_high);
  const fs::path wide_file = write_pfm(dir / "wide.pfm", 16, 8, std::vector<float>(16 * 8, 0.1f));
  const fs::path spike_file = write_pfm(dir / "spike.pfm", 16, 16, ok);
  const fs::path radius_big = write_pfm(dir / "radius_big.pfm", 16, 16, std::vector<float>(16 * 16, 8.0f));
  const fs::path radius_small = write_pfm(dir / "radius_small.pfm", 8, 8, std::vector<float>(8 * 8, 0.0f));
  const std::string o = " -o " + out.string();
  testing::expect_refused(kPrefix,
                          {{"--field plasma", "plasma"},
                           {"--field fbm --field-size 3000", "3000"},
                           {("--field-file " + nan_file.string()).c_str(), "NaN"},
                           {("--field-file " + high_file.string()).c_str(), "1.5"},
                           {("--field-file " + wide_file.string()).c_str(), "square"},
                           {"--field-file /nonexistent/h.exr", "/nonexistent/h.exr"},
                           {("--field-file " + spike_file.string() + " --radius-file " + radius_big.string()).c_str(),
                            "does not match the heightfield"},
                           {("--field-file " + spike_file.string() + " --radius-file " + radius_small.string()).c_str(),
                            "does not match the heightfield"},
                           {"--methods exact,fastest", "'fastest' is not a method"},
                           {"--angles 185", "--angles '185'"},
                           {"--frustum -1", "--frustum '-1'"},
                           {"--box-height 0", "--box-height '0'"},
                           {"--field-mesh shape:cube", "cube"},
                           {"--box-at 1,2,3", "--box-at needs --placement city"},
                           {"--placement city --angles 10", "--angles is for --placement own"},
                           {"--placement city --frustum 1", "takes the box, not a --frustum"},
                           {"--placement city --box-at 1,2", "is not X,Z,SIZE"},
                           {"--radius paper --radius-epsilon 2", "--radius-epsilon '2'"},
                           {"--radius paper --radius-epsilon nan", "--radius-epsilon 'nan'"},
                           {"--radius strict --radius-epsilon 0.1", "add --radius paper"},
                           {"--radius exact", "exact"},
                           {("--radius-epsilon 0.01 --radius-file " + radius_big.string()).c_str(), "takes no --radius-epsilon"},
                           {"--box-depth some", "some"}},
                          o, out);
  fs::remove_all(out.parent_path());
}

}  // namespace
}  // namespace nbsim

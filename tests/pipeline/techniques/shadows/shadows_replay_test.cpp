// ShadowsReplayTest: fresh shadows captures (128x96, 2 frames, 64-lexel litmaps) of boxes, terrain
// and city in every shadow mode, replayed by the shadows program: every draw's fragments and passed
// samples equal GL's, the stencil buffer and both shadow masks equal GL's, the model's z_min/z_max
// and lookups equal the capture's and no decision unlike the capture's rule; the fill falls from
// infinite to culled to clamped. The model's own volumes replay any mode, and its own litmaps equal
// GL's at the captured size and give GL's clamped result at 32 and 128 lexels. A u16, divisor-2 or level-capped N-buffer stays conservative; a
// damaged SHDC record, a missing litmap or a truncated trace is refused with exit 2; `nbsim shadows --json` rows.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <cmath>
#include <iterator>
#include <map>
#include <set>
#include <utility>
#include <string>
#include <variant>
#include <vector>

#include "tests/common/run_nbsim.h"
#include "tests/pipeline/explore/read_csv.h"
#include "traces/format/reader.h"
#include "traces/format/writer.h"

namespace {

namespace fs = std::filesystem;
using nbsim::testing::CliResult;
using nbsim::testing::has;
using nbsim::testing::run_nbsim;

fs::path scratch(const std::string& name) { return nbsim::testing::scratch_path("nbsim_shadows_replay", name); }

// The scenes, kept small: a capture takes well under a second each.
const std::map<std::string, std::string> kSceneArgs = {
    {"boxes", "--scene boxes"},
    {"terrain", "--scene terrain --towers 8 --birds 120"},
    {"city", "--scene city --objects 400"},
};

// Captures `scene` in `mode` once per test binary run (cached by name).
fs::path capture(const std::string& scene, const std::string& mode, const std::string& extra = "") {
  std::string tag;
  for (const char ch : extra) tag += std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
  const fs::path t = scratch(scene + "_" + mode + (extra.empty() ? "" : "_" + tag) + ".nbt");
  if (fs::exists(t)) return t;
  const std::string litmap = extra.find("--litmap ") == std::string::npos ? "--litmap 64 " : "";
  const CliResult c = run_nbsim("capture shadows " + kSceneArgs.at(scene) + " --path fly --size 128x96 --frames 2 " + litmap +
                                "--shadow-mode " + mode + " " + extra + " -o " + t.string());
  EXPECT_EQ(c.status, 0) << scene << " " << mode << ": " << c.out << c.err;
  return t;
}

nlohmann::json replay(const fs::path& t, const std::string& sets = "", const std::string& tag = "run") {
  const fs::path dir = t.parent_path() / (t.stem().string() + "_" + tag);
  const CliResult r = run_nbsim("replay " + t.string() + " --out " + dir.string() + sets);
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  std::ifstream in(dir / "run.json");
  return nlohmann::json::parse(in);
}

// Rewrites `good` into `bad`, frame 1 changed by `edit` (and frame 0 by `first`).
template <class Edit, class First = void (*)(nbsim::scene::Frame&)>
void rewrite(const fs::path& good, const fs::path& bad, Edit edit, First first = [](nbsim::scene::Frame&) {}) {
  nbsim::trace::FrameReader in(good);
  nbsim::trace::TraceWriter w(bad, in.trace().properties());
  if (in.trace().scene()) w.write(*in.trace().scene());
  while (auto f = in.next()) {
    if (f->ordinal == 1) edit(*f);
    if (f->ordinal == 0) first(*f);
    w.begin_frame(f->begin);
    for (const auto& d : f->draws) w.write(d);
    for (const auto& d : f->depths) w.write(d);
    for (const auto& l : f->levels) w.write(l);
    for (const auto& s : f->stencils) w.write(s);
    if (f->light) w.write_light(*f->light);
    for (const auto& r : f->technique_records) w.write(r);
    if (f->truth) w.write(*f->truth);
    w.end_frame(f->end);
  }
  w.close();
}

class ShadowsReplayTest : public ::testing::TestWithParam<std::string> {};

// Each scene in each mode: exact draws, stencil and masks equal to GL's, the queries and decisions
// as the capture's, and fill clamped <= culled <= infinite.
TEST_P(ShadowsReplayTest, ReplaysExactlyInEveryMode) {
  const std::string scene = GetParam();
  std::map<std::string, double> fill, reference;
  for (const std::string mode : {"infinite", "culled", "clamped"}) {
    SCOPED_TRACE(scene + " " + mode);
    const auto run = replay(capture(scene, mode));
    const auto& sum = run["summary"];
    EXPECT_GT(sum["draws"].get<int>(), 0);
    EXPECT_EQ(sum["draws_exact"], sum["draws"]) << "every draw's fragments and passed samples equal GL's";
    EXPECT_EQ(sum["stencil_pixels_matching"], sum["stencil_pixels"]) << "the stencil buffer equals GL's";
    EXPECT_EQ(sum["depth_pixels_matching"], sum["depth_pixels"]);
    const auto& s = sum["shadows"];
    EXPECT_EQ(s["frames"], 2);
    EXPECT_EQ(s["shadow_mode"], mode);
    EXPECT_EQ(s["scene"], scene);
    EXPECT_GT(s["casters"].get<int>(), 0);
    EXPECT_GT(s["measured"].get<int>(), 0) << "some caster has a rectangle in the litmap";
    EXPECT_EQ(s["mask_diff"], 0) << "the model's mask equals GL's";
    EXPECT_EQ(s["mask_diff_infinite"], 0) << "and the infinite reference's";
    EXPECT_EQ(s["gl_mask_diff"], 0);
    EXPECT_EQ(s["mask_pixels"], s["gl_mask_pixels"]);
    EXPECT_EQ(s["zmin_mismatches"], 0) << "f32 full resolution: GL's z_min";
    EXPECT_EQ(s["zmax_mismatches"], 0) << "f32 full resolution: GL's z_max";
    EXPECT_EQ(s["lookup_mismatches"], 0) << "as many texels as the capture read";
    EXPECT_EQ(s["decision_mismatches"], 0);
    EXPECT_EQ(s["unsafe_culls"], 0);
    EXPECT_EQ(s["not_conservative"], 0);
    EXPECT_EQ(s["fill"], s["gl_fill"]) << "the fill is GL's";
    EXPECT_GE(s["culled"].get<int>(), s["gl_culled"].get<int>()) << "the litmap rule culls at least what GL culled";
    EXPECT_GT(s["build_texels"].get<int>(), 0);
    EXPECT_GT(s["litmap_reprojections"].get<int>(), 0);
    EXPECT_EQ(s["stencil_tests"], s["fill"]) << "one stencil test per volume fragment";
    EXPECT_EQ(s["per_frame"].size(), 2u);
    fill[mode] = s["fill_per_frame"].get<double>();
    reference[mode] = s["reference_fill_per_frame"].get<double>();
    ASSERT_TRUE(s["fill_ratio_to_infinite"].is_number()) << "every frame's SHDC holds GL's reference fill";
    EXPECT_LE(s["fill_ratio_to_infinite"].get<double>(), 1.0);
  }
  EXPECT_EQ(reference["infinite"], fill["infinite"]) << "an infinite capture's reference is its own fill";
  EXPECT_EQ(reference["culled"], fill["infinite"]) << "the reference pass draws what the infinite capture draws";
  EXPECT_EQ(reference["clamped"], fill["infinite"]);
  EXPECT_LE(fill["clamped"], fill["culled"]);
  EXPECT_LE(fill["culled"], fill["infinite"]);
  EXPECT_GT(fill["infinite"], 0.0);
}

INSTANTIATE_TEST_SUITE_P(Scenes, ShadowsReplayTest, ::testing::Values("boxes", "terrain", "city"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

// The model's own volumes (shadows.volumes, built from the trace's caster meshes with the model's
// N-buffer answers): a capture in one mode replays as each mode with the fill, the stencil buffer
// (its CRC-32 every frame, the model's stencil being GL's in the trace replays above) and the mask
// a capture of that mode gives on GL, on every scene; and the captured mode rebuilt gives GL's own
// volumes back.
TEST_P(ShadowsReplayTest, ModelBuiltVolumesReplayAnyMode) {
  const std::string scene = GetParam();
  std::map<std::string, nlohmann::json> gl;
  for (const std::string mode : {"infinite", "culled", "clamped"}) gl[mode] = replay(capture(scene, mode));
  const auto checksums = [](const nlohmann::json& run) {
    std::vector<std::uint64_t> v;
    for (const auto& f : run["frames"]) v.push_back(f["stencil_checksum"].get<std::uint64_t>());
    return v;
  };
  for (const std::string from : {"infinite", "clamped"})
    for (const std::string as : {"infinite", "culled", "clamped"}) {
      SCOPED_TRACE(scene + ": a " + from + " capture replayed as " + as);
      const auto run = replay(capture(scene, from), " --set shadows.volumes=" + as, "as_" + as);
      const auto& s = run["summary"]["shadows"];
      const auto& g = gl[as]["summary"]["shadows"];
      EXPECT_EQ(s["model_volumes"], g["volume_draws"]) << "the volumes a capture of that mode drew";
      EXPECT_EQ(s["fill"], g["gl_fill"]) << "GL's fill in that mode";
      EXPECT_EQ(checksums(run), checksums(gl[as])) << "GL's stencil buffer in that mode, frame by frame";
      EXPECT_EQ(s["mask_diff"], 0);
      EXPECT_EQ(s["mask_diff_infinite"], 0);
      EXPECT_EQ(s["rect_mismatches"], 0) << "rectangles from the meshes' bounds and the recorded light";
      EXPECT_EQ(s["own_mask_diff"], 0) << "the mask equals the model's own infinite volumes'";
      EXPECT_EQ(run["summary"]["draws_exact"], run["summary"]["draws"]) << "GL's own draws (scene) stay exact";
      double casters = 0.0, fill = 0.0;
      for (const auto& b : s["fill_breakdown"]) casters += b["casters_per_frame"].get<double>(), fill += b["fill_per_frame"].get<double>();
      EXPECT_DOUBLE_EQ(casters, s["casters_per_frame"].get<double>()) << "the breakdown counts every caster once, by the model's decision";
      EXPECT_DOUBLE_EQ(fill, s["fill_per_frame"].get<double>()) << "and all of the model's fill";
      // Each draw of a frame, the model's volumes included, has its own index in draws.csv.
      const fs::path t = capture(scene, from);
      const auto rows = nbsim::testing::read_csv(t.parent_path() / (t.stem().string() + "_as_" + as) / "draws.csv");
      std::set<std::pair<std::string, std::string>> seen;
      for (const auto& row : rows)
        EXPECT_TRUE(seen.insert({row.at("frame"), row.at("draw")}).second) << "frame " << row.at("frame") << ": draw " << row.at("draw") << " twice";
      EXPECT_FALSE(rows.empty());
    }
}

// The model's own litmaps (shadows.litmaps=model, drawn from the trace's object meshes): at the
// captured size every litmap texel and every litmap and splat draw's fragment count equal GL's; at
// another size (half and twice the captured side) or with the N-buffers' other covering, an
// infinite capture replayed as clamped gives the fill, the stencil buffer frame by frame and the
// mask of a clamped capture of that design on GL.
TEST_P(ShadowsReplayTest, ModelLitmapsAtAnySize) {
  const std::string scene = GetParam();
  const auto checksums = [](const nlohmann::json& run) {
    std::vector<std::uint64_t> v;
    for (const auto& f : run["frames"]) v.push_back(f["stencil_checksum"].get<std::uint64_t>());
    return v;
  };
  {
    SCOPED_TRACE(scene + ": the captured size");
    const auto run = replay(capture(scene, "clamped"), " --set shadows.litmaps=model", "own_litmaps");
    const auto& s = run["summary"]["shadows"];
    EXPECT_EQ(s["model_litmap_frames"], 2);
    EXPECT_EQ(s["litmap_texel_diff"], 0) << "both litmaps equal GL's, bit for bit";
    EXPECT_EQ(s["litmap_fragment_diff"], 0) << "every litmap and splat draw rasterizes GL's fragments";
    EXPECT_GT(s["litmap_discarded"].get<int>(), 0) << "the reprojection test drops what the observer cannot see";
    EXPECT_EQ(s["zmin_mismatches"], 0);
    EXPECT_EQ(s["zmax_mismatches"], 0);
    EXPECT_EQ(s["fill"], s["gl_fill"]);
    EXPECT_EQ(s["mask_diff"], 0);
  }
  const struct {
    std::string tag, capture, sets;
  } designs[] = {{"32", "--litmap 32", " --set shadows.litmap_size=32"},
                 {"128", "--litmap 128", " --set shadows.litmap_size=128"},
                 {"corners", "--covering corners", " --set litmap_min.covering=corners --set litmap_max.covering=corners"}};
  for (const auto& design : designs) {
    SCOPED_TRACE(scene + ": " + design.capture);
    const auto gl = replay(capture(scene, "clamped", design.capture));
    const auto run = replay(capture(scene, "infinite"), " --set shadows.litmaps=model --set shadows.volumes=clamped" + design.sets,
                            "as_clamped_" + design.tag);
    const auto& s = run["summary"]["shadows"];
    const auto& g = gl["summary"]["shadows"];
    EXPECT_EQ(s["model_volumes"], g["volume_draws"]) << "the volumes a clamped capture of that design drew";
    EXPECT_EQ(s["fill"], g["gl_fill"]) << "GL's clamped fill of that design";
    EXPECT_EQ(checksums(run), checksums(gl)) << "GL's stencil buffer of that design, frame by frame";
    EXPECT_EQ(s["mask_pixels"], g["gl_mask_pixels"]);
    EXPECT_EQ(s["own_mask_diff"], 0);
    EXPECT_EQ(s["culled"], g["gl_culled"]) << "the casters GL culled of that design";
  }
}

// Another litmap size without the model's litmaps and volumes, or a trace without SHDM, is refused.
TEST(ShadowsModelLitmapsTest, BadSettingsRefused) {
  const fs::path t = capture("boxes", "clamped");
  const auto refused = [&](const std::string& sets, const std::string& message, const fs::path& trace) {
    const CliResult r = run_nbsim("replay " + trace.string() + " --out " + (t.parent_path() / "bad_litmaps_run").string() + sets);
    EXPECT_EQ(r.status, 2) << sets << ": " << r.out << r.err;
    EXPECT_TRUE(has(r.err, message)) << r.err;
  };
  refused(" --set shadows.litmap_size=32", "another size needs shadows.litmaps=model", t);
  refused(" --set shadows.litmap_size=32 --set shadows.litmaps=model", "needs the model's own volumes", t);
  const fs::path bare = scratch("no_litmap_meshes.nbt");
  rewrite(t, bare, [](nbsim::scene::Frame&) {}, [](nbsim::scene::Frame& f) {
    std::erase_if(f.technique_records, [](const auto& r) { return r.type == nbsim::trace::fourcc("SHDM"); });
  });
  refused(" --set shadows.litmaps=model", "needs every object's mesh (a ShadowLitmapMeshes record", bare);
}

// The litmap comparison sees a single changed texel of GL's litmap.
TEST(ShadowsModelLitmapsTest, OneChangedTexelCounted) {
  const fs::path bad = scratch("one_texel.nbt");
  rewrite(capture("boxes", "clamped"), bad, [](nbsim::scene::Frame& f) {
    for (auto& d : f.depths)
      if (d.name == "litmap_min") d.texels[d.texels.size() / 2] = std::nextafter(d.texels[d.texels.size() / 2], 0.0f);
  });
  const auto run = replay(bad, " --set shadows.litmaps=model", "own");
  EXPECT_EQ(run["summary"]["shadows"]["litmap_texel_diff"], 1);
}

// The model's litmaps drawn on one thread (the receiver splats rasterized once for both litmaps) or
// on two (the min and the max litmap at once): the same statistics, frames and draws, on every scene.
TEST(ShadowsModelLitmapsTest, OneOrTwoThreadsAlike) {
  for (const std::string scene : {"boxes", "city"}) {
    const fs::path t = capture(scene, "clamped");
    std::map<std::string, std::pair<nlohmann::json, std::string>> runs;
    for (const std::string threads : {"1", "2"}) {
      const fs::path dir = t.parent_path() / (t.stem().string() + "_threads_" + threads);
      const CliResult r = nbsim::testing::run_nbsim_env("NBSIM_SHADOWS_THREADS=" + threads + " ",
                                                        "replay " + t.string() + " --out " + dir.string() +
                                                            " --set shadows.litmaps=model --set shadows.volumes=clamped");
      ASSERT_EQ(r.status, 0) << r.out << r.err;
      std::ifstream in(dir / "run.json"), frames(dir / "frames.csv"), draws(dir / "draws.csv");
      runs[threads] = {nlohmann::json::parse(in)["stats"],
                       std::string(std::istreambuf_iterator<char>(frames), {}) + std::string(std::istreambuf_iterator<char>(draws), {})};
    }
    EXPECT_EQ(runs["1"].first, runs["2"].first) << scene << ": statistics";
    EXPECT_EQ(runs["1"].second, runs["2"].second) << scene << ": frames.csv and draws.csv";
    EXPECT_GT(runs["1"].first["gpu.shadows"]["litmap_draws"].get<double>(), 0.0) << scene;
  }
}

// A lossy design of both N-buffers (u16, a quarter of the resolution) with the model's own clamped
// volumes: looser slabs, so at least GL's clamped fill, and the mask equal to the model's own
// infinite volumes' cut at the same planes (GL's infinite reference is cut at GL's planes, so a few
// of its boundary pixels may rasterize otherwise).
TEST(ShadowsModelVolumesTest, LossyDesignKeepsItsOwnMask) {
  for (const std::string scene : {"terrain", "city"}) {
    SCOPED_TRACE(scene);
    const auto gl = replay(capture(scene, "clamped"));
    const auto run = replay(capture(scene, "clamped"),
                            " --set shadows.volumes=clamped --set litmap_min.format=u16 --set litmap_max.format=u16"
                            " --set litmap_min.resolution_divisor=4 --set litmap_max.resolution_divisor=4",
                            "lossy_own");
    const auto& s = run["summary"]["shadows"];
    EXPECT_EQ(s["own_mask_diff"], 0);
    EXPECT_EQ(s["unsafe_culls"], 0);
    EXPECT_GE(s["fill"].get<double>(), gl["summary"]["shadows"]["gl_fill"].get<double>()) << "a looser slab draws no less";
    EXPECT_GT(s["model_volumes"].get<int>(), 0);
  }
}

// Bad input for the model's own volumes: a trace of the caster rule is refused, naming why.
TEST(ShadowsModelVolumesTest, CasterRuleTraceRefused) {
  const fs::path t = capture("boxes", "clamped", "--clamp-rule caster");
  const fs::path dir = t.parent_path() / "caster_rule_run";
  const CliResult r = run_nbsim("replay " + t.string() + " --out " + dir.string() + " --set shadows.volumes=clamped");
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "clamp_rule caster") && has(r.err, "--clamp-rule edge")) << r.err;
}

// Lossy N-buffer designs (u16, divisor 2, level cap 2) stay conservative: no z_min above GL's, no
// z_max below, no caster culled that GL's values keep; the mask (GL's volumes) is unchanged.
TEST(ShadowsDesignTest, ReducedNBuffersStayConservative) {
  const fs::path t = capture("terrain", "clamped");
  const struct {
    const char* tag;
    const char* sets;
  } designs[] = {
      {"u16", " --set litmap_min.format=u16 --set litmap_max.format=u16"},
      {"div2", " --set litmap_min.resolution_divisor=2 --set litmap_max.resolution_divisor=2"},
      {"cap2", " --set litmap_min.level_cap=2 --set litmap_max.level_cap=2"},
  };
  for (const auto& d : designs) {
    SCOPED_TRACE(d.tag);
    const auto s = replay(t, d.sets, d.tag)["summary"]["shadows"];
    EXPECT_EQ(s["not_conservative"], 0);
    EXPECT_EQ(s["unsafe_culls"], 0) << "never culls a caster GL's values keep";
    EXPECT_EQ(s["mask_diff"], 0);
    EXPECT_LE(s["culled"].get<int>(), s["measured"].get<int>());
  }
  const auto u16 = replay(t, designs[0].sets, "u16b")["summary"]["shadows"];
  const auto full = replay(t)["summary"]["shadows"];
  EXPECT_LE(u16["culled"].get<int>(), full["culled"].get<int>()) << "a looser design culls no more";
}

void expect_refused(const fs::path& bad, const std::string& message) {
  const fs::path dir = bad.parent_path() / (bad.stem().string() + "_run");
  const CliResult r = run_nbsim("replay " + bad.string() + " --out " + dir.string());
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_TRUE(has(r.err, message)) << r.err;
  EXPECT_FALSE(fs::exists(dir / "run.json")) << "a refused replay leaves no run.json";
  const fs::path table = bad.parent_path() / (bad.stem().string() + "_table");
  const CliResult s = run_nbsim("shadows " + bad.string() + " --out " + table.string());
  EXPECT_EQ(s.status, 2) << s.out << s.err;
  EXPECT_FALSE(fs::exists(table / "shadows.json")) << "a refused table leaves no shadows.json";
}

// A caster naming a draw that is not a shadow volume: exit 2, frame and caster named.
TEST(ShadowsBadInputTest, DamagedCasterRecordRefused) {
  const fs::path good = capture("boxes", "clamped");
  const fs::path bad = scratch("bad_record.nbt");
  rewrite(good, bad, [](nbsim::scene::Frame& f) {
    for (auto& r : f.technique_records)
      for (auto& fl : r.fields)
        if (fl.name == "draw")
          if (auto* v = std::get_if<std::vector<std::int32_t>>(&fl.value)) (*v)[0] = 0;  // draw 0 is a scene draw
  });
  expect_refused(bad, "frame 1: caster 0 names draw 0, which is not a shadow_volume draw of the frame");
}

// A frame without its max litmap: exit 2 naming it.
TEST(ShadowsBadInputTest, MissingLitmapRefused) {
  const fs::path good = capture("boxes", "clamped");
  const fs::path bad = scratch("no_litmap.nbt");
  rewrite(good, bad, [](nbsim::scene::Frame& f) {
    std::erase_if(f.depths, [](const auto& d) { return d.name == "litmap_max"; });
  });
  expect_refused(bad, "frame 1: no 'litmap_max' depth image: the max N-buffer has nothing to be built from");
}

// A shadows trace cut anywhere (here: in its middle, and 40 bytes before its end): `replay` and
// `nbsim shadows` exit 2 with a message, and the replay leaves no run.json.
TEST(ShadowsBadInputTest, TruncatedTraceRefused) {
  const fs::path good = capture("boxes", "clamped");
  const auto size = fs::file_size(good);
  for (const std::uintmax_t keep : {size / 2, size - 40}) {
    SCOPED_TRACE(keep);
    const fs::path bad = scratch("truncated_" + std::to_string(keep) + ".nbt");
    fs::copy_file(good, bad, fs::copy_options::overwrite_existing);
    fs::resize_file(bad, keep);
    expect_refused(bad, "nbsim: error: ");
  }
}

// A mask pixel unlike the model's (GL's shadow_mask flipped at one lit pixel): the replay completes,
// the pixel is counted, and `nbsim shadows` exits 1.
TEST(ShadowsTableTest, MaskPixelDifferingExits1) {
  const fs::path good = capture("boxes", "clamped");
  const fs::path bad = scratch("flipped_mask.nbt");
  rewrite(good, bad, [](nbsim::scene::Frame& f) {
    const auto* region = f.stencil("light_region");
    for (auto& st : f.stencils)
      if (st.name == "shadow_mask")
        for (std::size_t i = 0; i < st.texels.size(); ++i)
          if (region->texels[i]) {
            st.texels[i] = st.texels[i] ? 0 : 1;
            return;
          }
  });
  const auto s = replay(bad)["summary"]["shadows"];
  EXPECT_EQ(s["mask_diff"], 1) << "one pixel of GL's mask flipped";
  EXPECT_EQ(s["mask_diff_infinite"], 0);
  const CliResult r = run_nbsim("shadows " + bad.string() + " --json");
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)[0]["mask_diff"], 1);
}

// `nbsim shadows --json`: a row per trace, the ratio to the trace's own reference fill.
TEST(ShadowsTableTest, JsonRowsWithRatioToInfinite) {
  const fs::path inf = capture("boxes", "infinite"), cl = capture("boxes", "clamped");
  const CliResult r = run_nbsim("shadows " + inf.string() + " " + cl.string() + " --json");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto rows = nlohmann::json::parse(r.out);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0]["shadow_mode"], "infinite");
  EXPECT_DOUBLE_EQ(rows[0]["ratio_to_infinite"].get<double>(), 1.0);
  EXPECT_EQ(rows[1]["shadow_mode"], "clamped");
  ASSERT_TRUE(rows[1]["ratio_to_infinite"].is_number());
  EXPECT_LE(rows[1]["ratio_to_infinite"].get<double>(), 1.0);
  EXPECT_EQ(rows[1]["ratio_reference"], "reference_fill");
  EXPECT_DOUBLE_EQ(rows[1]["ratio_to_infinite"].get<double>(),
                   rows[1]["fill_per_frame"].get<double>() / rows[0]["fill_per_frame"].get<double>())
      << "the reference pass's fill is the infinite capture's";
  EXPECT_EQ(rows[1]["mask_diff"], 0);
  EXPECT_EQ(rows[1]["draws_exact"], rows[1]["draws"]);
  const CliResult alone = run_nbsim("shadows " + cl.string() + " --json");
  ASSERT_EQ(alone.status, 0) << alone.err;
  EXPECT_EQ(nlohmann::json::parse(alone.out)[0]["ratio_to_infinite"], rows[1]["ratio_to_infinite"])
      << "the trace alone gives its ratio";
  const CliResult text = run_nbsim("shadows " + cl.string());
  EXPECT_EQ(text.status, 0);
  EXPECT_TRUE(has(text.out, "Shadows: fill per frame")) << text.out;
  // Where the fill goes: the rows by class and reason kept add up to the fill and to the infinite
  // volumes' fill, in both modes; the boxes scene's casters are all "box".
  for (const auto& row : rows) {
    double fill = 0.0, infinite = 0.0, casters = 0.0;
    for (const auto& b : row["fill_breakdown"]) {
      EXPECT_EQ(b["class"], "box");
      fill += b["fill_per_frame"].get<double>(), infinite += b["fill_infinite_per_frame"].get<double>();
      casters += b["casters_per_frame"].get<double>();
      if (b["kept"] == "dropped") {
        EXPECT_EQ(b["fill_per_frame"].get<double>(), row["shadow_mode"] == "infinite" ? b["fill_infinite_per_frame"].get<double>() : 0.0);
      }
    }
    EXPECT_NEAR(fill, row["fill_per_frame"].get<double>(), 1e-6 * fill) << row["shadow_mode"];
    EXPECT_NEAR(infinite, row["reference_fill_per_frame"].get<double>(), 1e-6 * infinite) << row["shadow_mode"];
    EXPECT_NEAR(casters, row["casters_per_frame"].get<double>(), 1e-9) << row["shadow_mode"];
  }
  const CliResult split = run_nbsim("shadows " + cl.string() + " --breakdown");
  EXPECT_EQ(split.status, 0);
  EXPECT_TRUE(has(split.out, "fill per frame by caster class and reason kept") && has(split.out, "box")) << split.out;
}

}  // namespace

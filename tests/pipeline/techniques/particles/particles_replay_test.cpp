// ParticlesReplayTest: fresh particles captures (128x96, every mode, sprites 16, 24 and attenuated,
// reversed Z) replayed by the particles program: every draw's fragments and passed samples equal
// GL's, the model's vertex-stage decisions equal GL's, no popping and no false cull for nb and hiz,
// popping for center, and nb's depth tests far below none's. A damaged PRTC record is refused.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <ostream>
#include <string>
#include <variant>

#include "tests/common/run_nbsim.h"
#include "traces/format/reader.h"
#include "traces/format/writer.h"

namespace {

namespace fs = std::filesystem;
using nbsim::testing::CliResult;
using nbsim::testing::has;
using nbsim::testing::run_nbsim;

fs::path scratch(const std::string& name) { return nbsim::testing::scratch_path("nbsim_particles_replay", name); }

// Captures a small walk (3 frames, 1500 particles) with `args` into `name`.
fs::path capture(const std::string& name, const std::string& args) {
  const fs::path t = scratch(name);
  const CliResult c = run_nbsim("capture particles --scene city --path walk --size 128x96 --frames 3 --objects 1500 "
                                "--particles 1500 " + args + " -o " + t.string());
  EXPECT_EQ(c.status, 0) << args << ": " << c.out << c.err;
  return t;
}

nlohmann::json replay(const fs::path& t) {
  const fs::path dir = t.parent_path() / (t.stem().string() + "_run");
  const CliResult r = run_nbsim("replay " + t.string() + " --out " + dir.string());
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  std::ifstream in(dir / "run.json");
  return nlohmann::json::parse(in);
}

// `nbsim compare`: every draw exact (fragments and passed samples equal GL's).
void expect_compare_exact(const fs::path& t) {
  const CliResult r = run_nbsim("compare " + t.string() + " --json");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["draws"].get<int>(), 0);
  EXPECT_EQ(j["draws_exact"], j["draws"]) << "every draw's fragments and passed samples equal GL's";
  EXPECT_EQ(j["fragments_model"], j["fragments_gl"]);
  EXPECT_EQ(j["passed_model"], j["passed_gl"]);
  ASSERT_TRUE(j.contains("particles")) << "compare shows the particles summary";
  EXPECT_EQ(j["particles"]["decision_mismatches"], 0) << "the model decided as GL's vertex shader";
  EXPECT_EQ(j["particles"]["lookup_mismatches"], 0) << "the model read as many texels as GL's vertex shader";
}

struct Variant {
  const char* name;
  const char* args;
  bool conservative;  // nb, hiz: no popping, no false cull
  bool all_kept = false;  // every on-screen sprite larger than the levels built
};

// How GoogleTest shows a Variant (GetParam() in a failure): its name and capture arguments.
void PrintTo(const Variant& v, std::ostream* os) {
  *os << v.name << " (capture particles " << v.args << (v.conservative ? ", conservative" : "")
      << (v.all_kept ? ", all kept" : "") << ")";
}

class ParticlesReplayTest : public ::testing::TestWithParam<Variant> {};

// Each mode and sprite: exact draws, GL's decisions, the mode's correctness.
TEST_P(ParticlesReplayTest, ReplaysExactlyAndDecidesAsGl) {
  const Variant& v = GetParam();
  const fs::path t = capture(std::string(v.name) + ".nbt", v.args);
  expect_compare_exact(t);
  const auto run = replay(t);
  const auto s = run["summary"]["particles"];
  EXPECT_EQ(s["frames"], 3);
  EXPECT_EQ(s["particles"], 4500);
  EXPECT_EQ(s["culled"], s["gl_culled"]);
  EXPECT_EQ(s["query_depth_tests"], s["gl_lookups"]) << "distinct texels read, as GL's shader counted them";
  EXPECT_EQ(s["total_depth_tests"].get<std::uint64_t>(),
            s["query_depth_tests"].get<std::uint64_t>() + s["raster_depth_tests"].get<std::uint64_t>() +
                s["build_texels"].get<std::uint64_t>());
  EXPECT_EQ(s["false_culls"], s["popping"]) << "the exact sprite test (GL's square against the depth buffer) agrees with "
                                               "GL's reference pass";
  std::uint64_t culled = 0, popping = 0;  // per frame: differences at frame ends
  for (const auto& f : run["frames"]) culled += f["culled"].get<std::uint64_t>(), popping += f["popping"].get<std::uint64_t>();
  EXPECT_EQ(culled, s["culled"].get<std::uint64_t>()) << "the frames' values add up to the run's";
  EXPECT_EQ(popping, s["popping"].get<std::uint64_t>());
  if (v.all_kept) {
    EXPECT_EQ(s["culled"], 0) << v.name;
    EXPECT_EQ(s["kept_too_large"], s["tested"].get<int>() + s["kept_too_large"].get<int>()) << "none tested";
    EXPECT_GT(s["kept_too_large"].get<int>(), 0) << v.name;
  }
  EXPECT_LE(s["culled_below_exact"].get<std::uint64_t>(), s["exactly_hidden"].get<std::uint64_t>());
  if (v.conservative) {
    EXPECT_GT(s["culled"].get<int>(), 0) << "the capture culls something";
    EXPECT_EQ(s["popping"], 0) << v.name << ": a conservative test never pops";
    EXPECT_EQ(s["false_culls"], 0) << v.name << ": nor culls a sprite with a passing pixel";
  }
}

INSTANTIATE_TEST_SUITE_P(Modes, ParticlesReplayTest,
                         ::testing::Values(Variant{"none16", "--sprite 16 --mode none", false},
                                           Variant{"center16", "--sprite 16 --mode center", false},
                                           Variant{"nb16", "--sprite 16 --mode nb", true},
                                           Variant{"hiz16", "--sprite 16 --mode hiz", true},
                                           Variant{"nb24", "--sprite 24 --mode nb", true},
                                           Variant{"nb_atten", "--sprite atten --mode nb", true},
                                           Variant{"hiz_atten", "--sprite atten --mode hiz", true},
                                           Variant{"nb16_reversed", "--sprite 16 --mode nb --reversed-z", true},
                                           Variant{"hiz24_reversed", "--sprite 24 --mode hiz --reversed-z", true},
                                           Variant{"nb16_cap3", "--sprite 16 --mode nb --level-cap 3", false, true}),
                         [](const auto& param_info) { return std::string(param_info.param.name); });

// The paper's claim, checked: with 16 px sprites nb spends far fewer depth tests than none, and
// center pops on the walk while nb does not.
TEST(ParticlesCostTest, NBufferCheaperThanRasterizingAndCenterPops) {
  const auto none = replay(capture("cost_none.nbt", "--sprite 16 --mode none"))["summary"]["particles"];
  const auto nb = replay(capture("cost_nb.nbt", "--sprite 16 --mode nb"))["summary"]["particles"];
  const auto center = replay(capture("cost_center.nbt", "--sprite 16 --mode center"))["summary"]["particles"];
  EXPECT_EQ(none["culled"], 0);
  EXPECT_EQ(none["query_depth_tests"], 0);
  EXPECT_EQ(none["culled_below_exact"], none["exactly_hidden"]) << "none keeps every hidden sprite";
  EXPECT_LE(100 * nb["culled_below_exact"].get<std::uint64_t>(), nb["exactly_hidden"].get<std::uint64_t>())
      << "16 px sprites: one exact square each; only ties (a 17 px rectangle) and the margin keep a hidden one";
  EXPECT_LT(nb["raster_depth_tests"].get<double>(), 0.5 * none["raster_depth_tests"].get<double>())
      << "nb rasterizes only what it keeps";
  EXPECT_LT(nb["query_depth_tests"].get<double>(), 0.1 * none["raster_depth_tests"].get<double>())
      << "at most one lookup a 16 px sprite, against up to 256 fragments";
  EXPECT_GT(center["popping"].get<int>(), 0) << "the centre-only test pops at silhouettes";
  EXPECT_EQ(nb["popping"], 0);
}

nlohmann::json replay_set(const fs::path& t, const std::string& name, const std::string& set) {
  const fs::path dir = scratch(name);
  const CliResult r = run_nbsim("replay " + t.string() + " --out " + dir.string() + " --set " + set);
  EXPECT_EQ(r.status, 0) << set << ": " << r.out << r.err;
  std::ifstream in(dir / "run.json");
  return nlohmann::json::parse(in)["summary"]["particles"];
}

// particles.mode: a `none` capture (every sprite drawn at its own clip position) replayed as
// center, nb and hiz decides, culls and rasterizes exactly as the replay of that mode's own
// capture of the same walk (GL's draws there); the other way, a capture replayed as none draws the
// sprites GL culled again from their window positions and rasterizes what the none capture drew.
TEST(ParticlesModeTest, NoneCaptureReplaysAsEveryMode) {
  for (const char* sprite : {"16", "atten"}) {
    const std::string s(sprite);
    const fs::path none = capture("mode_none_" + s + ".nbt", "--sprite " + s + " --mode none");
    const auto base = replay(none)["summary"]["particles"];
    for (const char* mode : {"center", "nb", "hiz"}) {
      const std::string m(mode);
      const fs::path own = capture("mode_" + m + "_" + s + ".nbt", "--sprite " + s + " --mode " + m);
      const auto want = replay(own)["summary"]["particles"];
      const auto got = replay_set(none, "mode_" + m + "_" + s + "_as", "particles.mode=" + m);
      EXPECT_EQ(got["mode"], m);
      EXPECT_EQ(got["capture_mode"], "none");
      for (const char* k : {"culled", "tested", "kept_too_large", "query_depth_tests", "raster_depth_tests", "raster_passed",
                            "popping", "false_culls", "exactly_hidden"})
        EXPECT_EQ(got[k], want[k]) << m << " " << s << ": " << k;
      EXPECT_EQ(got["redrawn"], 0) << "a none capture holds every sprite's own clip position";
      EXPECT_EQ(got["dropped"], got["culled"]) << "what the model culls is left out of GL's draws";
      EXPECT_EQ(want["own_draws"], 0) << "in its own mode the model issues GL's draws";
      const auto back = replay_set(own, "mode_" + m + "_" + s + "_as_none", "particles.mode=none");
      EXPECT_EQ(back["culled"], 0);
      EXPECT_EQ(back["redrawn"], want["culled"]);
      EXPECT_EQ(back["raster_depth_tests"], base["raster_depth_tests"]) << m << " " << s << " replayed as none";
    }
  }
  const CliResult bad = run_nbsim("compare " + scratch("mode_none_16.nbt").string() + " --set particles.mode=zbuffer");
  EXPECT_EQ(bad.status, 2) << bad.out << bad.err;
  EXPECT_TRUE(has(bad.err, "particles.mode")) << bad.err;
}

// The N-buffer unit's keys apply: every update policy decides as GL's shader (only the build cost
// moves), u16 storage and a reduced resolution stay conservative, and cull.mode is refused.
TEST(ParticlesCostTest, NBufferKeysApply) {
  const fs::path t = capture("keys.nbt", "--sprite 16 --mode nb");
  const auto replay_with = [&](const std::string& name, const std::string& set) { return replay_set(t, "keys_" + name, set); };
  for (const char* policy : {"eager", "batched", "lazy"}) {
    const auto s = replay_with(policy, std::string("nbuffer.update_policy=") + policy);
    EXPECT_EQ(s["decision_mismatches"], 0) << policy;
    EXPECT_GT(s["build_texels"].get<int>(), 0) << policy << ": the partial build is counted";
  }
  for (const char* set : {"nbuffer.format=u16", "nbuffer.resolution_divisor=2"}) {
    const auto s = replay_with(set[8] == 'f' ? "u16" : "div2", set);
    EXPECT_EQ(s["popping"], 0) << set;
    EXPECT_EQ(s["false_culls"], 0) << set;
  }
  const CliResult refused = run_nbsim("compare " + t.string() + " --set cull.mode=nb");
  EXPECT_EQ(refused.status, 2) << refused.out << refused.err;
  EXPECT_TRUE(has(refused.err, "cull.mode=nb culls with the programs occlusion_culling and ")) << refused.err;
}

// `nbsim particles`: one row per trace from its replay's /summary/particles, the paper's claim
// beside none and nb for 16 px sprites; a trace of another technique is refused.
TEST(ParticlesCostTest, TableCommand) {
  const fs::path none = capture("table_none.nbt", "--sprite 16 --mode none");
  const fs::path nb = capture("table_nb.nbt", "--sprite 16 --mode nb");
  const fs::path dir = scratch("table_out");
  const CliResult r = run_nbsim("particles " + none.string() + " " + nb.string() + " --json --out " + dir.string());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto rows = nlohmann::json::parse(r.out);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0]["mode"], "none");
  EXPECT_EQ(rows[0]["paper_depth_tests_per_frame"].get<double>(), 256.0 * 1500.0);
  EXPECT_EQ(rows[1]["mode"], "nb");
  EXPECT_EQ(rows[1]["paper_depth_tests_per_frame"].get<double>(), 1500.0);
  EXPECT_EQ(rows[1]["popping"], 0);
  EXPECT_TRUE(fs::exists(dir / "particles.json"));
  EXPECT_EQ(rows[0]["settings"], nlohmann::json::array()) << "the run's --set options are recorded (none here)";
  EXPECT_EQ(rows[0]["capture_mode"], "none");
  // --set options land in every row; particles.mode replays the none capture as nb
  const CliResult as_nb = run_nbsim("particles " + none.string() + " --json --set particles.mode=nb");
  ASSERT_EQ(as_nb.status, 0) << as_nb.out << as_nb.err;
  const auto nb_rows = nlohmann::json::parse(as_nb.out);
  EXPECT_EQ(nb_rows[0]["mode"], "nb");
  EXPECT_EQ(nb_rows[0]["capture_mode"], "none");
  EXPECT_EQ(nb_rows[0]["settings"], nlohmann::json::array({"particles.mode=nb"}));
  EXPECT_EQ(nb_rows[0]["paper_depth_tests_per_frame"].get<double>(), 1500.0) << "the paper's claim follows the mode replayed";
  const CliResult text = run_nbsim("particles " + nb.string());
  EXPECT_EQ(text.status, 0) << text.err;
  EXPECT_TRUE(has(text.out, "256 N by rasterization, N with the N-buffer")) << text.out;
  const fs::path other = scratch("other.nbt");
  {
    nbsim::trace::TraceWriter w(other, {{"viewport", "8x8"}, {"depth_func", "LESS"}, {"depth_clear", "1"},
                                        {"technique", "occlusion_culling"}, {"frames", "0"}});
    w.close();
  }
  const CliResult refused = run_nbsim("particles " + other.string());
  EXPECT_EQ(refused.status, 2) << refused.out << refused.err;
  EXPECT_TRUE(has(refused.err, "is not a particles trace")) << refused.err;
}

// A PRTC record whose count does not match the particle draws' points: exit 2, the frame and the
// count named, no run.json.
TEST(ParticlesCostTest, DamagedRecordRefused) {
  const fs::path good = capture("good.nbt", "--sprite 16 --mode nb");
  const fs::path bad = scratch("bad.nbt");
  {
    nbsim::trace::FrameReader in(good);
    nbsim::trace::TraceWriter w(bad, in.trace().properties());
    if (in.trace().scene()) w.write(*in.trace().scene());
    while (auto f = in.next()) {
      w.begin_frame(f->begin);
      for (const auto& d : f->draws) w.write(d);
      for (const auto& d : f->depths) w.write(d);
      for (const auto& l : f->levels) w.write(l);
      for (auto r : f->technique_records) {
        if (f->ordinal == 1)  // one particle fewer in every field: consistent, but not the draws' points
          for (auto& fl : r.fields) {
            if (auto* c = std::get_if<std::uint64_t>(&fl.value)) --*c;
            if (auto* u = std::get_if<std::vector<std::uint32_t>>(&fl.value)) u->pop_back();
            if (auto* x = std::get_if<std::vector<float>>(&fl.value)) x->pop_back();
          }
        w.write(r);
      }
      if (f->truth) w.write(*f->truth);
      w.end_frame(f->end);
    }
    w.close();
  }
  const fs::path dir = scratch("bad_run");
  const CliResult r = run_nbsim("replay " + bad.string() + " --out " + dir.string());
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "frame 1: the ParticleCulling record's count is 1499, but the frame's particle draws hold 1500 points"))
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "run.json")) << "a refused replay leaves no run.json";
  const CliResult c = run_nbsim("compare " + bad.string());
  EXPECT_EQ(c.status, 2) << c.out << c.err;
}

// The committed sample (scripts/make_samples: 256x256, 16 frames, 10,000 sprites of 16 px, mode
// nb): every draw exact, the model decides as GL's shader, conservative, and `nbsim particles` runs
// on it with the paper's claim (N depth tests for N sprites) beside it.
TEST(ParticlesSampleTest, SampleReplaysExactlyAndRunsTheTable) {
  const fs::path t = fs::path(NBSIM_SAMPLES) / "particles_walk_256.nbt";
  ASSERT_TRUE(fs::exists(t)) << t << " missing: run scripts/make_samples";
  expect_compare_exact(t);
  const CliResult r = run_nbsim("particles " + t.string() + " --json");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto rows = nlohmann::json::parse(r.out);
  ASSERT_EQ(rows.size(), 1u);
  const auto& row = rows[0];
  EXPECT_EQ(row["mode"], "nb");
  EXPECT_EQ(row["sprite"], "16");
  EXPECT_EQ(row["particles_per_frame"].get<double>(), 10000.0);
  EXPECT_EQ(row["paper_depth_tests_per_frame"].get<double>(), 10000.0) << "the paper: N depth tests with the N-buffer";
  EXPECT_EQ(row["popping"], 0) << "nb never pops";
  EXPECT_EQ(row["false_culls"], 0);
  EXPECT_EQ(row["decision_mismatches"], 0);
  EXPECT_GT(row["culled_per_frame"].get<double>(), 0.0) << "the walk hides sprites behind buildings";
  EXPECT_LE(row["query_depth_tests_per_frame"].get<double>(), 4 * 10000.0) << "at most four lookups a sprite (one unless a tie widens it)";
}

}  // namespace

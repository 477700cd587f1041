// LdiReplayTest: the ldi program through `nbsim compare` on traces written by the trace writer
// from hand-made frames (tests/model/ldi/hand_frame.h; no GL capture of the technique exists on
// this branch): the program is chosen by technique=ldi, its counters reach the JSON summary, a
// GL counter changed in the file is counted, and a damaged LDIL is refused with exit 2.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "model/mesh/shapes.h"
#include "tests/common/run_nbsim.h"
#include "tests/model/ldi/hand_frame.h"
#include "traces/format/writer.h"

namespace {

namespace fs = std::filesystem;
using nbsim::testing::CliResult;
using nbsim::testing::has;
using nbsim::testing::run_nbsim;
namespace ldi = nbsim::ldi;

fs::path scratch(const std::string& name) { return nbsim::testing::scratch_path("nbsim_ldi_replay", name); }

// Writes `frames` hand-made frames of a box (frame 1 a nested-shells shape) at 16x16; `edit`
// changes each frame before it is written.
template <class Edit>
fs::path write_trace(const std::string& name, Edit edit) {
  const fs::path t = scratch(name);
  nbsim::mesh::TriMesh nested = nbsim::mesh::make_nested_shells({2, 9, 12});
  nbsim::mesh::normalize_to_unit_cube(nested, 0.05);
  nbsim::trace::TraceWriter w(t, {{"viewport", "16x16"}, {"depth_func", "LESS"}, {"depth_clear", "1"}, {"technique", "ldi"},
                                  {"shape", "box"}, {"frames", "2"}});
  for (std::uint32_t i = 0; i < 2; ++i) {
    nbsim::scene::Frame f = ldi::testing::make_frame(i == 0 ? nbsim::mesh::make_box(0.2f, 0.8f) : nested, 16, 16, i);
    edit(f);
    w.begin_frame(f.begin);
    for (const auto& d : f.draws) w.write(d);
    for (const auto& r : f.technique_records) w.write(r);
    w.end_frame(f.end);
  }
  w.close();
  return t;
}

// technique=ldi picks the ldi program: the peel, the LDI and the parity tests agree with the
// (self-consistent) records, and the summary holds the program's fields.
TEST(LdiReplayTest, CompareReportsTheProgramsCounters) {
  const fs::path t = write_trace("consistent.nbt", [](nbsim::scene::Frame&) {});
  const CliResult r = run_nbsim("compare " + t.string() + " --json");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.contains("ldi")) << r.out;
  const auto& l = j["ldi"];
  for (const char* name : {"peel_passes", "peel_fragments", "gl_peel_fragments", "peel_samples", "gl_peel_samples", "peel_pass_mismatches",
                           "layer_texel_mismatches", "crop_mismatch", "compressed_mismatches", "test_points", "parity_mismatches_layers",
                           "parity_mismatches_ranges", "fetch_mismatches_layers", "fetch_mismatches_ranges", "fetches_layers",
                           "fetches_ranges", "misclassified_layers", "misclassified_ranges", "classified_points", "near_surface_points",
                           "cycles"})
    EXPECT_TRUE(l.contains(name)) << "summary field " << name;
  EXPECT_EQ(l["frames"], 2);
  EXPECT_EQ(l["peel_passes"], 3 + 5) << "box: 2 layers + the empty pass; two nested shells: 4 + 1";
  EXPECT_EQ(l["peel_fragments"], l["gl_peel_fragments"]);
  EXPECT_EQ(l["peel_samples"], l["gl_peel_samples"]);
  EXPECT_EQ(l["peel_pass_mismatches"], 0);
  EXPECT_EQ(l["layer_texel_mismatches"], 0);
  EXPECT_EQ(l["compressed_mismatches"], 0);
  EXPECT_EQ(l["parity_mismatches_layers"], 0);
  EXPECT_EQ(l["fetch_mismatches_ranges"], 0);
  EXPECT_GT(l["test_points"].get<int>(), 100);
  EXPECT_GT(l["cycles"].get<std::uint64_t>(), 0u);
  EXPECT_GT(l["memory_bytes"].get<std::uint64_t>(), 0u) << "the LDI's memory client moved bytes";
  EXPECT_EQ(l["memory_bytes"], l["peel_bytes"].get<std::uint64_t>() + l["vpt_bytes"].get<std::uint64_t>());
  EXPECT_TRUE(j["within_thresholds"].get<bool>());
}

// A GL peel counter changed in the file is a mismatch and puts compare outside its thresholds.
TEST(LdiReplayTest, ChangedGlCounterIsCounted) {
  const fs::path t = write_trace("counter.nbt", [](nbsim::scene::Frame& f) { f.draws[0].gl.fragments += 3; });
  const CliResult r = run_nbsim("compare " + t.string() + " --json");
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["ldi"]["peel_pass_mismatches"], 2);
  EXPECT_EQ(j["ldi"]["gl_peel_fragments"].get<std::uint64_t>(), j["ldi"]["peel_fragments"].get<std::uint64_t>() + 6);
}

// A compressed texture that does not decompress to GL's layers: exit 2, the frame named.
TEST(LdiReplayTest, DamagedCompressedTextureIsRefused) {
  const fs::path t = write_trace("damaged.nbt", [](nbsim::scene::Frame& f) {
    if (f.begin.frame != 1) return;
    auto& c = std::get<std::vector<std::uint32_t>>(ldi::testing::field_of(f, ldi::kLdiImageRecordType, "compressed").value);
    c[c.size() / 2] ^= 0x10u;
  });
  const CliResult r = run_nbsim("compare " + t.string() + " --json");
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "frame 1")) << r.err;
  EXPECT_TRUE(has(r.err, "compressed")) << r.err;
}

// The "ldi." keys are declared and checked.
TEST(LdiReplayTest, ConfigKeysAreDeclaredAndChecked) {
  const CliResult list = run_nbsim("config");
  ASSERT_EQ(list.status, 0) << list.err;
  for (const char* key : {"ldi.setup_triangles_per_cycle", "ldi.blocks_per_cycle", "ldi.tests_per_cycle", "ldi.pass_latency_cycles",
                          "ldi.vpt_cycles_per_point", "ldi.vpt_latency_cycles"})
    EXPECT_TRUE(has(list.out, key)) << key;
  const fs::path t = write_trace("config.nbt", [](nbsim::scene::Frame&) {});
  const CliResult bad = run_nbsim("compare " + t.string() + " --set ldi.tests_per_cycle=0");
  EXPECT_EQ(bad.status, 2) << bad.out << bad.err;
  // Slower fragment lanes: the same counts, more cycles.
  const CliResult a = run_nbsim("compare " + t.string() + " --json");
  const CliResult b = run_nbsim("compare " + t.string() + " --json --set ldi.tests_per_cycle=0.5");
  ASSERT_EQ(a.status, 0) << a.err;
  ASSERT_EQ(b.status, 0) << b.err;
  const auto ja = nlohmann::json::parse(a.out)["ldi"], jb = nlohmann::json::parse(b.out)["ldi"];
  EXPECT_EQ(ja["peel_fragments"], jb["peel_fragments"]);
  EXPECT_GT(jb["peel_cycles"].get<std::uint64_t>(), ja["peel_cycles"].get<std::uint64_t>());
}

}  // namespace

// ReplayCliTest: `nbsim replay`, `nbsim compare` and `nbsim config` from the outside: the counter
// comparison passes on the sample traces and on a fresh capture, unit latencies change cycles but
// not depth-test counts, and bad configs are refused.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>
#include <string>

#include "tests/common/run_nbsim.h"
#include "traces/format/codec.h"
#include "traces/format/reader.h"
#include "traces/format/writer.h"

namespace {

namespace fs = std::filesystem;
using nbsim::testing::CliResult;
using nbsim::testing::has;
using nbsim::testing::run_nbsim;

fs::path scratch(const std::string& name) { return nbsim::testing::scratch_path("nbsim_replay", name); }

std::string sample(const char* name) { return (fs::path(NBSIM_SAMPLES) / name).string(); }

nlohmann::json read_json(const fs::path& f) {
  std::ifstream in(f);
  return nlohmann::json::parse(in);
}

// The model's fragments, passed samples and depth match GL on every sample trace.
TEST(ReplayCliTest, CompareSamplesWithinThresholds) {
  for (const char* s : {"city_small_oq.nbt", "city_small_nb_reversed.nbt", "city_walk_512.nbt"}) {
    const CliResult r = run_nbsim("compare " + sample(s) + " --json");
    ASSERT_EQ(r.status, 0) << s << ": " << r.out << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_TRUE(j["within_thresholds"].get<bool>()) << s;
    EXPECT_GT(j["draws"].get<long>(), 0) << s;
    EXPECT_EQ(j["fragments_model"], j["fragments_gl"]) << s;
    EXPECT_EQ(j["passed_model"], j["passed_gl"]) << s;
    EXPECT_EQ(j["depth_pixels_matching"], j["depth_pixels"]) << s;
  }
}

// A fresh capture on this machine's Mesa compares within the thresholds too (flyover, flat queries).
TEST(ReplayCliTest, CompareFreshCapture) {
  const fs::path t = scratch("fresh.nbt");
  const CliResult c = run_nbsim("capture occlusion_culling --scene city --size 96x80 --frames 3 --objects 700 --path fly --mode oq_hier -o " + t.string());
  ASSERT_EQ(c.status, 0) << c.out << c.err;
  const CliResult r = run_nbsim("compare " + t.string());
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "within the thresholds")) << r.out;
}

// Changing a unit's latency changes the cycles but not one depth-test count.
TEST(ReplayCliTest, LatencyChangesCyclesNotCounts) {
  const std::string t = sample("city_small_oq.nbt");
  const fs::path a = scratch("base"), b = scratch("slow");
  ASSERT_EQ(run_nbsim("replay " + t + " --out " + a.string()).status, 0);
  const CliResult r = run_nbsim("replay " + t + " --out " + b.string() +
                                " --set depth.latency_cycles=400 --set geometry.latency_cycles=300 --set memory.latency_cycles=900");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto ja = read_json(a / "run.json"), jb = read_json(b / "run.json");
  EXPECT_GT(jb["summary"]["cycles"].get<long>(), ja["summary"]["cycles"].get<long>()) << "longer latencies, more cycles";
  EXPECT_EQ(ja["summary"]["depth_tests"], jb["summary"]["depth_tests"]);
  EXPECT_EQ(ja["summary"]["fragments_model"], jb["summary"]["fragments_model"]);
  EXPECT_EQ(ja["summary"]["passed_model"], jb["summary"]["passed_model"]);
  EXPECT_EQ(jb["config"]["depth"]["latency_cycles"], 400) << "run.json records the config used";
  std::ifstream draws(b / "draws.csv");
  std::string header;
  std::getline(draws, header);
  EXPECT_TRUE(has(header, "frame,draw,object,role") && has(header, "model_fragments,gl_fragments")) << header;
}

// config --defaults lists every key; bad keys and values are refused with exit 2.
TEST(ReplayCliTest, ConfigKeysAndRefusals) {
  const CliResult d = run_nbsim("config --defaults --json");
  ASSERT_EQ(d.status, 0) << d.err;
  const auto keys = nlohmann::json::parse(d.out);
  ASSERT_GT(keys.size(), 10u);
  for (const auto& k : keys) {
    EXPECT_FALSE(k["description"].get<std::string>().empty()) << k["key"];
  }
  const std::string t = sample("city_small_oq.nbt");
  struct Row { std::string args, message; };
  const Row rows[] = {
      {"--set depth.latency_cycle=3", "did you mean 'depth.latency_cycles'"},
      {"--set depth.latency_cycles=-5", "outside its limits"},
      {"--config /nonexistent.json", "cannot be read"},
  };
  for (const Row& row : rows) {
    const CliResult r = run_nbsim("compare " + t + " " + row.args);
    EXPECT_EQ(r.status, 2) << row.args << ": " << r.err;
    EXPECT_TRUE(has(r.err, row.message)) << row.args << ": " << r.err;
  }
  const fs::path bad = scratch("bad.json");
  std::ofstream(bad) << R"({"depth": {"tests_per_cycle": "fast"}})";
  const CliResult r = run_nbsim("compare " + t + " --config " + bad.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "must be a number")) << r.err;
}

// The storage of every option of `nbsim config` outlives parsing: valgrind sees no write into freed
// memory (a flag such as --defaults bound to a shared_ptr that its callback does not capture would
// write into freed memory). In the sanitizer build (scripts/sanitize sets NBSIM_SANITIZED) ASan
// watches the same run itself, and valgrind cannot run an ASan executable.
TEST(ReplayCliTest, ConfigFlagsWriteLiveMemory) {
  const bool sanitized = std::getenv("NBSIM_SANITIZED") != nullptr;
  if (!sanitized && !fs::exists("/usr/bin/valgrind")) GTEST_SKIP() << "valgrind is not installed (apt-get install valgrind)";
  const CliResult r =
      nbsim::testing::run_nbsim_env(sanitized ? "" : "/usr/bin/valgrind -q --error-exitcode=99 ", "config --defaults --json");
  EXPECT_EQ(r.status, 0) << r.err.substr(0, 2000);
  EXPECT_FALSE(has(r.err, "Invalid write")) << r.err.substr(0, 2000);
}

// Config files and --set values the JSON library cannot take, or that break a limit, exit 2 with a
// message naming the problem (never exit 1 with a library exception, a crash, or a silent cut).
TEST(ReplayCliTest, BadConfigInputsRefused) {
  const std::string t = sample("city_small_oq.nbt");
  const fs::path dup = scratch("dup.json"), nul = scratch("nul.json"), deep = scratch("deep.json"), dir = scratch("config_dir");
  std::ofstream(dup) << R"({"depth": {"latency_cycles": 3, "latency_cycles": 4}})";
  std::ofstream(nul, std::ios::binary) << std::string(R"({"depth": {"latency_cycles": 3}})") + '\0' + R"(, "x": 1)";
  std::ofstream(deep) << R"({"depth": {"latency_cycles": )" << std::string(10000, '[') << std::string(10000, ']') << "}}";
  fs::create_directories(dir);
  struct Row { std::string args, message; };
  const Row rows[] = {
      {"--config " + dup.string(), "gives the key \"latency_cycles\" twice"},
      {"--config " + nul.string(), "NUL byte at offset 32"},
      {"--config " + deep.string(), "deeper than 64 levels"},
      {"--config " + dir.string(), "is a directory"},
      {"--set 'depth.latency_cycles=" + std::string(20000, '[') + std::string(20000, ']') + "'", "deeper than 64 levels"},
      {"--set \"$(printf 'cull.mode=\\377')\"", "not valid UTF-8"},
      {"--set \"$(printf 'depth.latency_cycles=\\042\\376\\042')\"", "not valid UTF-8"},
  };
  for (const Row& row : rows) {
    const CliResult r = run_nbsim("compare " + t + " " + row.args);
    EXPECT_EQ(r.status, 2) << row.args.substr(0, 200) << ": " << r.err;
    EXPECT_TRUE(has(r.err, row.message)) << row.args.substr(0, 200) << ": " << r.err;
    EXPECT_LT(r.err.size(), 1000u) << "a message, not a dump";
  }
}

// In a culling mode, culls.csv lists every bounds test with its decision, cost and ground truth;
// the N-buffer compares at most four texels a test and culls nothing visible.
// Bounds that cross the near plane are never culled, in any mode.
TEST(ReplayCliTest, CullModeWritesEveryBoundsTest) {
  for (const char* mode : {"nb", "oq", "hiz_pyramid"}) {
  const fs::path out = scratch(mode);
  const CliResult r = run_nbsim("replay " + sample("city_small_oq.nbt") + " --set cull.mode=" + mode + " --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream csv(out / "culls.csv");
  std::string line;
  std::getline(csv, line);
  ASSERT_TRUE(has(line, "decision,depth_tests,truth_visible_pixels,false_cull")) << line;
  int rows = 0, culled = 0, near = 0;
  while (std::getline(csv, line)) {
    ++rows;
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
    ASSERT_EQ(f.size(), 14u) << line;
    EXPECT_EQ(f[1], mode);
    if (std::string(mode) == "nb") {
      EXPECT_LE(std::stoi(f[11]), 4) << "at most four lookups: " << line;
    }
    EXPECT_EQ(f[13], "0") << "false cull: " << line;
    if (f[9] == "1") {
      EXPECT_EQ(f[10], "visible") << "bounds crossing the near plane were culled: " << line;
    }
    culled += f[10] == "culled";
    near += f[9] == "1";
  }
  EXPECT_GT(rows, 100) << mode;
  EXPECT_GT(culled, 0) << mode << " culled nothing";
  EXPECT_GT(near, 0) << "the sample has bounds crossing the near plane (the ground)";
  }
}

// A trace whose frames have no draws replays to zero counts, not a crash or a hang.
TEST(ReplayCliTest, EmptyFramesReplay) {
  const fs::path t = scratch("empty.nbt");
  {
    nbsim::trace::TraceWriter w(t, {{"viewport", "8x8"}, {"depth_func", "LESS"}, {"depth_clear", "1"}, {"frames", "2"}});
    for (std::uint32_t f = 0; f < 2; ++f) {
      nbsim::trace::FrameBegin b;
      b.frame = f;
      w.begin_frame(b);
      nbsim::trace::FrameEnd e;
      e.frame = f;
      w.end_frame(e);
    }
    w.close();
  }
  const CliResult r = run_nbsim("compare " + t.string() + " --json");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["frames"], 2);
  EXPECT_EQ(j["draws"], 0);
  EXPECT_TRUE(j["within_thresholds"].get<bool>());
}

// The frame program comes from the trace's technique (pipeline/sim/programs.h): a technique
// without a program replays its recorded draws, and a config that asks to cull it is refused.
TEST(ReplayCliTest, ProgramChosenByTechnique) {
  const fs::path t = scratch("other_technique.nbt");
  {
    nbsim::trace::TraceWriter w(t, {{"viewport", "8x8"}, {"depth_func", "LESS"}, {"depth_clear", "1"},
                                    {"technique", "no_such_technique"}, {"frames", "1"}});
    nbsim::trace::FrameBegin b;
    w.begin_frame(b);
    nbsim::trace::FrameEnd e;
    w.end_frame(e);
    w.close();
  }
  const CliResult replayed = run_nbsim("compare " + t.string() + " --json");
  EXPECT_EQ(replayed.status, 0) << replayed.out << replayed.err;
  const CliResult culled = run_nbsim("compare " + t.string() + " --set cull.mode=nb");
  EXPECT_EQ(culled.status, 2) << culled.out << culled.err;
  EXPECT_TRUE(has(culled.err, "the trace's technique is 'no_such_technique'")) << culled.err;
  EXPECT_TRUE(has(culled.err, "programs exist for: occlusion_culling")) << culled.err;
}


// gpu.program=off runs no technique program, whatever the technique: the recorded draws replay
// through the generic units, run.json holds no technique summary, and a trace whose GL draws a
// program models beyond them (relief's shader discards the missed rays) no longer matches GL. A
// cull.mode that asks to cull is refused with it.
TEST(ReplayCliTest, ProgramOffReplaysTheRecordedDraws) {
  const fs::path out = scratch("program_off");
  const CliResult particles = run_nbsim("replay " + sample("particles_walk_256.nbt") + " --out " + out.string() + " --set gpu.program=off");
  ASSERT_EQ(particles.status, 0) << particles.out << particles.err;
  const nlohmann::json run = read_json(out / "run.json");
  EXPECT_FALSE(run["summary"].contains("particles")) << "no particles program ran";
  EXPECT_TRUE(run["summary"]["within_thresholds"].get<bool>()) << "the particle draws GL kept replay exactly";
  const CliResult on = run_nbsim("compare " + sample("particles_walk_256.nbt") + " --json");
  ASSERT_EQ(on.status, 0) << on.err;
  EXPECT_TRUE(nlohmann::json::parse(on.out).contains("particles")) << "auto runs the particles program";

  const CliResult relief = run_nbsim("compare " + sample("relief_fbm_64.nbt") + " --json --set gpu.program=off");
  EXPECT_EQ(relief.status, 1) << relief.out << relief.err;
  const nlohmann::json j = nlohmann::json::parse(relief.out);
  EXPECT_FALSE(j["within_thresholds"].get<bool>());
  EXPECT_FALSE(j.contains("relief"));
  // Without the walks' discards every fragment of a frame's first box passes and writes the box's
  // depth, which then hides the other methods' boxes (each started from the restored depth in GL).
  EXPECT_NE(j["passed_model"].get<long>(), j["passed_gl"].get<long>()) << "the generic replay cannot know which rays hit";

  const CliResult refused = run_nbsim("compare " + sample("city_small_oq.nbt") + " --set gpu.program=off --set cull.mode=nb");
  EXPECT_EQ(refused.status, 2) << refused.out << refused.err;
  EXPECT_TRUE(has(refused.err, "gpu.program=off runs no program, but cull.mode=nb")) << refused.err;
  const CliResult bad = run_nbsim("compare " + sample("city_small_oq.nbt") + " --set gpu.program=sometimes");
  EXPECT_EQ(bad.status, 2) << bad.err;
  EXPECT_TRUE(has(bad.err, "gpu.program")) << bad.err;
}
// relief.score=false (the bench's replay) leaves out the exact reference: the hit-error counts are
// null, not 0, every other count is the scored replay's, and the relief table refuses the run.
TEST(ReplayCliTest, ReliefUnscoredReplayNullsTheHitErrors) {
  const CliResult scored = run_nbsim("compare " + sample("relief_fbm_64.nbt") + " --json");
  ASSERT_EQ(scored.status, 0) << scored.err;
  const CliResult unscored = run_nbsim("compare " + sample("relief_fbm_64.nbt") + " --json --set relief.score=false");
  ASSERT_EQ(unscored.status, 0) << unscored.err;
  const nlohmann::json a = nlohmann::json::parse(scored.out)["relief"], b = nlohmann::json::parse(unscored.out)["relief"];
  EXPECT_TRUE(a["errors"].is_number());
  EXPECT_TRUE(b["errors"].is_null());
  EXPECT_TRUE(b["error_rate"].is_null());
  EXPECT_EQ(a["cycles"], b["cycles"]);
  EXPECT_EQ(a["cache_misses"], b["cache_misses"]);
  for (const auto& [method, m] : a["methods"].items()) {
    const nlohmann::json& u = b["methods"][method];
    for (const char* k : {"reference_hits", "wrong_hit", "wrong_miss", "far_hit", "errors", "error_rate", "mean_hit_distance"})
      EXPECT_TRUE(u[k].is_null()) << method << " " << k;
    for (const char* k : {"fragments", "samples", "lookups", "steps", "bisections", "hits", "cycles", "walk_mismatches", "pixel_mismatches"})
      EXPECT_EQ(u[k], m[k]) << method << " " << k;
  }
  const fs::path out = scratch("relief_unscored");
  ASSERT_EQ(run_nbsim("replay " + sample("relief_fbm_64.nbt") + " --out " + out.string() + " --set relief.score=false").status, 0);
  const nlohmann::json run = read_json(out / "run.json");
  for (const auto& [method, v] : run["frames"][0]["relief"].items()) {
    EXPECT_TRUE(v["errors"].is_null()) << method;
    EXPECT_TRUE(v["fragments"].is_number()) << method;
  }
}

// A damaged trace is refused by replay with exit 2 and the chunk named.
TEST(ReplayCliTest, RefusesDamagedTrace) {
  const fs::path t = scratch("damaged.nbt");
  fs::copy_file(sample("city_small_oq.nbt"), t, fs::copy_options::overwrite_existing);
  fs::resize_file(t, fs::file_size(t) / 2);
  const CliResult r = run_nbsim("compare " + t.string());
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "chunk")) << r.err;
}

// A header value that is not UTF-8 is refused by replay with exit 2 naming the key, before any
// output is written (not an exception from the JSON library and an empty run.json).
TEST(ReplayCliTest, RefusesNonUtf8HeaderWithoutOutput) {
  namespace tr = nbsim::trace;
  const fs::path t = scratch("latin1.nbt");
  {
    std::vector<std::uint8_t> b;
    const auto pre = tr::encode_preamble(tr::kFormatVersion);
    b.assign(pre.begin(), pre.end());
    for (const auto& c : {tr::encode_chunk(tr::ChunkType::Header, tr::encode(tr::Properties{{"viewport", "8x8"}, {"scene", "caf\xe9"}})),
                          tr::encode_chunk(tr::ChunkType::End, tr::encode(tr::EndMarker{1, 0}))})
      b.insert(b.end(), c.begin(), c.end());
    std::ofstream(t, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
  }
  const fs::path out = scratch("latin1_out");
  const CliResult r = run_nbsim("replay " + t.string() + " --out " + out.string());
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "property 'scene' has a value that is not UTF-8")) << r.err;
  EXPECT_FALSE(fs::exists(out / "run.json")) << "no empty run.json";
}

// A trace whose final depth image is h x w under a w x h viewport: one frame with one draw.
fs::path swapped_depth_trace(const std::string& name) {
  namespace tr = nbsim::trace;
  const fs::path t = scratch(name);
  tr::TraceWriter w(t, {{"viewport", "16x8"}, {"depth_func", "LESS"}, {"depth_clear", "1"}, {"frames", "1"}});
  tr::FrameBegin b;
  w.begin_frame(b);
  tr::DrawRecord d;
  d.clip_positions = {{-1, -1, 0, 1}, {1, -1, 0, 1}, {0, 1, 0, 1}};
  d.state.test = d.state.write = true;
  w.write(d);
  tr::DepthSnapshot depth;
  depth.name = "final";
  depth.width = 8;
  depth.height = 16;
  depth.texels.assign(8 * 16, 1.0f);
  w.write(depth);
  tr::FrameEnd e;
  e.draws = 1;
  w.end_frame(e);
  w.close();
  return t;
}

// A depth snapshot of another size than the viewport (swapped sides) is refused with exit 2 and
// the chunk named, not an abort from the depth unit's thread, and the failed run leaves no output
// file behind (no empty run.json, no partial CSV).
TEST(ReplayCliTest, RefusesDepthOfAnotherSizeThanTheViewport) {
  const fs::path t = swapped_depth_trace("swapped.nbt");
  const fs::path out = scratch("swapped_out");
  const CliResult r = run_nbsim("replay " + t.string() + " --out " + out.string());
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "chunk 3 (DPTH)") && has(r.err, "depth image 'final' is 8x16, but the header's viewport is 16x8"))
      << r.err;
  for (const char* f : {"run.json", "draws.csv", "frames.csv"}) EXPECT_FALSE(fs::exists(out / f)) << f << " left by a failed run";
  const CliResult c = run_nbsim("compare " + t.string());
  EXPECT_EQ(c.status, 2) << c.out << c.err;
}

// A technique chunk this nbsim does not know, with an empty payload (flag bit 1: readers keep it
// raw), in every frame of a sample: `trace verify` finds the trace sound and the replay's counts
// are the sample's (the CRC of an empty payload is the running value over the chunk header, not 0:
// trace::crc32).
TEST(ReplayCliTest, UnknownEmptyTechniqueChunkVerifiesAndReplays) {
  namespace tr = nbsim::trace;
  const fs::path t = scratch("empty_chunk.nbt");
  {
    tr::FrameReader in{fs::path(sample("city_small_oq.nbt"))};
    tr::TraceWriter w(t, in.trace().properties());
    if (in.trace().scene()) w.write(*in.trace().scene());
    tr::TechniqueRecord empty;
    empty.type = tr::fourcc("ZERO");
    while (const auto f = in.next()) {
      w.begin_frame(f->begin);
      for (const tr::DrawRecord& d : f->draws) w.write(d);
      w.write(empty);
      for (const tr::DepthSnapshot& d : f->depths) w.write(d);
      for (const tr::NBufferLevels& l : f->levels) w.write(l);
      if (f->truth) w.write(*f->truth);
      w.end_frame(f->end);
    }
    w.close();
  }
  const CliResult v = run_nbsim("trace verify " + t.string());
  EXPECT_EQ(v.status, 0) << v.err;
  EXPECT_TRUE(has(v.out, "sound")) << v.out;
  const fs::path a = scratch("empty_chunk_out"), b = scratch("empty_chunk_sample_out");
  for (const auto& [trace, out] : {std::pair{t.string(), a}, std::pair{sample("city_small_oq.nbt"), b}}) {
    const CliResult r = run_nbsim("replay " + trace + " --out " + out.string());
    ASSERT_EQ(r.status, 0) << r.err;
  }
  const nlohmann::json ja = read_json(a / "run.json")["summary"], jb = read_json(b / "run.json")["summary"];
  for (const char* k : {"frames", "draws", "draws_exact", "fragments_model", "passed_model", "depth_tests", "cycles"})
    EXPECT_EQ(ja[k], jb[k]) << k;
  // A known chunk type (the particles' PRTC) with an empty payload is refused for what it is.
  const fs::path known = scratch("empty_known_chunk.nbt");
  {
    tr::TraceWriter w(known, {{"viewport", "8x8"}});
    w.begin_frame(tr::FrameBegin{});
    tr::TechniqueRecord prtc;
    prtc.type = tr::fourcc("PRTC");
    w.write(prtc);
    w.end_frame({0, 0, 0.0});
    w.close();
  }
  const CliResult k = run_nbsim("trace verify " + known.string());
  EXPECT_EQ(k.status, 2) << k.out;
  EXPECT_TRUE(has(k.err, "(PRTC)") && has(k.err, "the payload of 0 bytes") && has(k.err, "decodes short")) << k.err;
  EXPECT_FALSE(has(k.err, "CRC")) << k.err;
}

// A refused replay removes the output folder it created (and the parents it created for it), but
// never a folder that was there before it ran.
TEST(ReplayCliTest, RefusedReplayRemovesTheFolderItCreated) {
  const fs::path t = scratch("damaged_for_out.nbt");
  fs::copy_file(sample("city_small_oq.nbt"), t, fs::copy_options::overwrite_existing);
  fs::resize_file(t, fs::file_size(t) / 2);
  const fs::path created = scratch("made_by_replay");
  fs::remove_all(created);
  CliResult r = run_nbsim("replay " + t.string() + " --out " + (created / "run").string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_FALSE(fs::exists(created)) << "the folder a refused replay created is removed";
  const fs::path existing = scratch("there_before");
  fs::create_directories(existing);
  std::ofstream(existing / "keep.txt") << "mine";
  r = run_nbsim("replay " + t.string() + " --out " + existing.string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(fs::exists(existing / "keep.txt")) << "a folder that was there before stays, with its files";
  EXPECT_FALSE(fs::exists(existing / "run.json"));
}

// The rectangle levels with every level (nbuffer.levels=rect) are the ideal per-pixel rectangle
// test: every bounds test of a culling replay is culled exactly when its nearest depth is farther
// than the farthest pixel of its rectangle in GL's depth after the occluders, counted here by brute
// force. The paper's covering and the corner squares, reading squares that overhang the rectangle,
// cull a subset of those (never one the ideal test keeps).
TEST(ReplayCliTest, RectangleLevelsAreTheIdealRectangleTest) {
  namespace tr = nbsim::trace;
  const std::string trace = sample("city_small_oq.nbt");
  std::vector<std::vector<float>> depth;  // after the occluders, per frame (y up)
  int width = 0;
  {
    tr::FrameReader frames{fs::path(trace)};
    while (const auto f = frames.next()) {
      const tr::DepthSnapshot* d = f->depth(tr::DepthWhich::AfterOccluders);
      ASSERT_NE(d, nullptr);
      depth.push_back(d->texels);
      width = d->width;
    }
  }
  struct Row {
    int frame, x, y, w, h;
    float nearest;
    bool near, culled;
  };
  const auto read_culls = [](const fs::path& csv) {
    std::vector<Row> rows;
    std::ifstream in(csv);
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) {
      std::vector<std::string> c;
      std::stringstream ss(line);
      for (std::string cell; std::getline(ss, cell, ',');) c.push_back(cell);
      rows.push_back({std::stoi(c[0]), std::stoi(c[4]), std::stoi(c[5]), std::stoi(c[6]), std::stoi(c[7]), std::stof(c[8]),
                      c[9] == "1", c[10] == "culled"});
    }
    return rows;
  };
  const auto ideal = [&](const Row& r) {
    if (r.near || r.w <= 0 || r.h <= 0) return false;
    float far = 0.0f;
    for (int y = r.y; y < r.y + r.h; ++y)
      for (int x = r.x; x < r.x + r.w; ++x) far = std::max(far, depth[static_cast<std::size_t>(r.frame)][static_cast<std::size_t>(y * width + x)]);
    return r.nearest > far;
  };
  std::map<std::string, int> culled;
  for (const char* variant : {"--set nbuffer.levels=rect", "--set nbuffer.covering=paper --set nbuffer.align=top",
                              "--set nbuffer.covering=corners --set nbuffer.align=bottom"}) {
    const fs::path out = scratch("ideal_" + std::to_string(culled.size()));
    const CliResult r = run_nbsim("replay " + trace + " --set cull.mode=nb " + variant + " --out " + out.string());
    ASSERT_EQ(r.status, 0) << r.err;
    const std::vector<Row> rows = read_culls(out / "culls.csv");
    ASSERT_GT(rows.size(), 1000u);
    int n = 0, differ = 0, beyond = 0;
    for (const Row& row : rows) {
      const bool want = ideal(row);
      n += row.culled;
      differ += row.culled != want;
      beyond += row.culled && !want;
    }
    EXPECT_EQ(beyond, 0) << variant << ": culled what the ideal rectangle test keeps";
    if (std::string(variant).find("rect") != std::string::npos) {
      EXPECT_EQ(differ, 0) << variant << ": not the ideal test";
    }
    culled[variant] = n;
  }
  EXPECT_GT(culled["--set nbuffer.levels=rect"], culled["--set nbuffer.covering=paper --set nbuffer.align=top"]);
  EXPECT_GT(culled["--set nbuffer.covering=paper --set nbuffer.align=top"],
            culled["--set nbuffer.covering=corners --set nbuffer.align=bottom"]);
}

}  // namespace

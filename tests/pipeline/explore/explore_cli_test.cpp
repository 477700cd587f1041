// ExploreCliTest: `nbsim explore` from the outside: bad sweeps exit 2 before anything runs, a small
// sweep on the sample trace writes results.csv, a second run resumes without running a child, a
// failing point is recorded while the others complete, and the sample sweep files are valid.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <set>
#include <string>
#include <vector>

#include "tests/common/run_nbsim.h"
#include "tests/pipeline/explore/read_csv.h"

namespace {

namespace fs = std::filesystem;
using nbsim::testing::CliResult;
using nbsim::testing::has;
using nbsim::testing::run_nbsim;
using nbsim::testing::read_csv;

fs::path scratch(const std::string& name) { return nbsim::testing::scratch_path("nbsim_explore", name); }

const std::string kSample = (fs::path(NBSIM_SAMPLES) / "city_small_oq.nbt").string();

fs::path write_sweep(const std::string& name, const nlohmann::json& j) {
  const fs::path f = scratch(name);
  std::ofstream(f) << j.dump(2);
  return f;
}

// Bad sweeps exit 2 naming the problem, and no point runs.
TEST(ExploreCliTest, RefusedBeforeAnythingRuns) {
  struct Case {
    nlohmann::json sweep;
    const char* message;
  };
  const Case cases[] = {
      {{{"traces", {kSample}}, {"axes", {{"nbuffer.resolution_divisr", {1, 2}}}}}, "unknown config key 'nbuffer.resolution_divisr'"},
      {{{"traces", {kSample}}, {"axes", {{"nbuffer.format", {"f32", "u12"}}}}}, "axes.nbuffer.format[1]"},
      {{{"traces", {kSample}}, {"set", {{"nbuffer.cache_size_bytes", 1000}}}, {"axes", {{"cull.mode", {"nb"}}}}},
       "nbuffer.cache_size_bytes"},
      {{{"traces", {kSample, "/nonexistent/x.nbt"}}, {"axes", {{"cull.mode", {"nb"}}}}}, "trace '/nonexistent/x.nbt' does not exist"},
  };
  int n = 0;
  for (const auto& c : cases) {
    const fs::path out = scratch("refused_out_" + std::to_string(n));
    const fs::path f = write_sweep("refused_" + std::to_string(n++) + ".json", c.sweep);
    const CliResult r = run_nbsim("explore " + f.string() + " --out " + out.string());
    EXPECT_EQ(r.status, 2) << c.message << ": " << r.out << r.err;
    EXPECT_TRUE(has(r.err, c.message)) << "expected '" << c.message << "' in: " << r.err;
    EXPECT_TRUE(has(r.err, f.string())) << "the message names the sweep file: " << r.err;
    EXPECT_FALSE(fs::exists(out / "points")) << "nothing may run on a bad sweep";
  }
  fs::path bad = scratch("not_json.json");
  std::ofstream(bad) << "{\"traces\": [";
  const CliResult r = run_nbsim("explore " + bad.string() + " --out " + scratch("nj").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(has(r.err, "is not valid JSON")) << r.err;
}

// A real sweep of three points on the sample trace: rows, columns, values; then a second run
// resumes every point (no child runs, run.json untouched) and a grown sweep runs only the new point.
TEST(ExploreCliTest, SmallSweepAndResume) {
  const fs::path out = scratch("small");
  nlohmann::json sweep = {{"traces", {kSample}},
                          {"set", {{"nbuffer.format", "u16"}}},
                          {"axes", nlohmann::json::object()}};
  sweep["axes"]["cull.mode"] = {"nb_hier"};
  sweep["axes"]["nbuffer.resolution_divisor"] = {1, 2};
  sweep["axes"]["nbuffer.lookup_latency_cycles"] = {8};
  const fs::path f = write_sweep("small.json", sweep);
  CliResult r = run_nbsim("explore " + f.string() + " --jobs 2 --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  // The culling reference (float32 levels, full resolution) is not in the sweep: one point is added.
  EXPECT_TRUE(has(r.out, "3 points (1 of them references): 3 run, 0 resumed, 0 failed")) << r.out;

  std::vector<std::string> header;
  auto rows = read_csv(out / "results.csv", &header);
  ASSERT_EQ(rows.size(), 3u);
  for (const char* col : {"point_id", "trace", "trace_crc32", "nbsim_version", "nbuffer.format", "cull.mode",
                          "nbuffer.resolution_divisor", "nbuffer.lookup_latency_cycles", "status", "frames", "cycles_per_frame",
                          "depth_tests_per_frame", "query_depth_tests_per_frame", "total_depth_tests_per_frame", "false_culls",
                          "culling_efficiency", "memory_bytes_per_frame", "nbuffer_bytes_per_frame", "host_seconds", "error", "role",
                          "nbuffer_memory_bytes", "counter_error", "efficiency_lost", "cycle_error", "culling_reference",
                          "timing_reference"})
    EXPECT_NE(std::find(header.begin(), header.end(), col), header.end()) << "results.csv lacks column " << col;
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("status"), "ok") << row.at("error");
    EXPECT_EQ(row.at("frames"), "8");
    EXPECT_EQ(row.at("nbuffer.format"), row.at("role") == "sweep" ? "u16" : "f32") << "set reaches every sweep row";
    EXPECT_EQ(row.at("cull.mode"), "nb_hier");
    EXPECT_EQ(row.at("false_culls"), "0") << "N-buffer culling is conservative";
    EXPECT_EQ(row.at("trace_crc32").size(), 8u);
    EXPECT_EQ(row.at("nbsim_version"), "0.1.0");
    EXPECT_GT(std::stod(row.at("query_depth_tests_per_frame")), 0.0);
    EXPECT_GT(std::stod(row.at("memory_bytes_per_frame")), 0.0);
    EXPECT_TRUE(fs::exists(out / "points" / row.at("point_id") / "run.json"));
    EXPECT_TRUE(fs::exists(out / "points" / row.at("point_id") / "stderr.txt"));
  }
  EXPECT_EQ(rows[0].at("nbuffer.resolution_divisor"), "1");
  EXPECT_EQ(rows[1].at("nbuffer.resolution_divisor"), "2");
  // Errors against the reference: culling efficiency lost (exactly the difference), cycles against
  // the same point at the most detailed timing (here the point itself: 0).
  const auto& ref = rows[2];
  EXPECT_EQ(ref.at("role"), "reference");
  EXPECT_EQ(ref.at("nbuffer.resolution_divisor"), "1");
  EXPECT_EQ(ref.at("efficiency_lost"), "0");
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(rows[i].at("role"), "sweep");
    EXPECT_EQ(rows[i].at("culling_reference"), ref.at("point_id"));
    EXPECT_EQ(rows[i].at("timing_reference"), rows[i].at("point_id"));
    EXPECT_EQ(rows[i].at("cycle_error"), "0");
    EXPECT_DOUBLE_EQ(std::stod(rows[i].at("efficiency_lost")),
                     std::stod(ref.at("culling_efficiency")) - std::stod(rows[i].at("culling_efficiency")));
    EXPECT_EQ(rows[i].at("counter_error"), "0") << "replays are bit-exact with GL";
  }
  // Level memory: levels x (128/d)x(96/d) texels x 2 bytes (u16) or 4 (f32).
  EXPECT_EQ(std::stoll(rows[0].at("nbuffer_memory_bytes")), 7LL * 128 * 96 * 2);
  EXPECT_EQ(std::stoll(rows[1].at("nbuffer_memory_bytes")), 6LL * 64 * 48 * 2);
  EXPECT_EQ(std::stoll(ref.at("nbuffer_memory_bytes")), 7LL * 128 * 96 * 4);
  const auto run0 = nlohmann::json::parse(std::ifstream(out / "points" / rows[0].at("point_id") / "run.json"));
  EXPECT_EQ(run0["config"]["nbuffer"]["format"], "u16") << "the child ran the point's settings";
  EXPECT_EQ(run0["config"]["cull"]["mode"], "nb_hier");
  const auto sj = nlohmann::json::parse(std::ifstream(out / "sweep.json"));
  EXPECT_EQ(sj["points"].size(), 3u);
  EXPECT_EQ(sj["points"][0]["id"], rows[0].at("point_id"));

  const fs::path done = out / "points" / rows[0].at("point_id") / "run.json";
  const auto mtime = fs::last_write_time(done);
  r = run_nbsim("explore " + f.string() + " --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "3 points (1 of them references): 0 run, 3 resumed, 0 failed")) << r.out;
  EXPECT_EQ(fs::last_write_time(done), mtime) << "a done point is not run again";
  EXPECT_EQ(read_csv(out / "results.csv").size(), 3u);

  sweep["axes"]["nbuffer.resolution_divisor"] = {1, 2, 4};
  r = run_nbsim("explore " + write_sweep("small3.json", sweep).string() + " --jobs 2 --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "4 points (1 of them references): 1 run, 3 resumed, 0 failed")) << r.out;
  rows = read_csv(out / "results.csv");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[2].at("nbuffer.resolution_divisor"), "4");
  EXPECT_EQ(rows[2].at("status"), "ok");
}

// A point whose replay fails (a trace damaged after its header passes the sweep's checks) is
// recorded with its message; the other point completes and the exit status is 1.
TEST(ExploreCliTest, FailingPointRecorded) {
  const fs::path corrupt = scratch("corrupt.nbt");
  fs::copy_file(kSample, corrupt, fs::copy_options::overwrite_existing);
  fs::resize_file(corrupt, fs::file_size(corrupt) / 2);
  const fs::path out = scratch("failing");
  const nlohmann::json sweep = {{"traces", {kSample, corrupt.string()}},
                                {"points", {{{"cull.mode", "nb_hier"}, {"trace", kSample}}, {{"cull.mode", "nb_hier"}, {"trace", corrupt.string()}}}}};
  const CliResult r = run_nbsim("explore " + write_sweep("failing.json", sweep).string() + " --jobs 2 --out " + out.string());
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "2 points (0 of them references): 2 run, 0 resumed, 1 failed")) << r.out;
  EXPECT_TRUE(has(r.out, "failed: ")) << r.out;
  const auto rows = read_csv(out / "results.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("status"), "ok");
  EXPECT_EQ(rows[0].at("frames"), "8");
  EXPECT_EQ(rows[1].at("status"), "failed");
  EXPECT_FALSE(rows[1].at("error").empty()) << "the failure's message is in the row";
  EXPECT_TRUE(rows[1].at("frames").empty());
  EXPECT_TRUE(fs::exists(out / "points" / rows[1].at("point_id") / "error.txt"));
  EXPECT_FALSE(fs::exists(out / "points" / rows[1].at("point_id") / "run.json"));
}

// A design point that cannot be built (each value valid, the combination not: level 0 shared with
// the depth buffer at a reduced resolution) is refused by name before any replay and recorded as a
// failed point; the sweep runs the others.
TEST(ExploreCliTest, ImpossibleDesignRecordedAsFailed) {
  const fs::path out = scratch("impossible");
  const nlohmann::json sweep = {{"traces", {kSample}},
                                {"set", {{"cull.mode", "nb_hier"}, {"nbuffer.level0", "depth"}}},
                                {"axes", {{"nbuffer.resolution_divisor", {1, 4}}}}};
  const CliResult r = run_nbsim("explore " + write_sweep("impossible.json", sweep).string() + " --jobs 2 --out " + out.string());
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "2 points (0 of them references): 1 run, 0 resumed, 1 failed")) << r.out;
  const auto rows = read_csv(out / "results.csv");
  ASSERT_EQ(rows.size(), 2u);
  for (const auto& row : rows) {
    if (row.at("nbuffer.resolution_divisor") == "1") {
      EXPECT_EQ(row.at("status"), "ok");
    } else {
      EXPECT_EQ(row.at("status"), "failed");
      EXPECT_TRUE(has(row.at("error"), "nbuffer.level0=depth reads the depth buffer")) << row.at("error");
      EXPECT_FALSE(fs::exists(out / "points" / row.at("point_id") / "run.json")) << "never run";
    }
  }
}

// The front search (--search front) on a 24-point grid: a few random points, then the grid
// neighbours of the front round after round; it finds the whole grid's Pareto front (total depth
// tests, or cycles with --search-cost, against culling efficiency lost) running fewer points, and
// results.csv lists only the points it ran. A listed sweep has no grid to search.
TEST(ExploreCliTest, FrontSearchFindsTheGridsFront) {
  const nlohmann::json sweep = {{"traces", {kSample}},
                                {"set", {{"cull.mode", "nb_hier"}}},
                                {"axes",
                                 {{"nbuffer.resolution_divisor", {1, 2, 4, 8}},
                                  {"nbuffer.format", {"f32", "u16"}},
                                  {"nbuffer.update_policy", {"eager", "lazy", "on_demand"}}}}};
  const fs::path f = write_sweep("front.json", sweep);
  const fs::path grid = scratch("front_grid");
  ASSERT_EQ(run_nbsim("explore " + f.string() + " --jobs 2 --out " + grid.string()).status, 0);
  const auto front = [](const fs::path& csv, const std::string& cost) {
    std::vector<std::map<std::string, std::string>> ok;
    for (const auto& r : read_csv(csv))
      if (r.at("status") == "ok" && r.at("role") == "sweep") ok.push_back(r);
    std::set<std::string> ids;
    const auto v = [&](const std::map<std::string, std::string>& r, const std::string& k) { return std::stod(r.at(k)); };
    for (const auto& r : ok) {
      bool dominated = false;
      for (const auto& o : ok)
        dominated = dominated || (v(o, cost) <= v(r, cost) && v(o, "efficiency_lost") <= v(r, "efficiency_lost") &&
                                  (v(o, cost) < v(r, cost) || v(o, "efficiency_lost") < v(r, "efficiency_lost")));
      if (!dominated) ids.insert(r.at("point_id"));
    }
    return ids;
  };
  for (const std::string cost : {"total_depth_tests_per_frame", "cycles_per_frame"}) {
    SCOPED_TRACE(cost);
    const fs::path out = scratch("front_search_" + cost);
    const CliResult r = run_nbsim("explore " + f.string() + " --jobs 2 --search front --search-start 3 --search-cost " + cost +
                                  " --out " + out.string());
    ASSERT_EQ(r.status, 0) << r.out << r.err;
    EXPECT_TRUE(has(r.out, "search round 0: 5 points")) << "3 random points and their 2 references: " << r.out;
    const auto rows = read_csv(out / "results.csv");
    if (cost == "total_depth_tests_per_frame") {
      EXPECT_LT(rows.size(), 24u) << "the search ran fewer points than the grid";
    }
    EXPECT_EQ(front(out / "results.csv", cost), front(grid / "results.csv", cost));
  }
  const fs::path listed = write_sweep("listed.json", {{"traces", {kSample}}, {"points", {{{"cull.mode", "nb"}}}}});
  const CliResult bad = run_nbsim("explore " + listed.string() + " --search front --out " + scratch("listed_out").string());
  EXPECT_EQ(bad.status, 2);
  EXPECT_TRUE(has(bad.err, "--search front steps along a sweep's axes")) << bad.err;
}

// A sweep naming a file that is not a trace is refused at validation, naming the file, before
// any point runs (rather than passing validation and then failing every point).
TEST(ExploreCliTest, NotATraceRefused) {
  const fs::path junk = scratch("junk.nbt");
  std::ofstream(junk) << "not a trace at all";
  const fs::path out = scratch("junk_out");
  const fs::path f = write_sweep("junk.json", {{"traces", {kSample, junk.string()}}, {"axes", {{"cull.mode", {"nb"}}}}});
  const CliResult r = run_nbsim("explore " + f.string() + " --out " + out.string());
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "trace '" + junk.string() + "' cannot be opened as a trace")) << r.err;
  EXPECT_FALSE(fs::exists(out / "points")) << "nothing may run";
}

// Sweep files the JSON reader must not take whole are refused with exit 2 and a short message: a
// directory, a value nested 200,000 deep under a key nobody reads, a repeated key, a NUL byte.
TEST(ExploreCliTest, BadSweepFilesRefused) {
  const fs::path deep = scratch("deep.json"), dup = scratch("dup.json"), nul = scratch("nul.json"), dir = scratch("a_dir");
  std::ofstream(deep) << R"({"traces": [")" << kSample << R"("], "axes": {"cull.mode": ["nb"]}, "description": )"
                      << std::string(200000, '[') << std::string(200000, ']') << "}";
  std::ofstream(dup) << R"({"traces": [")" << kSample << R"("], "axes": {"cull.mode": ["nb"]}, "axes": {"cull.mode": ["oq"]}})";
  std::ofstream(nul, std::ios::binary) << std::string(R"({"traces": [")") + kSample + R"("], "axes": {"cull.mode": ["nb"]}})" + '\0' + "junk";
  fs::create_directories(dir);
  struct Row { fs::path file; std::string message; };
  const Row rows[] = {{deep, "deeper than 64 levels"}, {dup, "gives the key \"axes\" twice"}, {nul, "holds a NUL byte"}, {dir, "is a directory"}};
  for (const Row& row : rows) {
    const fs::path out = scratch("bad_file_out");
    const CliResult r = run_nbsim("explore " + row.file.string() + " --dry-run --out " + out.string());
    EXPECT_EQ(r.status, 2) << row.file << ": " << r.err;
    EXPECT_TRUE(has(r.err, row.message)) << row.file << ": " << r.err;
    EXPECT_TRUE(has(r.err, row.file.string())) << "the message names the file: " << r.err;
    EXPECT_LT(r.err.size(), 1000u);
    EXPECT_FALSE(fs::exists(out)) << "nothing written for a refused sweep";
  }
}

// A sweep of 1,000 x 1,000 points is refused at once by counting, before it is expanded (expanding
// it would take minutes and gigabytes, even in --dry-run); --max-points raises the limit.
TEST(ExploreCliTest, SweepSizeLimited) {
  nlohmann::json sweep = {{"traces", {kSample}}, {"axes", nlohmann::json::object()}};
  for (const char* key : {"nbuffer.lookup_latency_cycles", "memory.latency_cycles"}) {
    sweep["axes"][key] = nlohmann::json::array();
    for (int i = 1; i <= 1000; ++i) sweep["axes"][key].push_back(i);
  }
  const fs::path out = scratch("big_out");
  CliResult r = run_nbsim("explore " + write_sweep("big.json", sweep).string() + " --dry-run --out " + out.string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(has(r.err, "1 trace x 1000 x 1000 = 1000000 points, more than the limit of 10000 (--max-points N raises it)")) << r.err;
  EXPECT_FALSE(fs::exists(out));
  const nlohmann::json three = {{"traces", {kSample}}, {"axes", {{"nbuffer.lookup_latency_cycles", {1, 2, 3}}}}};
  const fs::path f = write_sweep("three.json", three);
  r = run_nbsim("explore " + f.string() + " --dry-run --max-points 2 --out " + scratch("three_refused").string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(has(r.err, "more than the limit of 2")) << r.err;
  r = run_nbsim("explore " + f.string() + " --dry-run --max-points 3 --out " + scratch("three_ok").string());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has(r.out, "explore: 3 points")) << r.out;
}

// A JSON library exception on the user's files (here a resumed point's run.json with a string where
// a number belongs) exits 2 with its message and the file, never 1, and leaves no partial results.csv.
TEST(ExploreCliTest, JsonLibraryErrorExits2) {
  const nlohmann::json sweep = {{"traces", {kSample}}, {"points", {{{"cull.mode", "nb_hier"}}}}};
  const fs::path f = write_sweep("tampered.json", sweep), out = scratch("tampered_out");
  CliResult r = run_nbsim("explore " + f.string() + " --dry-run --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  int points = 0;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line) && line.rfind("explore:", 0) != 0; ++points) {
    const fs::path dir = out / "points" / line.substr(0, line.find(' '));
    fs::create_directories(dir);
    std::ofstream(dir / "run.json") << R"({"summary": {"frames": 8, "cycles": "many"}})";
  }
  ASSERT_GT(points, 0) << r.out;
  r = run_nbsim("explore " + f.string() + " --out " + out.string());
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "run.json: [json.exception.type_error.302]")) << "the message names the file: " << r.err;
  EXPECT_FALSE(fs::exists(out / "results.csv")) << "no partial results.csv";
}

// Every sample sweep in pipeline/sweeps/ is valid (real keys, real traces): --dry-run runs nothing.
TEST(ExploreCliTest, SampleSweepsAreValid) {
  const fs::path dir = fs::path(NBSIM_SOURCE_DIR) / "pipeline" / "sweeps";
  const fs::path cwd = fs::current_path();
  fs::current_path(NBSIM_SOURCE_DIR);  // sweep files name traces from the repository's root
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".json") continue;
    ++n;
    const fs::path out = scratch("dry_" + e.path().stem().string());
    const CliResult r = run_nbsim("explore " + e.path().string() + " --dry-run --out " + out.string());
    EXPECT_EQ(r.status, 0) << e.path() << ": " << r.err;
    EXPECT_TRUE(has(r.out, "none run (--dry-run)")) << r.out;
    EXPECT_FALSE(fs::exists(out / "results.csv"));
  }
  fs::current_path(cwd);
  EXPECT_GE(n, 8) << "the sample sweeps are missing";
}

// A particles sweep on the particles sample (mode nb): the technique's columns (pipeline/techniques/
// results.cpp) are written, the reference (full-resolution float32 N-buffer at the capture's level
// cap) is added, and the declared errors come out: a capped N-buffer below the sprites' level keeps
// every sprite (the whole efficiency lost), a conservative one never pops.
TEST(ExploreCliTest, ParticlesSweepWritesItsColumns) {
  const std::string sample = (fs::path(NBSIM_SAMPLES) / "particles_walk_256.nbt").string();
  ASSERT_TRUE(fs::exists(sample)) << sample << " missing: run scripts/make_samples";
  const fs::path out = scratch("particles");
  nlohmann::json sweep = {{"traces", {sample}}, {"set", {{"nbuffer.format", "u16"}}}, {"axes", nlohmann::json::object()}};
  sweep["axes"]["nbuffer.level_cap"] = {3, -1};
  const fs::path f = write_sweep("particles.json", sweep);
  const CliResult r = run_nbsim("explore " + f.string() + " --jobs 2 --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "3 points (1 of them references): 3 run, 0 resumed, 0 failed")) << r.out;
  std::vector<std::string> header;
  const auto rows = read_csv(out / "results.csv", &header);
  ASSERT_EQ(rows.size(), 3u);
  for (const char* col : {"query_depth_tests_per_frame", "raster_depth_tests_per_frame", "build_texels_per_frame",
                          "total_depth_tests_per_frame", "popping", "false_culls", "culling_efficiency",
                          "culled_below_exact_fraction", "culled_below_exact", "culled_per_frame", "nbuffer_memory_bytes",
                          "particles_reference", "reference_culling_efficiency", "efficiency_lost", "culled_lost_per_frame"})
    EXPECT_NE(std::find(header.begin(), header.end(), col), header.end()) << "results.csv lacks particles column " << col;
  EXPECT_EQ(std::find(header.begin(), header.end(), "culling_reference"), header.end()) << "occlusion culling's, not in this sweep";
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("status"), "ok") << row.at("error");
    EXPECT_EQ(row.at("popping"), "0") << "a conservative N-buffer never pops";
    EXPECT_EQ(row.at("false_culls"), "0");
    EXPECT_FALSE(row.at("efficiency_lost").empty());
    EXPECT_NEAR(std::stod(row.at("culling_efficiency")) + std::stod(row.at("culled_below_exact_fraction")), 1.0, 1e-9);
  }
  const auto& capped = rows[0];  // level_cap 3: a 16 px sprite needs level 4
  EXPECT_EQ(capped.at("nbuffer.level_cap"), "3");
  EXPECT_EQ(std::stod(capped.at("culled_per_frame")), 0.0) << "every sprite too large for the levels built is kept";
  EXPECT_EQ(std::stod(capped.at("culled_below_exact_fraction")), 1.0);
  EXPECT_NEAR(std::stod(capped.at("efficiency_lost")), std::stod(capped.at("reference_culling_efficiency")), 1e-9);
  EXPECT_GT(std::stod(rows[1].at("culled_per_frame")), 0.0);
  EXPECT_EQ(rows[2].at("role"), "reference");
  EXPECT_EQ(rows[2].at("nbuffer.format"), "f32");
  EXPECT_EQ(std::stod(rows[2].at("efficiency_lost")), 0.0);
  const auto tr = nlohmann::json::parse(std::ifstream(out / "technique_results.json"));
  ASSERT_EQ(tr["techniques"].size(), 1u);
  EXPECT_EQ(tr["techniques"][0]["technique"], "particles");
  EXPECT_EQ(tr["techniques"][0]["headline_error"], "culled_below_exact_fraction");
}

}  // namespace

// `--point N|ID` runs one point into its folder and writes no shared file; `--collect` merges what
// is there without running anything: the other points are "not_run" and the exit status is 1.
// Resume across modes: a full run afterwards runs only the points --point did not.
TEST(ExploreCliTest, PointAndCollect) {
  const fs::path out = scratch("point_collect");
  const fs::path f = write_sweep("point.json", {{"traces", {kSample}}, {"axes", {{"cull.mode", {"nb_hier"}}, {"nbuffer.format", {"f32", "u16"}}}}});
  CliResult r = run_nbsim("explore " + f.string() + " --out " + out.string() + " --point 1");
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "ran; wrote")) << r.out;
  EXPECT_FALSE(fs::exists(out / "results.csv")) << "--point writes its folder only";
  EXPECT_FALSE(fs::exists(out / "sweep.json"));

  r = run_nbsim("explore " + f.string() + " --out " + out.string() + " --collect");
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "2 points (0 of them references): 1 done, 0 failed, 1 not run (--collect: nothing run)")) << r.out;
  auto rows = read_csv(out / "results.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("status"), "not_run");
  EXPECT_EQ(rows[1].at("status"), "ok");
  EXPECT_EQ(rows[1].at("nbuffer.format"), "u16") << "--point 1 is the second point of sweep.json";
  EXPECT_FALSE(fs::exists(out / "points" / rows[0].at("point_id") / "run.json")) << "--collect runs nothing";

  // The same point by id: done before, not run again.
  r = run_nbsim("explore " + f.string() + " --out " + out.string() + " --point " + rows[1].at("point_id"));
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "was done before, not run again")) << r.out;

  r = run_nbsim("explore " + f.string() + " --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.out, "2 points (0 of them references): 1 run, 1 resumed, 0 failed")) << r.out;

  for (const auto& [args, message] : std::vector<std::pair<std::string, std::string>>{
           {"--point 2", "--point 2: the sweep '" + f.string() + "' has 2 points (0 to 1"},
           {"--point 0123456789abcdef", "no point of the sweep"},
           {"--point 0 --collect", "run alone: give one of them"},
           {"--partition p", "are options of --engine slurm"},
           {"--engine slurm --jobs 2", "--jobs is an option of --engine local"},
           {"--engine slurm --point 0", "leave out --engine slurm"},
           {"--engine pbs", "--engine"},
           {"--engine slurm --sbatch-arg=--array=0-3", "--sbatch-arg '--array=0-3': nbsim sets --array itself"},
           {"--engine slurm --sbatch-arg=-o/tmp/x", "nbsim sets -o itself"},
           {"--engine slurm --sbatch-arg=--chdir=/", "nbsim sets --chdir itself"}}) {
    r = run_nbsim("explore " + f.string() + " --out " + out.string() + " " + args);
    EXPECT_EQ(r.status, 2) << args << ": " << r.out << r.err;
    EXPECT_TRUE(has(r.err, message)) << args << ": " << r.err;
  }
}

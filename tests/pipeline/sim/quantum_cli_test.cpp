// QuantumCliTest: the timing-granularity knob gpu.quantum_cycles (temporal decoupling,
// model/sim/unit.h) from the outside: quantum 1 runs through the quantum keepers yet gives the
// same run as no decoupling, bit for bit; a large quantum changes cycles but no count; bad values,
// and a VCD (which samples SystemC time) with a quantum, are refused.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/common/run_nbsim.h"

namespace {

namespace fs = std::filesystem;
using nbsim::testing::CliResult;
using nbsim::testing::has;
using nbsim::testing::run_nbsim;

fs::path scratch(const std::string& name) { return nbsim::testing::scratch_path("nbsim_quantum", name); }

const std::string kTrace = (fs::path(NBSIM_SAMPLES) / "city_small_oq.nbt").string();

// Replays the small sample into a fresh folder; the test fails if the replay does.
fs::path replay(const std::string& name, const std::string& args) {
  const fs::path out = scratch(name);
  fs::remove_all(out);
  const CliResult r = run_nbsim("replay " + kTrace + " --out " + out.string() + " " + args);
  EXPECT_EQ(r.status, 0) << args << ": " << r.err;
  return out;
}

nlohmann::json read_json(const fs::path& f) {
  std::ifstream in(f);
  return nlohmann::json::parse(in);
}

std::string read_text(const fs::path& f) {
  std::ifstream in(f);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// run.json without what differs between any two runs (host time) or what the config says.
nlohmann::json run_without_host(const fs::path& dir) {
  nlohmann::json j = read_json(dir / "run.json");
  for (const char* k : {"host_seconds", "depth_tests_per_host_second", "cycles_per_host_second"}) j["summary"].erase(k);
  j.erase("config");
  return j;
}

// Every column of a CSV but the named ones (cycles), row by row.
std::vector<std::string> csv_without(const fs::path& f, const std::set<std::string>& columns) {
  std::ifstream in(f);
  std::vector<std::string> rows;
  std::vector<bool> skip;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    if (rows.empty())
      for (const std::string& c : cells) skip.push_back(columns.count(c) > 0);
    std::string row;
    for (std::size_t i = 0; i < cells.size(); ++i)
      if (i >= skip.size() || !skip[i]) row += cells[i] + ",";
    rows.push_back(row);
  }
  return rows;
}

// Quantum 1 goes through the keepers but synchronises after every work item: every output is the
// one of the run without decoupling (the default, and an explicit 0), in trace and culling modes.
TEST(QuantumCliTest, QuantumOneMatchesNoDecouplingBitForBit) {
  for (const std::string mode : {"trace", "nb_hier"}) {
    const fs::path plain = replay(mode + "_default", "--set cull.mode=" + mode);
    const fs::path zero = replay(mode + "_q0", "--set cull.mode=" + mode + " --set gpu.quantum_cycles=0");
    const fs::path one = replay(mode + "_q1", "--set cull.mode=" + mode + " --set gpu.quantum_cycles=1");
    const nlohmann::json p = run_without_host(plain);
    ASSERT_GT(p["summary"]["cycles"].get<long>(), 0) << mode;
    EXPECT_EQ(p, run_without_host(zero)) << mode << ": quantum 0 is not the default run";
    EXPECT_EQ(p, run_without_host(one)) << mode << ": quantum 1 changed run.json (cycles, stats or per-frame values)";
    for (const char* csv : {"draws.csv", "frames.csv", "culls.csv"})
      EXPECT_EQ(read_text(plain / csv), read_text(one / csv)) << mode << ": quantum 1 changed " << csv;
    EXPECT_EQ(read_json(one / "run.json")["config"]["gpu"]["quantum_cycles"], 1) << "run.json records the quantum";
  }
}

// A large quantum changes the cycles but no count: every summary value but cycles and host time,
// every draw's and frame's counts, every bounds test and its decision.
TEST(QuantumCliTest, LargeQuantumKeepsCountsChangesCycles) {
  for (const std::string mode : {"trace", "nb_hier", "oq"}) {
    const fs::path base = replay(mode + "_base", "--set cull.mode=" + mode);
    const fs::path loose = replay(mode + "_loose", "--set cull.mode=" + mode + " --set gpu.quantum_cycles=100000");
    nlohmann::json a = run_without_host(base)["summary"], b = run_without_host(loose)["summary"];
    const long ca = a["cycles"].get<long>(), cb = b["cycles"].get<long>();
    EXPECT_NE(ca, cb) << mode << ": a quantum of 100000 cycles did not change the cycles: is decoupling on?";
    EXPECT_LT(std::abs(static_cast<double>(cb - ca)) / static_cast<double>(ca), 0.25)
        << mode << ": cycle error above 25% (" << ca << " -> " << cb << ")";
    for (nlohmann::json* s : {&a, &b}) {
      s->erase("cycles");
      if (s->contains("cull")) (*s)["cull"].erase("cycles"), (*s)["cull"].erase("cycles_per_frame");
    }
    EXPECT_EQ(a, b) << mode << ": a count in the summary changed with the quantum";
    const std::vector<std::string> draws = csv_without(base / "draws.csv", {"done_cycle"});
    ASSERT_GT(draws.size(), 100u) << mode;
    EXPECT_EQ(draws, csv_without(loose / "draws.csv", {"done_cycle"})) << mode << ": a draw's counts changed";
    EXPECT_EQ(csv_without(base / "frames.csv", {"end_cycle", "cycles"}), csv_without(loose / "frames.csv", {"end_cycle", "cycles"}))
        << mode << ": a frame's counts changed";
    EXPECT_EQ(read_text(base / "culls.csv"), read_text(loose / "culls.csv")) << mode << ": a cull decision changed";
  }
}

// A quantum outside 0..10,000,000 is refused with exit 2 and the key named.
TEST(QuantumCliTest, RefusesBadQuantum) {
  for (const char* value : {"-1", "10000001", "fast"}) {
    const CliResult r = run_nbsim("replay " + kTrace + " --out " + scratch("bad").string() + " --set gpu.quantum_cycles=" + value);
    EXPECT_EQ(r.status, 2) << value << ": " << r.err;
    EXPECT_TRUE(has(r.err, "gpu.quantum_cycles")) << value << ": " << r.err;
  }
}

// --vcd samples SystemC time, which decoupled units run ahead of: refused with a quantum, with the
// way out named; the trace-event timeline (each unit's own time) is still written.
TEST(QuantumCliTest, VcdRefusedWithQuantum) {
  const fs::path vcd = scratch("q.vcd");
  fs::remove(vcd);
  const CliResult r = run_nbsim("replay " + kTrace + " --out " + scratch("vcd").string() +
                                " --set gpu.quantum_cycles=1000 --vcd " + vcd.string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(has(r.err, "--vcd")) << r.err;
  EXPECT_TRUE(has(r.err, "--timeline")) << r.err;
  EXPECT_FALSE(fs::exists(vcd));
  const fs::path json = scratch("q_timeline.json");
  replay("timeline", "--set gpu.quantum_cycles=1000 --timeline " + json.string());
  EXPECT_GT(fs::file_size(json), 1000u);
}

}  // namespace

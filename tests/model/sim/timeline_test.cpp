// TimelineTest: the timeline recorder (model/sim/timeline.h) inside small SystemC models: spans at
// the cycles the units spent, one named track per unit, overlapping spans on a second track, the
// event cap, and the VCD's busy bits. Each TEST elaborates once, so each runs in its own process.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <regex>
#include <string>
#include <tuple>
#include <vector>

#include "model/common/error.h"
#include "model/sim/timeline.h"
#include "model/sim/unit.h"
#include "tests/common/scratch.h"

extern "C" int sc_main(int, char*[]) { return 1; }  // libsystemc's main() needs one; gtest's main runs

namespace nbsim::sim {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  return nbsim::testing::scratch_path("nbsim_timeline", name);
}

TimelineOptions options(std::optional<fs::path> json, std::optional<fs::path> vcd, std::uint64_t max_events = 1000) {
  TimelineOptions o;
  o.json = std::move(json), o.vcd = std::move(vcd), o.max_events = max_events;
  return o;
}

std::string read_text(const fs::path& f) {
  std::ifstream in(f);
  return {std::istreambuf_iterator<char>(in), {}};
}

// A unit that spends the listed spans: (start cycle, cycles, label); label "" leaves it unnamed.
struct Scripted : Unit {
  using Step = std::tuple<std::uint64_t, std::uint64_t, std::string>;
  std::vector<Step> steps;
  SC_HAS_PROCESS(Scripted);
  Scripted(const sc_core::sc_module_name& n, stats::Registry& r, std::vector<Step> s) : Unit(n, r), steps(std::move(s)) {
    SC_THREAD(run);
  }
  void run() {
    for (const auto& [at, n, text] : steps) {
      if (at > now_cycles()) wait(cycles(at - now_cycles()));
      if (!text.empty()) label(text);
      work(n);
    }
  }
};

// Two threads of one unit: the second starts while the first still works.
struct TwoThreads : Unit {
  SC_HAS_PROCESS(TwoThreads);
  TwoThreads(const sc_core::sc_module_name& n, stats::Registry& r) : Unit(n, r) {
    SC_THREAD(first);
    SC_THREAD(second);
  }
  void first() {
    work(10);   // [0, 10)
    work(5);    // [10, 15)
  }
  void second() {
    wait(cycles(3));
    label_with([] { return std::string("second"); });
    work(4);    // [3, 7): overlaps the first thread's span
    wait(cycles(13));
    work(2);    // [20, 22): both spans are over, back on the first track
  }
};

// The VCD identifier of a 1-bit variable, from its $var line; "" when there is none.
std::string vcd_id(const std::string& vcd, const std::string& name) {
  std::smatch m;
  const std::regex var(R"(\$var wire\s+1\s+(\S+)\s+)" + name + R"(\s+\$end)");
  return std::regex_search(vcd, m, var) ? m[1].str() : "";
}

// Whether the VCD's time step `cycle` contains the value change `change` ("1aaaab").
bool has_change(const std::string& vcd, std::uint64_t cycle, const std::string& change) {
  const std::size_t at = vcd.find("\n#" + std::to_string(cycle) + "\n");
  if (at == std::string::npos) return false;
  const std::size_t next = vcd.find("\n#", at + 1);
  return vcd.substr(at, next == std::string::npos ? std::string::npos : next - at).find("\n" + change + "\n") != std::string::npos;
}

struct Event {
  std::string track, name;
  std::uint64_t ts, dur;
  bool operator==(const Event&) const = default;
};

std::ostream& operator<<(std::ostream& os, const Event& e) {
  return os << e.track << ":" << e.name << "@" << e.ts << "+" << e.dur;
}

// The JSON's complete events with their track names, in file order; the track names in `tracks`.
std::vector<Event> events_of(const nlohmann::json& j, std::vector<std::string>* tracks = nullptr) {
  std::map<int, std::string> names;
  for (const auto& e : j.at("traceEvents"))
    if (e.at("ph") == "M" && e.at("name") == "thread_name") {
      names[e.at("tid").get<int>()] = e.at("args").at("name").get<std::string>();
      if (tracks) tracks->push_back(e.at("args").at("name").get<std::string>());
    }
  std::vector<Event> out;
  for (const auto& e : j.at("traceEvents"))
    if (e.at("ph") == "X")
      out.push_back({names.at(e.at("tid").get<int>()), e.at("name").get<std::string>(), e.at("ts").get<std::uint64_t>(),
                     e.at("dur").get<std::uint64_t>()});
  return out;
}

// Two units' spans land at the cycles they spent, with their labels, one named track per unit.
TEST(TimelineTest, TwoUnitsSpansAtTheirCycles) {
  install_report_handler();
  stats::Registry reg;
  Scripted a("a", reg, {{0, 5, "first"}, {0, 3, ""}});
  Scripted b("b", reg, {{2, 4, "draw 7 (occluder)"}, {20, 1, "late"}});
  const fs::path json = scratch("two.json"), vcd = scratch("two.vcd");
  Timeline t(options(json, vcd));
  t.attach_units();
  sc_core::sc_start();
  const TimelineSummary s = t.close();
  EXPECT_EQ(s.events, 4u);
  EXPECT_EQ(s.dropped, 0u);

  std::vector<std::string> tracks;
  const auto j = nlohmann::json::parse(read_text(json));  // throws, and fails the test, if it is not JSON
  const std::vector<Event> ev = events_of(j, &tracks);
  EXPECT_EQ(tracks, (std::vector<std::string>{"a", "b"})) << "one thread_name track per unit";
  const std::vector<Event> expected = {{"a", "first", 0, 5}, {"b", "draw 7 (occluder)", 2, 4}, {"a", "busy", 5, 3},
                                       {"b", "late", 20, 1}};
  EXPECT_EQ(ev, expected) << "spans are written as they end, at the cycles spent, unnamed ones as \"busy\"";
  EXPECT_EQ(j.at("otherData").at("events"), 4);
  EXPECT_EQ(reg.values()["a"]["busy_cycles"], 8) << "the timeline does not change the busy count";

  const std::string v = read_text(vcd);
  EXPECT_TRUE(std::regex_search(v, std::regex(R"(\$timescale\s+1 ns\s+\$end)"))) << "one VCD step per cycle:\n" << v;
  const std::string a_id = vcd_id(v, "a_busy"), b_id = vcd_id(v, "b_busy");
  ASSERT_FALSE(a_id.empty() || b_id.empty()) << "a $var line per unit:\n" << v;
  EXPECT_TRUE(has_change(v, 2, "1" + b_id)) << "b starts at cycle 2:\n" << v;
  EXPECT_TRUE(has_change(v, 8, "0" + a_id)) << "a's two spans are one busy stretch to cycle 8:\n" << v;
  EXPECT_TRUE(has_change(v, 21, "0" + b_id)) << "the last change, at the run's end, reaches the file:\n" << v;
}

// Spans of one unit that overlap (two threads) go to a second track, never overlapping on one.
TEST(TimelineTest, OverlappingSpansGetASecondTrack) {
  install_report_handler();
  stats::Registry reg;
  TwoThreads u("u", reg);
  const fs::path json = scratch("overlap.json");
  Timeline t(options(json, std::nullopt));
  t.attach_units();
  sc_core::sc_start();
  t.close();
  std::vector<std::string> tracks;
  const std::vector<Event> ev = events_of(nlohmann::json::parse(read_text(json)), &tracks);
  EXPECT_EQ(tracks, (std::vector<std::string>{"u", "u #2"}));
  const std::vector<Event> expected = {{"u #2", "second", 3, 4}, {"u", "busy", 0, 10}, {"u", "busy", 10, 5},
                                       {"u", "busy", 20, 2}};
  EXPECT_EQ(ev, expected);
}

// Past max_events, spans are counted, not written, and the file stays valid JSON that says so.
TEST(TimelineTest, CapKeepsTheFileValid) {
  install_report_handler();
  stats::Registry reg;
  Scripted a("a", reg, {{0, 1, ""}, {0, 1, ""}, {0, 1, ""}, {7, 1, ""}, {0, 1, ""}});
  const fs::path json = scratch("cap.json");
  Timeline t(options(json, std::nullopt, 2));
  t.attach_units();
  sc_core::sc_start();
  const TimelineSummary s = t.close();
  EXPECT_EQ(s.events, 2u);
  EXPECT_EQ(s.dropped, 3u);
  EXPECT_EQ(s.first_dropped_cycle, 2u);
  const auto j = nlohmann::json::parse(read_text(json));
  EXPECT_EQ(events_of(j).size(), 2u);
  EXPECT_EQ(j.at("otherData").at("dropped_events"), 3);
}

// An output that cannot be written is the user's error, reported before the simulation runs.
TEST(TimelineTest, UnwritablePathsAreInputErrors) {
  EXPECT_THROW(Timeline(options("/nonexistent-dir/t.json", std::nullopt)), InputError);
  EXPECT_THROW(Timeline(options(std::nullopt, "/nonexistent-dir/t.vcd")), InputError);
}

}  // namespace
}  // namespace nbsim::sim

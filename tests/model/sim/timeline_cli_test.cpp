// TimelineCliTest: `nbsim replay --timeline FILE.json --vcd FILE.vcd` from the outside: both files
// are written, the JSON parses with a track of spans per unit that add up to the unit's busy cycles,
// the VCD declares a busy bit per unit, and an unwritable timeline is refused with exit 2.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <regex>
#include <string>

#include "tests/common/run_nbsim.h"

namespace {

namespace fs = std::filesystem;
using nbsim::testing::CliResult;
using nbsim::testing::has;
using nbsim::testing::run_nbsim;

fs::path scratch(const std::string& name) { return nbsim::testing::scratch_path("nbsim_timeline_cli", name); }

std::string read_text(const fs::path& f) {
  std::ifstream in(f);
  return {std::istreambuf_iterator<char>(in), {}};
}

struct TrackTotals {
  std::uint64_t spans = 0, cycles = 0, last_end = 0, draw_spans = 0;
};

// Per track name: spans, summed durations, the last end, spans named after a draw.
std::map<std::string, TrackTotals> tracks_of(const nlohmann::json& j) {
  std::map<int, std::string> names;
  for (const auto& e : j.at("traceEvents"))
    if (e.at("ph") == "M" && e.at("name") == "thread_name") names[e.at("tid").get<int>()] = e.at("args").at("name");
  std::map<std::string, TrackTotals> out;
  for (const auto& [tid, name] : names) out[name];
  for (const auto& e : j.at("traceEvents")) {
    if (e.at("ph") != "X") continue;
    TrackTotals& t = out[names.at(e.at("tid").get<int>())];
    const auto ts = e.at("ts").get<std::uint64_t>(), dur = e.at("dur").get<std::uint64_t>();
    ++t.spans;
    t.cycles += dur;
    t.last_end = std::max(t.last_end, ts + dur);
    if (has(e.at("name").get<std::string>(), " draw ")) ++t.draw_spans;
  }
  return out;
}

// The sample replay writes both files; each pipeline unit has a track whose spans add up to its
// busy cycles in run.json and end by the run's last cycle; the VCD has a busy bit per unit.
TEST(TimelineCliTest, ReplayWritesTimelineAndVcd) {
  const fs::path out = scratch("oq"), json = scratch("oq.json"), vcd = scratch("oq.vcd");
  const CliResult r = run_nbsim("replay " + (fs::path(NBSIM_SAMPLES) / "city_small_oq.nbt").string() + " --out " +
                                out.string() + " --timeline " + json.string() + " --vcd " + vcd.string());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  ASSERT_TRUE(fs::exists(json) && fs::exists(vcd)) << r.out;
  EXPECT_TRUE(has(r.out, "timeline: ")) << r.out;
  const auto j = nlohmann::json::parse(read_text(json));
  const auto run = nlohmann::json::parse(read_text(out / "run.json"));
  const auto tracks = tracks_of(j);
  const std::string v = read_text(vcd);
  for (const char* unit : {"gpu.cp", "gpu.geometry", "gpu.raster", "gpu.depth"}) {
    ASSERT_TRUE(tracks.count(unit)) << unit << " has no track";
    const TrackTotals& t = tracks.at(unit);
    EXPECT_GT(t.spans, 0u) << unit;
    EXPECT_EQ(t.cycles, run["stats"][unit]["busy_cycles"].get<std::uint64_t>())
        << unit << ": the spans add up to the unit's busy cycles";
    EXPECT_LE(t.last_end, run["summary"]["cycles"].get<std::uint64_t>()) << unit << ": no span after the run's end";
    EXPECT_EQ(t.draw_spans, t.spans - (std::string(unit) == "gpu.depth" ? run["stats"]["gpu.depth"]["clears"].get<std::uint64_t>() : 0))
        << unit << ": every span but the depth clears is named after its draw";
    // SystemC turns the dots of "gpu.cp_busy" into scopes: $scope module gpu, $var ... cp_busy.
    const std::regex var(R"(\$var wire\s+1\s+\S+\s+)" + std::string(unit).substr(4) + R"(_busy\s+\$end)");
    EXPECT_TRUE(std::regex_search(v, var)) << unit << ": no $var line in the VCD";
  }
  EXPECT_TRUE(has(v, "$scope module gpu $end")) << "the units' bits sit in the gpu scope";
  EXPECT_EQ(j["otherData"]["dropped_events"], 0);
}

// In a culling mode the cull stage and the N-buffer unit get tracks too: every unit with busy cycles
// in run.json has a track whose spans add up to them, and the N-buffer's spans say what they were.
TEST(TimelineCliTest, CullingModeTracksEveryUnit) {
  const fs::path out = scratch("nb"), json = scratch("nb.json");
  const CliResult r = run_nbsim("replay " + (fs::path(NBSIM_SAMPLES) / "city_small_oq.nbt").string() + " --out " +
                                out.string() + " --set cull.mode=nb --timeline " + json.string());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto j = nlohmann::json::parse(read_text(json));
  const auto run = nlohmann::json::parse(read_text(out / "run.json"));
  const auto tracks = tracks_of(j);
  int units = 0;
  for (const auto& [group, values] : run["stats"].items()) {
    if (!values.contains("busy_cycles")) continue;
    ++units;
    ASSERT_TRUE(tracks.count(group)) << group << " has no track";
    EXPECT_EQ(tracks.at(group).cycles, values["busy_cycles"].get<std::uint64_t>()) << group;
  }
  EXPECT_EQ(units, 6) << "cp, geometry, raster, depth, cull and nbuffer";
  int nbuffer_tid = -1;
  for (const auto& e : j["traceEvents"])
    if (e["ph"] == "M" && e["name"] == "thread_name" && e["args"]["name"] == "gpu.nbuffer") nbuffer_tid = e["tid"];
  std::map<std::string, int> nbuffer_kinds;
  for (const auto& e : j["traceEvents"])
    if (e["ph"] == "X" && e["tid"] == nbuffer_tid) ++nbuffer_kinds[e["name"].get<std::string>().substr(0, 5)];
  EXPECT_GT(nbuffer_kinds["query"], 0) << "the N-buffer's lookups are named";
  EXPECT_GT(nbuffer_kinds["updat"], 0) << "the N-buffer's update batches are named";
}

// An output that cannot be written is refused with a message and exit 2, not a crash.
TEST(TimelineCliTest, UnwritableTimelineIsRefused) {
  const CliResult r = run_nbsim("replay " + (fs::path(NBSIM_SAMPLES) / "city_small_oq.nbt").string() + " --out " +
                                scratch("bad").string() + " --timeline /nonexistent-dir/t.json");
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "cannot write the timeline")) << r.err;
}

}  // namespace

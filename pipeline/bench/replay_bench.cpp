// The simulator-speed benchmark; see replay_bench.h.
#include "pipeline/bench/replay_bench.h"

#include <malloc.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "model/common/error.h"
#include "model/config/schema.h"
#include "pipeline/sim/replay.h"
#include "traces/capture/capture.h"
#include "traces/capture/technique.h"

namespace nbsim::bench {
namespace {

// What a repetition's replay reports to the bench.
struct Timing {
  double host_seconds = 0.0;
  std::uint64_t cycles = 0, depth_tests = 0;
  int failed = 0;          // 1: bad input, 2: another error
  char message[1024] = {};  // why, when failed
};

// Replays in a child process: SystemC elaborates a model once per process, so every repetition
// but the last (which the bench's summary comes from) runs in its own fork of this one. The child
// only replays (no GL), on heap pages of its own, and reports through a pipe.
Timing replay_in_child(const pipeline::ReplayOptions& r) {
  int fds[2];
  if (::pipe(fds) != 0) throw std::runtime_error("bench replay: pipe failed");
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("bench replay: fork failed");
  if (pid == 0) {
    ::close(fds[0]);
    // The heap's free pages, inherited from the capture, go back to the system: a replay that
    // reused them would copy each on its first write (copy on write, the fork's), a cost a replay in
    // a process of its own (nbsim replay) never pays. Measured: without this, the repetitions in a
    // child took 6 to 13% longer than the one in this process.
    ::malloc_trim(0);
    Timing t;
    try {
      const pipeline::ReplaySummary s = pipeline::replay(r);
      t.host_seconds = s.host_seconds, t.cycles = s.cycles, t.depth_tests = s.depth_tests;
    } catch (const InputError& e) {
      t.failed = 1;
      std::snprintf(t.message, sizeof t.message, "%s", e.what());
    } catch (const std::exception& e) {
      t.failed = 2;
      std::snprintf(t.message, sizeof t.message, "%s", e.what());
    }
    const char* p = reinterpret_cast<const char*>(&t);
    for (std::size_t left = sizeof t; left > 0;) {
      const ssize_t n = ::write(fds[1], p, left);
      if (n <= 0) break;
      p += n, left -= static_cast<std::size_t>(n);
    }
    ::_exit(0);
  }
  ::close(fds[1]);
  Timing t;
  char* p = reinterpret_cast<char*>(&t);
  std::size_t got = 0;
  while (got < sizeof t) {
    const ssize_t n = ::read(fds[0], p + got, sizeof t - got);
    if (n <= 0) break;
    got += static_cast<std::size_t>(n);
  }
  ::close(fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  if (got != sizeof t || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error("bench replay: a repetition's replay process ended without a result");
  if (t.failed == 1) throw InputError(t.message);
  if (t.failed == 2) throw std::runtime_error(t.message);
  return t;
}

}  // namespace

nlohmann::ordered_json run_replay_bench(const ReplayBenchOptions& o) {
  const capture::TechniqueRow& row = capture::find_technique(o.technique);
  const capture::BenchPreset& preset = row.bench;
  capture::CaptureOptions c;
  c.technique = o.technique;
  c.scene = o.scene.value_or(preset.scene);
  c.path = o.path.value_or(preset.path);
  const std::string size = o.size.value_or(preset.size);
  char tail = 0;
  if (std::sscanf(size.c_str(), "%dx%d%c", &c.width, &c.height, &tail) != 2 || c.width < 1 || c.height < 1)
    throw InputError(fmt::format("--size '{}' is not WxH", size));
  c.frames = o.frames;
  c.options = preset.options;
  if (o.mode) {
    if (preset.mode_option.empty())
      throw InputError(fmt::format("--mode: the {} bench has no mode option (its capture options: nbsim capture {} --help)",
                                   o.technique, o.technique));
    c.options.set(preset.mode_option, *o.mode);
  }
  for (const auto& [name, value] : o.options) c.options.set(name, value);
  const auto file = std::filesystem::temp_directory_path() / ("nbsim_bench_" + std::to_string(::getpid()) + ".nbt");
  pipeline::ReplayOptions r;
  r.trace = file;
  {
    config::Schema schema;  // a bad key was refused before the capture (run_replay_bench's caller checks nothing: here)
    pipeline::GpuConfig::describe(schema, r.config);
    for (const std::string& set : preset.replay_sets) schema.set(set);
    for (const std::string& set : o.sets) schema.set(set);
    r.config_values = schema.values();
  }
  NBSIM_CHECK(o.repetitions >= 1, "bench replay needs at least one repetition");
  struct Pair {
    double gl_ms = 0.0, replay_ms = 0.0, ratio = 0.0;
  };
  std::vector<Pair> pairs;
  pipeline::ReplaySummary s;  // the last repetition's, replayed in this process
  std::vector<Timing> timings;
  for (int k = 0; k < o.repetitions; ++k) {
    const bool last = k + 1 == o.repetitions;
    Pair p;
    try {
      p.gl_ms = capture::capture(c, file.string()).gl_ms;
      if (last) {
        s = pipeline::replay(r);
        p.replay_ms = s.host_seconds * 1e3;
      } else {
        timings.push_back(replay_in_child(r));
        p.replay_ms = timings.back().host_seconds * 1e3;
      }
    } catch (...) {
      std::filesystem::remove(file);
      throw;
    }
    std::filesystem::remove(file);
    p.ratio = p.gl_ms > 0 ? p.replay_ms / p.gl_ms : 0.0;
    pairs.push_back(p);
  }
  for (std::size_t k = 0; k < timings.size(); ++k)
    NBSIM_CHECK(timings[k].cycles == s.cycles && timings[k].depth_tests == s.depth_tests,
                fmt::format("bench replay: repetition {} replayed to {} cycles and {} depth tests, the last to {} and {}", k + 1,
                            timings[k].cycles, timings[k].depth_tests, s.cycles, s.depth_tests));
  std::vector<Pair> by_ratio = pairs;
  std::sort(by_ratio.begin(), by_ratio.end(), [](const Pair& a, const Pair& b) { return a.ratio < b.ratio; });
  const Pair median = by_ratio[(by_ratio.size() - 1) / 2];  // the lower median of an even count

  nlohmann::ordered_json j;
  j["bench"] = "replay";
  j["technique"] = o.technique;
  j["size"] = size;
  j["frames"] = s.frames;
  j["scene"] = c.scene;
  j["path"] = c.path;
  const auto& values = c.options.values();
  const auto mode = values.find(preset.mode_option);
  j["mode"] = mode == values.end() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(mode->second);
  j["options"] = values;
  std::vector<std::string> sets = preset.replay_sets;
  sets.insert(sets.end(), o.sets.begin(), o.sets.end());
  j["sets"] = sets;
  j["draws"] = s.draws;
  j["repetitions"] = o.repetitions;
  j["gl_ms"] = median.gl_ms;
  j["replay_ms"] = median.replay_ms;
  j["ratio"] = median.ratio;
  nlohmann::ordered_json ratios = nlohmann::ordered_json::array();
  for (const Pair& p : pairs) ratios.push_back(p.ratio);
  j["ratios"] = std::move(ratios);
  j["depth_tests"] = s.depth_tests;
  j["depth_tests_per_s"] = median.replay_ms > 0 ? static_cast<double>(s.depth_tests) / (median.replay_ms * 1e-3) : 0.0;
  j["cycles"] = s.cycles;
  j["cycles_per_s"] = median.replay_ms > 0 ? static_cast<double>(s.cycles) / (median.replay_ms * 1e-3) : 0.0;
  j["draws_exact"] = s.draws_exact;
  j["within_thresholds"] = s.within_thresholds();
  if (!s.program.is_null()) {
    nlohmann::ordered_json totals = s.program;  // the bench reports totals
    totals.erase("per_frame");
    j[o.technique + "_summary"] = std::move(totals);
  }
  return j;
}

}  // namespace nbsim::bench

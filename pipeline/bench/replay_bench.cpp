// The simulator-speed benchmark; see replay_bench.h.
#include "pipeline/bench/replay_bench.h"

#include <unistd.h>

#include <fmt/format.h>

#include <filesystem>

#include "model/common/error.h"
#include "model/config/schema.h"
#include "pipeline/sim/replay.h"
#include "traces/capture/capture.h"
#include "traces/capture/technique.h"

namespace nbsim::bench {

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
  const capture::CaptureSummary cap = capture::capture(c, file.string());

  pipeline::ReplayOptions r;
  r.trace = file;
  {
    config::Schema schema;  // a bad key was refused before the capture (run_replay_bench's caller checks nothing: here)
    pipeline::GpuConfig::describe(schema, r.config);
    for (const std::string& set : preset.replay_sets) schema.set(set);
    for (const std::string& set : o.sets) schema.set(set);
    r.config_values = schema.values();
  }
  pipeline::ReplaySummary s;
  try {
    s = pipeline::replay(r);
  } catch (...) {
    std::filesystem::remove(file);
    throw;
  }
  std::filesystem::remove(file);

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
  j["gl_ms"] = cap.gl_ms;
  j["replay_ms"] = s.host_seconds * 1e3;
  j["ratio"] = cap.gl_ms > 0 ? s.host_seconds * 1e3 / cap.gl_ms : 0.0;
  j["depth_tests"] = s.depth_tests;
  j["depth_tests_per_s"] = s.host_seconds > 0 ? static_cast<double>(s.depth_tests) / s.host_seconds : 0.0;
  j["cycles"] = s.cycles;
  j["cycles_per_s"] = s.host_seconds > 0 ? static_cast<double>(s.cycles) / s.host_seconds : 0.0;
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

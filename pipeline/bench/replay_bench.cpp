// The simulator-speed benchmark; see replay_bench.h.
#include "pipeline/bench/replay_bench.h"

#include <unistd.h>

#include <filesystem>

#include "pipeline/sim/replay.h"
#include "traces/capture/capture.h"

namespace nbsim::bench {

nlohmann::ordered_json run_replay_bench(const ReplayBenchOptions& o) {
  capture::CaptureOptions c;
  if (std::sscanf(o.size.c_str(), "%dx%d", &c.width, &c.height) != 2) c.width = c.height = 512;
  c.frames = o.frames;
  c.technique = "occlusion_culling";
  c.scene = "city";
  c.options = {{"mode", o.mode}, {"levels-every", "0"}};
  const auto file = std::filesystem::temp_directory_path() / ("nbsim_bench_" + std::to_string(::getpid()) + ".nbt");
  const capture::CaptureSummary cap = capture::capture(c, file.string());

  pipeline::ReplayOptions r;
  r.trace = file;
  const pipeline::ReplaySummary s = pipeline::replay(r);
  std::filesystem::remove(file);

  nlohmann::ordered_json j;
  j["bench"] = "replay";
  j["size"] = o.size;
  j["frames"] = s.frames;
  j["mode"] = o.mode;
  j["draws"] = s.draws;
  j["gl_ms"] = cap.gl_ms;
  j["replay_ms"] = s.host_seconds * 1e3;
  j["ratio"] = cap.gl_ms > 0 ? s.host_seconds * 1e3 / cap.gl_ms : 0.0;
  j["depth_tests"] = s.depth_tests;
  j["depth_tests_per_s"] = s.host_seconds > 0 ? static_cast<double>(s.depth_tests) / s.host_seconds : 0.0;
  j["cycles"] = s.cycles;
  j["cycles_per_s"] = s.host_seconds > 0 ? static_cast<double>(s.cycles) / s.host_seconds : 0.0;
  j["within_thresholds"] = s.within_thresholds();
  return j;
}

}  // namespace nbsim::bench

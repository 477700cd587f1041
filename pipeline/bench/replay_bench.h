// `nbsim bench replay`: the simulator's own speed. Captures a workload with llvmpipe (timing the
// GL technique passes) and replays the same trace through the SystemC model in the same run, so
// the ratio of the two compares like with like on this machine, now. Each technique declares its
// workload beside its capture (capture::BenchPreset in its technique row: scene, path, viewport
// and capture options); the command line overrides any of them.
#pragma once

#include <nlohmann/json.hpp>

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "traces/capture/technique.h"

namespace nbsim::bench {

struct ReplayBenchOptions {
  std::string technique = capture::default_technique();  // a row of the capture's technique table
  int frames = 20;
  // Unset: the technique's preset.
  std::optional<std::string> size, scene, path;
  std::optional<std::string> mode;  // the value of the preset's mode option (its variant: a test mode, a shape, ...)
  std::map<std::string, std::string> options;  // capture options by name, over the preset's
  std::vector<std::string> sets;               // model config keys, unit.field=value (the replay's)
};

// One JSON object: bench, technique, size, frames, scene, path, mode (the preset's mode option's
// value, or null), options (every capture option the bench set), draws, gl_ms (llvmpipe, the
// technique passes), replay_ms, ratio replay/gl, depth tests and cycles per host second, draws
// exact and whether the comparison stayed within thresholds, and "<technique>_summary": the
// replay's technique summary (its per-frame values aside) when its program made one. Throws
// InputError for an unknown technique, a --mode the technique has no option for, or options the
// capture refuses (naming them).
nlohmann::ordered_json run_replay_bench(const ReplayBenchOptions& options);

}  // namespace nbsim::bench

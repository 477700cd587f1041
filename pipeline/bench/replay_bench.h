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
  // Capture-and-replay pairs, one after the other: on a shared machine the host's speed drifts by
  // a factor of two within a minute, so each pair's ratio is taken from two runs side by side and
  // the median pair is reported.
  int repetitions = 3;
};

// One JSON object: bench, technique, size, frames, scene, path, mode (the preset's mode option's
// value, or null), options (every capture option the bench set), draws, repetitions, gl_ms
// (llvmpipe, the technique passes) and replay_ms of the median pair, ratio replay/gl of that pair,
// ratios (every pair's, in run order), depth tests and cycles per host second, draws
// exact and whether the comparison stayed within thresholds, and "<technique>_summary": the
// replay's technique summary (its per-frame values aside) when its program made one. Throws
// InputError for an unknown technique, a --mode the technique has no option for, or options the
// capture refuses (naming them). Every pair must replay to the same cycles and depth tests (the
// capture and the model are deterministic); a difference is an internal error.
nlohmann::ordered_json run_replay_bench(const ReplayBenchOptions& options);

}  // namespace nbsim::bench

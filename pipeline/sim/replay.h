// Replay of a trace through the SystemC model (pipeline/sim/gpu.h), with the counter comparison
// against what GL recorded: per draw, rasterized fragments and passed samples; per frame, the
// depth buffer at GL's snapshots and, when the frame recorded a stencil image named "stencil"
// (kStencilSnapshotName), the stencil buffer at the frame's end. Writes run.json, frames.csv and draws.csv when given a folder.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/sim/gpu.h"

namespace nbsim::pipeline {

struct ReplayOptions {
  std::filesystem::path trace;
  GpuConfig config;
  nlohmann::ordered_json config_values;   // the schema's values, for run.json
  std::optional<std::filesystem::path> out;  // run.json, frames.csv, draws.csv
  std::optional<std::filesystem::path> timeline;  // trace-event JSON of unit activity (model/sim/timeline.h)
  std::optional<std::filesystem::path> vcd;       // busy bit per unit, a VCD
  double depth_tolerance = 1e-6;
  std::function<void(std::uint64_t frames_done, std::uint64_t frames_total)> progress;
};

// The frame's stencil image that `nbsim compare` compares with the model's stencil buffer at the
// frame's end.
inline constexpr const char* kStencilSnapshotName = "stencil";

// One stencil pixel that differs from GL's (the first few of a run are kept).
struct StencilMismatch {
  std::uint32_t frame = 0;
  int x = 0, y = 0;  // y up
  unsigned model = 0, gl = 0;
};

struct ReplaySummary {
  std::uint64_t frames = 0;
  std::uint64_t draws = 0;        // GL's draws with geometry, replayed (compared with GL's counters)
  std::uint64_t draws_exact = 0;  // fragments and passed samples equal to GL's
  // Draws a frame program made itself (query boxes of a culling mode, draws it decided otherwise
  // than GL): replayed and timed, their depth tests counted, but not compared with GL's counters
  // (GL drew nothing like them). In run.json when non-zero.
  std::uint64_t own_draws = 0;
  std::uint64_t passes_not_replayed = 0;  // GLSL N-buffer passes and lookups (no geometry)
  std::uint64_t fragments_model = 0, fragments_gl = 0;
  std::uint64_t passed_model = 0, passed_gl = 0;
  std::uint64_t depth_tests = 0;
  std::uint64_t depth_pixels = 0, depth_pixels_matching = 0;
  double depth_max_abs_error = 0.0;
  // Stencil: the depth unit's stencil tests, and the stencil buffer against GL's "stencil" images
  // (zero when the trace has none); the first kMaxStencilMismatches differing pixels.
  std::uint64_t stencil_tests = 0;
  std::uint64_t stencil_pixels = 0, stencil_pixels_matching = 0;
  static constexpr std::size_t kMaxStencilMismatches = 10;
  std::vector<StencilMismatch> stencil_mismatches;
  std::uint64_t cycles = 0;
  double host_seconds = 0.0;
  std::uint64_t timeline_events = 0, timeline_dropped = 0;  // spans written to / left out of the timeline
  nlohmann::ordered_json stats;  // every unit's statistics
  // The technique program's results (programs.h ProgramResults): its summary's key in run.json and
  // `compare --json` (its technique's name, or the key its results declare: "cull"), its
  // totals (null when no program made results), and whether
  // what the program itself compares with GL holds (part of within_thresholds()).
  std::string program_name;
  nlohmann::ordered_json program;
  bool program_exact = true;

  double fragment_error() const;  // |model - gl| / gl over all draws
  double passed_error() const;
  // The counter comparison's thresholds: total fragment and passed-sample error at most 0.01%, at
  // least 99% of draws exact, at least 99.99% of depth pixels within the tolerance; and every
  // stencil pixel equal to GL's (the stencil buffer is bit-exact or wrong).
  bool within_thresholds() const;
  // The stencil fields appear only for traces that have stencil draws or stencil images.
  nlohmann::ordered_json to_json() const;
};

// Replays the whole trace. Throws InputError for an unreadable trace or bad options. Runs one
// SystemC elaboration: call it once per process.
ReplaySummary replay(const ReplayOptions& options);

}  // namespace nbsim::pipeline

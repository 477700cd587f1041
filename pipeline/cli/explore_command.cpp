// `nbsim explore SWEEP.json --out DIR`: architecture exploration runs. Validates the whole sweep
// file against the config schema, then replays every point in a child process (pipeline/explore/)
// and writes DIR/points/<id>/, DIR/sweep.json, DIR/technique_results.json (the results the traces'
// techniques declare: pipeline/techniques/results.h) and the tidy DIR/results.csv.
#include <fmt/format.h>

#include <chrono>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <thread>

#include "model/common/error.h"
#include "model/config/json_input.h"
#include "pipeline/cli/command.h"
#include "pipeline/cli/progress.h"
#include "pipeline/explore/child.h"
#include "pipeline/explore/results.h"
#include "pipeline/explore/runner.h"
#include "pipeline/explore/sweep.h"
#include "pipeline/sim/gpu.h"

namespace nbsim::cli {

namespace {

namespace fs = std::filesystem;

// The real config check: the settings on a default GpuConfig, then the units' own validation;
// returns every key's effective value, flat.
nlohmann::json check_config(const nlohmann::json& settings, const std::string& origin) {
  pipeline::GpuConfig c;
  config::Schema schema;
  pipeline::GpuConfig::describe(schema, c);
  schema.apply(settings, origin);
  try {
    c.validate();
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", origin, e.what()));
  }
  nlohmann::json flat = nlohmann::json::object();
  const nlohmann::ordered_json values = schema.values();  // kept alive for the loop
  for (const auto& [unit, fields] : values.items())
    for (const auto& [field, v] : fields.items()) flat[unit + "." + field] = v;
  return flat;
}

struct ExploreOptions {
  std::string sweep, out;
  int jobs = 0;
  bool dry_run = false;
  std::uint64_t max_points = explore::kDefaultMaxSweepPoints;
};

int run_explore(const ExploreOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const std::string text = config::read_input_file(o.sweep, "sweep file");
  const nlohmann::ordered_json j = config::parse_input_ordered(text, fmt::format("sweep file '{}'", config::excerpt_text(o.sweep, 1024)), true);

  // Everything is checked before the first child starts.
  const explore::SweepSpec spec = explore::parse_sweep(j, o.sweep, o.max_points);
  std::map<std::string, explore::TraceFile> traces;
  for (const auto& t : spec.traces) {
    try {
      traces.emplace(t, explore::inspect_trace(t));
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: traces: {}", o.sweep, e.what()));
    }
  }
  std::vector<explore::Point> points = explore::expand(spec);
  for (auto& p : points) p.technique = traces.at(p.trace).technique;
  explore::check_points(spec, points, check_config, o.sweep);
  const std::vector<std::string> parameters = explore::parameter_keys(spec);
  const std::size_t sweep_points = points.size();
  explore::add_reference_points(points, parameters, check_config, o.sweep);

  const fs::path out(o.out);
  fs::create_directories(out / "points");
  explore::write_sweep_json(out / "sweep.json", o.sweep, spec, points, parameters, traces, NBSIM_VERSION);
  explore::write_technique_results_json(out / "technique_results.json", points, traces);
  for (const auto& t : spec.traces)
    if (!traces.at(t).note.empty()) fmt::print(stderr, "explore: note: {}\n", traces.at(t).note);
  if (o.dry_run) {
    for (const auto& p : points) fmt::print("{} {} {} {}\n", p.id, p.role, p.trace, p.settings.dump());
    fmt::print("explore: {} points and {} reference points, none run (--dry-run); wrote {}\n", sweep_points,
               points.size() - sweep_points, (out / "sweep.json").string());
    return 0;
  }

  explore::RunOptions ro;
  ro.out = out;
  ro.exe = explore::self_executable();
  ro.jobs = o.jobs > 0 ? o.jobs : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  std::optional<ProgressBar> bar;
  ro.progress = [&bar](std::size_t done, std::size_t total) {
    if (!bar) bar.emplace("explore", static_cast<long long>(total));
    bar->update(static_cast<long long>(done));
  };
  const explore::RunReport r = explore::run_points(points, traces, ro);
  if (bar) bar->finish();
  explore::write_results_csv(out / "results.csv", out, points, parameters, traces, NBSIM_VERSION);

  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (const auto& p : points) {
    const fs::path err = explore::point_dir(out, p) / "error.txt";
    if (!explore::point_done(out, p) && fs::exists(err)) {
      std::string first = explore::tail_lines(err, 1);
      fmt::print("failed: {} ({} {}): {}\n", p.id, p.trace, p.settings.dump(), first);
    }
  }
  fmt::print("explore: {} points ({} of them references): {} run, {} resumed, {} failed, {:.1f} s with {} jobs; wrote {}\n",
             points.size(), points.size() - sweep_points, r.ran, r.resumed, r.failed, seconds, ro.jobs,
             (out / "results.csv").string());
  return r.failed == 0 ? 0 : 1;
}

}  // namespace

void add_explore_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand("explore", "Architecture exploration: replay every point of a sweep file, write results.csv");
  auto o = std::make_shared<ExploreOptions>();
  cmd->add_option("SWEEP", o->sweep, "Sweep file (JSON): traces, set, and axes or points (pipeline/sweeps/)")->required();
  cmd->add_option("--out", o->out, "Output folder: points/<id>/, sweep.json, results.csv; points done there are not run again")
      ->required();
  cmd->add_option("--jobs", o->jobs, "Replays run at a time, one process each (default: the number of cores)")
      ->check(CLI::Range(1, 1024));
  cmd->add_flag("--dry-run", o->dry_run, "Validate and expand the sweep, write sweep.json and list the points; run nothing");
  cmd->add_option("--max-points", o->max_points,
                  "Refuse a sweep of more points than this (traces x axis sizes, or listed points x traces; reference "
                  "points not counted)")
      ->check(CLI::Range(std::uint64_t{1}, std::numeric_limits<std::uint64_t>::max()))
      ->capture_default_str();
  cmd->footer("Sweep file: {\"traces\": [...], \"set\": {key: value}, \"axes\": {key: [values]}} (every combination)\n"
              "or {\"traces\": [...], \"points\": [{key: value, \"trace\": optional}, ...]}; keys as `nbsim config\n"
              "--defaults` lists them. Exit 0 when every point ran, 1 when some failed (see results.csv), 2 on a bad sweep.\n"
              "Errors in results.csv: the columns the trace's technique declares (pipeline/techniques/results.cpp;\n"
              "occlusion_culling: efficiency_lost against nb_hier on the full-resolution float32 N-buffer, every level),\n"
              "cycle_error against gpu.quantum_cycles=0, batch 85, FMA on, counter_error against GL's counters; a\n"
              "reference the sweep lacks is run as an extra point (role=reference). A trace whose technique declares no\n"
              "results gets the generic columns only (a note says so). Plots and Pareto fronts: nbsim report DIR.");
  cmd->callback([&action, o] { action = [o] { return run_explore(*o); }; });
}

}  // namespace nbsim::cli

// `nbsim explore SWEEP.json --out DIR`: architecture exploration runs. Validates the whole sweep
// file against the config schema, then replays every point in a child process (pipeline/explore/)
// and writes DIR/points/<id>/, DIR/sweep.json, DIR/technique_results.json (the results the traces'
// techniques declare: pipeline/techniques/results.h) and the tidy DIR/results.csv.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <csignal>
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
#include "pipeline/explore/search.h"
#include "pipeline/explore/runner.h"
#include "pipeline/explore/slurm.h"
#include "pipeline/explore/sweep.h"
#include "pipeline/techniques/results.h"
#include "pipeline/sim/gpu.h"

namespace nbsim::cli {

namespace {

namespace fs = std::filesystem;

// The real config check: the settings on a default GpuConfig, then the units' own validation;
// returns every key's effective value, flat.
nlohmann::json check_config(const nlohmann::json& settings, const std::string& origin, explore::CheckScope scope) {
  pipeline::GpuConfig c;
  config::Schema schema;
  pipeline::GpuConfig::describe(schema, c);
  schema.apply(settings, origin);
  try {
    if (scope == explore::CheckScope::Whole) c.validate();
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
  std::string engine = "local";
  std::string partition;
  int max_running = 0;
  std::vector<std::string> sbatch_args;
  double poll_seconds = 2.0;
  double cluster_timeout = 300.0;
  std::string point;  // --point N|ID
  bool collect = false;
  bool max_points_set = false, jobs_set = false, slurm_waits_set = false;
  std::string search = "grid";  // grid: every point; front: explore::FrontSearch
  explore::SearchOptions search_options;
};

// Ctrl-C and SIGTERM while a Slurm sweep waits: the wait loop sees the flag and cancels the arrays.
volatile std::sig_atomic_t g_stop_signal = 0;
extern "C" void on_stop_signal(int sig) { g_stop_signal = sig; }

// The sweep, checked and expanded: every point, reference points included, in sweep.json's order.
struct CheckedSweep {
  explore::SweepSpec spec;
  std::map<std::string, explore::TraceFile> traces;
  std::vector<explore::Point> points;
  std::vector<std::string> parameters;
  std::size_t sweep_points = 0;
};

CheckedSweep check_sweep(const ExploreOptions& o) {
  CheckedSweep s;
  const std::string text = config::read_input_file(o.sweep, "sweep file");
  const nlohmann::ordered_json j = config::parse_input_ordered(text, fmt::format("sweep file '{}'", config::excerpt_text(o.sweep, 1024)), true);
  s.spec = explore::parse_sweep(j, o.sweep, o.max_points);
  for (const auto& t : s.spec.traces) {
    try {
      s.traces.emplace(t, explore::inspect_trace(t, o.point.empty()));  // --point writes no checksum: none read
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: traces: {}", o.sweep, e.what()));
    }
  }
  s.points = explore::expand(s.spec);
  for (auto& p : s.points) p.technique = s.traces.at(p.trace).technique;
  explore::check_points(s.spec, s.points, check_config, o.sweep);
  s.parameters = explore::parameter_keys(s.spec);
  s.sweep_points = s.points.size();
  explore::add_reference_points(s.points, s.parameters, check_config, o.sweep);
  return s;
}

// The point --point names: its index in sweep.json's list, or its id.
const explore::Point& find_point(const CheckedSweep& s, const ExploreOptions& o) {
  const std::string& want = o.point;
  const bool is_index = !want.empty() && want.size() < 10 && std::all_of(want.begin(), want.end(), ::isdigit);
  if (is_index) {
    const std::size_t i = std::stoul(want);
    if (i < s.points.size()) return s.points[i];
    throw InputError(fmt::format("--point {}: the sweep '{}' has {} points (0 to {}, reference points included)", want, o.sweep,
                                 s.points.size(), s.points.size() - 1));
  }
  for (const auto& p : s.points)
    if (p.id == want) return p;
  throw InputError(fmt::format("--point '{}': no point of the sweep '{}' has this index or id (sweep.json lists them)", want, o.sweep));
}

// Prints one line per point that failed, from its error.txt.
void print_failures(const fs::path& out, const std::vector<explore::Point>& points) {
  for (const auto& p : points) {
    const fs::path err = explore::point_dir(out, p) / "error.txt";
    if (!explore::point_done(out, p) && fs::exists(err)) {
      std::string first = explore::tail_lines(err, 1);
      fmt::print("failed: {} ({} {}): {}\n", p.id, p.trace, p.settings.dump(), first);
    }
  }
}

void check_option_combinations(const ExploreOptions& o) {
  const bool slurm = o.engine == "slurm";
  if (!slurm && (!o.partition.empty() || o.max_running > 0 || !o.sbatch_args.empty() || o.slurm_waits_set))
    throw InputError("--partition, --max-running, --sbatch-arg, --poll-seconds and --cluster-timeout are options of --engine slurm");
  if (slurm && o.jobs_set) throw InputError("--jobs is an option of --engine local; with --engine slurm, --max-running limits the tasks");
  // sbatch arguments the engine sets itself: a user's value would break the task-to-point mapping.
  for (const auto& a : o.sbatch_args) {
    const std::string name = a.substr(0, a.find('='));
    for (const char* own : {"--array", "-a", "--wrap", "--output", "-o", "--chdir", "-D", "--parsable", "--dependency", "-d"})
      if (name == own || (std::string(own).size() == 2 && name.rfind(own, 0) == 0 && name.size() > 2 && name[1] != '-'))
        throw InputError(fmt::format("--sbatch-arg '{}': nbsim sets {} itself (one array task per point, logs in DIR/slurm/)", a, own));
  }
  const int modes = (o.dry_run ? 1 : 0) + (o.collect ? 1 : 0) + (o.point.empty() ? 0 : 1);
  if (modes > 1) throw InputError("--dry-run, --collect and --point each run alone: give one of them");
  if (slurm && (o.collect || !o.point.empty()))
    throw InputError("--collect and --point run on this machine: leave out --engine slurm");
}

ExploreOptions absolute_paths(ExploreOptions o) {
  std::error_code ec;
  const fs::path sweep = fs::absolute(o.sweep, ec);
  if (!ec) o.sweep = sweep.lexically_normal().string();
  const fs::path out = fs::absolute(o.out, ec);
  if (!ec) o.out = out.lexically_normal().string();
  return o;
}

int run_explore(const ExploreOptions& given) {
  const auto start = std::chrono::steady_clock::now();
  check_option_combinations(given);
  // Points run in children (and on nodes) with absolute paths, whatever the current directory.
  const ExploreOptions o = given.engine == "slurm" || !given.point.empty() ? absolute_paths(given) : given;

  // Everything is checked before the first child starts.
  const CheckedSweep s = check_sweep(o);
  const auto& points = s.points;
  const fs::path out(o.out);

  explore::RunOptions ro;
  ro.out = out;
  ro.exe = explore::self_executable();
  ro.jobs = o.jobs > 0 ? o.jobs : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));

  if (!o.point.empty()) {
    // One point, as an array task runs it: its folder only (other tasks write the shared files).
    const explore::Point& p = find_point(s, o);
    fs::create_directories(out / "points");
    ro.jobs = 1;
    const explore::RunReport r = explore::run_points({p}, s.traces, ro);
    const fs::path dir = explore::point_dir(out, p);
    if (r.resumed) fmt::print("explore: point {} was done before, not run again ({})\n", p.id, dir.string());
    else if (r.failed) fmt::print("explore: point {} failed: {}\n", p.id, explore::tail_lines(dir / "error.txt", 1));
    else fmt::print("explore: point {} ran; wrote {}\n", p.id, (dir / "run.json").string());
    return r.failed == 0 ? 0 : 1;
  }

  std::optional<explore::ClusterInfo> cluster;
  if (o.engine == "slurm" && !o.dry_run) cluster = explore::check_cluster();

  fs::create_directories(out / "points");
  explore::write_sweep_json(out / "sweep.json", o.sweep, s.spec, points, s.parameters, s.traces, NBSIM_VERSION);
  explore::write_technique_results_json(out / "technique_results.json", points, s.traces);
  for (const auto& t : s.spec.traces)
    if (!s.traces.at(t).note.empty()) fmt::print(stderr, "explore: note: {}\n", s.traces.at(t).note);
  if (o.dry_run) {
    for (const auto& p : points) fmt::print("{} {} {} {}\n", p.id, p.role, p.trace, p.settings.dump());
    fmt::print("explore: {} points and {} reference points, none run (--dry-run); wrote {}\n", s.sweep_points,
               points.size() - s.sweep_points, (out / "sweep.json").string());
    return 0;
  }
  if (o.collect) {
    explore::write_results_csv(out / "results.csv", out, points, s.parameters, s.traces, NBSIM_VERSION);
    print_failures(out, points);
    std::size_t done = 0, failed = 0;
    for (const auto& p : points) {
      if (explore::point_done(out, p)) ++done;
      else if (fs::exists(explore::point_dir(out, p) / "error.txt")) ++failed;
    }
    fmt::print("explore: {} points ({} of them references): {} done, {} failed, {} not run (--collect: nothing run); wrote {}\n",
               points.size(), points.size() - s.sweep_points, done, failed, points.size() - done - failed,
               (out / "results.csv").string());
    return done == points.size() ? 0 : 1;
  }

  std::size_t ran = 0, resumed = 0, failed = 0;
  std::string how;
  bool cancelled = false;
  // Runs a set of points on the engine (the whole sweep, or a round of the front search).
  const auto run_set = [&](const std::vector<explore::Point>& pts) {
    if (o.engine == "slurm") {
      explore::SlurmOptions so;
      so.out = out;
      so.exe = ro.exe;
      so.sweep_file = o.sweep;
      so.workdir = fs::current_path();
      so.partition = o.partition;
      so.max_running = o.max_running;
      so.sbatch_args = o.sbatch_args;
      if (o.max_points_set) so.task_args = {"--max-points", std::to_string(o.max_points)};
      so.poll_seconds = o.poll_seconds;
      so.cluster_timeout_seconds = o.cluster_timeout;
      so.cluster = *cluster;
      std::vector<fs::path> shared = {out, fs::path(o.sweep), ro.exe};
      for (const auto& [name, t] : s.traces) shared.push_back(t.path);
      for (const auto& note : explore::node_local_paths(shared))
        fmt::print(stderr, "explore: note: {}: the output folder, the sweep, the traces and nbsim must be on a file system the nodes share\n", note);
      std::optional<ProgressBar> bar;
      so.progress = [&bar](const explore::SlurmProgress& p) {
        if (!bar) bar.emplace("explore (slurm)", static_cast<long long>(p.total));
        bar->update(static_cast<long long>(p.finished), fmt::format("{} running, {} failed", p.running, p.failed));
      };
      struct sigaction sa {}, old_int {}, old_term {};
      sa.sa_handler = on_stop_signal;
      sigemptyset(&sa.sa_mask);
      sigaction(SIGINT, &sa, &old_int);
      sigaction(SIGTERM, &sa, &old_term);
      g_stop_signal = 0;
      so.cancel_requested = [] { return g_stop_signal != 0; };
      explore::SlurmReport r;
      try {
        r = explore::run_points_slurm(pts, so);
      } catch (...) {
        sigaction(SIGINT, &old_int, nullptr);
        sigaction(SIGTERM, &old_term, nullptr);
        throw;
      }
      sigaction(SIGINT, &old_int, nullptr);
      sigaction(SIGTERM, &old_term, nullptr);
      if (bar) bar->finish();
      ran += r.submitted, resumed += r.resumed, failed += r.failed, cancelled = cancelled || r.cancelled;
      how = r.jobs.empty() ? std::string("on Slurm (nothing to submit)")
                           : fmt::format("on Slurm (array job{} {})", r.jobs.size() > 1 ? "s" : "", fmt::join(r.jobs, ","));
    } else {
      std::optional<ProgressBar> bar;
      ro.progress = [&bar](std::size_t done, std::size_t total) {
        if (!bar) bar.emplace("explore", static_cast<long long>(total));
        bar->update(static_cast<long long>(done));
      };
      const explore::RunReport r = explore::run_points(pts, s.traces, ro);
      if (bar) bar->finish();
      ran += r.ran, resumed += r.resumed, failed += r.failed;
      how = fmt::format("with {} jobs", ro.jobs);
    }
  };
  std::vector<explore::Point> written = points;  // the points results.csv lists
  if (o.search == "front") {
    explore::FrontSearch search(points, s.spec.axes.size(), o.search_options);
    explore::ResultsTable table;
    for (;;) {
      const std::vector<std::size_t> round = search.next(table);
      if (round.empty() || cancelled) break;
      std::vector<explore::Point> pts;
      for (std::size_t i : round) pts.push_back(points[i]);
      fmt::print("explore: search round {}: {} points\n", search.round() - 1, pts.size());
      run_set(pts);
      table = explore::results_table(out, points, s.parameters, s.traces, NBSIM_VERSION);
    }
    written.clear();
    for (std::size_t i : search.chosen()) written.push_back(points[i]);
    how += fmt::format("; front search: {} of {} points in {} rounds", written.size(), points.size(), search.round());
  } else {
    run_set(points);
  }
  explore::write_results_csv(out / "results.csv", out, written, s.parameters, s.traces, NBSIM_VERSION);

  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  print_failures(out, written);
  fmt::print("explore: {} points ({} of them references): {} run, {} resumed, {} failed, {:.1f} s {}; wrote {}\n",
             points.size(), points.size() - s.sweep_points, ran, resumed, failed, seconds, how, (out / "results.csv").string());
  if (cancelled) {
    fmt::print("explore: cancelled: the Slurm arrays were cancelled (scancel); points done are kept, run again to resume\n");
    return 130;
  }
  return failed == 0 ? 0 : 1;
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
  cmd->add_option("--engine", o->engine,
                  "Where the points run: local (child processes on this machine) or slurm (one Slurm job array, one task "
                  "per point; the output folder, sweep, traces and nbsim must be on a file system the nodes share)")
      ->check(CLI::IsMember({"local", "slurm"}))
      ->capture_default_str();
  cmd->add_option("--partition", o->partition, "--engine slurm: the partition to submit to (default: the cluster's default)");
  cmd->add_option("--max-running", o->max_running, "--engine slurm: most tasks running at a time (sbatch --array=...%M; a sweep larger than the cluster's MaxArraySize is several arrays, run one after the other)")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--sbatch-arg", o->sbatch_args,
                  "--engine slurm: one more sbatch argument, repeatable, e.g. --sbatch-arg=--time=00:30:00 --sbatch-arg=--mem=2G")
      ->allow_extra_args(false);
  cmd->add_option("--poll-seconds", o->poll_seconds, "--engine slurm: seconds between two looks at the tasks' states (squeue)")
      ->check(CLI::Range(0.1, 3600.0))
      ->capture_default_str();
  cmd->add_option("--cluster-timeout", o->cluster_timeout,
                  "--engine slurm: seconds squeue may fail in a row (a controller down or failing over) before the wait "
                  "ends; the tasks not seen to end are recorded as failed, and --collect merges them once they have run")
      ->check(CLI::Range(1.0, 7.0 * 86400.0))
      ->capture_default_str();
  cmd->add_option("--point", o->point,
                  "Run one point only, N (its index in sweep.json, references included) or its id, into DIR/points/<id>/; "
                  "what each Slurm array task runs. Writes no shared file: --collect merges");
  cmd->add_flag("--collect", o->collect,
                "Run nothing: write sweep.json and results.csv from the points done or failed in DIR (after a Slurm run, "
                "or tasks run with --point)");
  cmd->add_option("--search", o->search,
                  "grid: run every point; front: run a few random points of each trace, then the grid neighbours of each "
                  "trace's Pareto front of its technique's headline cost against its error, round after round, until a "
                  "round adds nothing (axes sweeps; results.csv lists the points run)")
      ->check(CLI::IsMember({"grid", "front"}))
      ->capture_default_str();
  cmd->add_option("--search-start", o->search_options.start, "--search front: random points of each trace in the first round")
      ->check(CLI::Range(std::size_t{1}, std::size_t{1000000}))
      ->capture_default_str();
  cmd->add_option("--search-rounds", o->search_options.rounds, "--search front: rounds at most, the first included")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--search-seed", o->search_options.seed, "--search front: seed of the first round's choice")
      ->capture_default_str();
  cmd->add_option("--search-cost", o->search_options.cost,
                  "--search front: the results.csv column of the cost (default: each technique's headline cost, e.g. "
                  "total_depth_tests_per_frame; cycles_per_frame for the cycles)");
  cmd->add_option("--search-error", o->search_options.error,
                  "--search front: the results.csv column of the error (default: each technique's headline error)");
  cmd->add_flag("--dry-run", o->dry_run, "Validate and expand the sweep, write sweep.json and list the points; run nothing");
  cmd->add_option("--max-points", o->max_points,
                  "Refuse a sweep of more points than this (traces x axis sizes, or listed points x traces; reference "
                  "points not counted)")
      ->check(CLI::Range(std::uint64_t{1}, std::numeric_limits<std::uint64_t>::max()))
      ->capture_default_str();
  std::string references = "Each technique's reference (pipeline/techniques/<name>/results.cpp):\n";
  for (const techniques::TechniqueResults& t : techniques::technique_results())
    references += t.reference ? fmt::format("  {}: {} against {}\n", t.technique, t.headline_error, t.reference->description)
                              : fmt::format("  {}: none declared\n", t.technique);
  cmd->footer("Sweep file: {\"traces\": [...], \"set\": {key: value}, \"axes\": {key: [values]}} (every combination)\n"
              "or {\"traces\": [...], \"points\": [{key: value, \"trace\": optional}, ...]}; keys as `nbsim config\n"
              "--defaults` lists them. Exit 0 when every point ran, 1 when some failed (see results.csv), 2 on a bad sweep.\n"
              "Errors in results.csv: the columns the trace's technique declares against its reference (below),\n"
              "cycle_error against gpu.quantum_cycles=0, batch 85, FMA on, counter_error against GL's counters; a\n"
              "reference the sweep lacks is run as an extra point (role=reference). A trace whose technique declares no\n"
              "results gets the generic columns only (a note says so). Plots and Pareto fronts: nbsim report DIR.\n"
              "Slurm (--engine slurm): the points not done are submitted as one job array (sbatch --array, one task per\n"
              "point running `nbsim explore SWEEP --out DIR --point ID` in this directory); the wait shows the tasks'\n"
              "states; a task that fails or is cancelled is recorded in results.csv with its reason. DIR, the sweep file,\n"
              "the traces and this nbsim executable must be on a file system every node sees at the same path. Ctrl-C\n"
              "cancels the arrays (scancel) and exits 130. No sbatch, no answer from the cluster or an SLURM_CONF that\n"
              "does not parse: exit 2. Resume works across engines: points done by either are not run again.\n" +
              references);
  cmd->callback([&action, o, cmd] {
    o->max_points_set = cmd->count("--max-points") > 0;
    o->jobs_set = cmd->count("--jobs") > 0;
    o->slurm_waits_set = cmd->count("--poll-seconds") + cmd->count("--cluster-timeout") > 0;
    action = [o] { return run_explore(*o); };
  });
}

}  // namespace nbsim::cli

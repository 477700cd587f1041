// The Slurm engine of `nbsim explore --engine slurm`: the points that are not done run as Slurm
// job arrays, one array task per point, each task running `nbsim explore SWEEP --out DIR --point
// ID` on a node. The tasks write into DIR/points/<id>/ exactly as a local run does (runner.h), so
// merging is writing results.csv. The submitting process waits for the array with the cluster's
// task states (squeue), records every task that fails, is cancelled or vanishes in its point's
// error.txt, and cancels the arrays (scancel) when asked to stop.
//
// The output folder, the sweep file, the traces and the nbsim executable must be on a file system
// the nodes share, at the same paths: the tasks are started in the submitting directory (sbatch
// --chdir) with absolute paths.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/explore/sweep.h"

namespace nbsim::explore {

// What the cluster told check_cluster().
struct ClusterInfo {
  std::size_t max_array_size = 1001;  // MaxArraySize: array task ids run 0 .. max_array_size - 1
  std::string cluster_name;
};

// Checks that sbatch, squeue, scancel and scontrol are in PATH, that SLURM_CONF (when set) names a
// file that parses, and that the controller answers (`scontrol show config`). Throws InputError
// with what went wrong (the exit status 2 of the command).
ClusterInfo check_cluster();

struct SlurmProgress {
  std::size_t total = 0;     // tasks submitted
  std::size_t finished = 0;  // tasks in a final state (including the failed ones)
  std::size_t failed = 0;
  std::size_t running = 0;
};

struct SlurmOptions {
  std::filesystem::path out;         // the sweep's folder, absolute
  std::filesystem::path exe;         // the nbsim executable the tasks run, absolute
  std::filesystem::path sweep_file;  // absolute
  std::filesystem::path workdir;     // the tasks' working directory (relative trace paths resolve from it)
  std::string partition;             // "" = the cluster's default
  int max_running = 0;               // tasks of one array running at a time; 0 = no limit
  std::vector<std::string> sbatch_args;  // passed to sbatch as given
  std::vector<std::string> task_args;    // appended to each task's `nbsim explore ... --point ID`
  double poll_seconds = 2.0;             // between two squeue calls
  double cluster_timeout_seconds = 300.0;  // squeue failing this long in a row ends the wait
  ClusterInfo cluster;
  std::function<void(const SlurmProgress&)> progress;  // after each poll
  std::function<bool()> cancel_requested;              // polled often; true: scancel and stop
};

struct SlurmReport {
  std::size_t submitted = 0;  // tasks submitted
  std::size_t resumed = 0;    // points done before, not submitted
  std::size_t failed = 0;     // tasks that failed, were cancelled or vanished
  bool cancelled = false;     // cancel_requested() turned true and the arrays were cancelled
  std::vector<std::string> jobs;  // the array job ids
};

// Submits every point that is not done and waits for the tasks. Throws InputError when sbatch
// refuses the array (after cancelling any array it already submitted).
SlurmReport run_points_slurm(const std::vector<Point>& points, const SlurmOptions& o);

// ------------------------------------------------------------- pieces, tested without a cluster

// One line of `squeue -h -t all -r -o "%i %T %r"`: "<job>_<task> <STATE> <reason>". Lines of
// pending arrays not yet split ("<job>_[0-9%2]"), and lines of plain jobs, give nullopt.
struct TaskState {
  std::string job;
  std::size_t task = 0;
  std::string state;
  std::string reason;
};
std::optional<TaskState> parse_squeue_line(std::string_view line);

// True for states a task never leaves (COMPLETED, FAILED, CANCELLED, TIMEOUT, OUT_OF_MEMORY,
// NODE_FAIL, PREEMPTED, BOOT_FAIL, DEADLINE, SPECIAL_EXIT, REVOKED).
bool is_final_state(std::string_view state);

// sbatch's --array value for `count` tasks: "0-<count-1>", with "%<max_running>" when positive.
std::string array_spec(std::size_t count, int max_running);

// The job id in `sbatch --parsable`'s answer ("<id>" or "<id>;<cluster>"), or "" when it holds none.
std::string parse_sbatch_id(std::string_view answer);

// `text` in single quotes for sh, with every ' written as '\''.
std::string shell_quote(std::string_view text);

// The batch script every array task runs: it takes the offset of its array as $1, reads its point
// id from line offset + SLURM_ARRAY_TASK_ID + 1 of `tasks_file` and execs
// `exe explore sweep --out out --point ID task_args...`.
std::string batch_script(const std::filesystem::path& tasks_file, const std::filesystem::path& exe,
                         const std::filesystem::path& sweep_file, const std::filesystem::path& out,
                         const std::vector<std::string>& task_args);

// Paths that are on a file system other nodes cannot see (tmpfs, ramfs): a note each.
std::vector<std::string> node_local_paths(const std::vector<std::filesystem::path>& paths);

}  // namespace nbsim::explore

// Child processes of the nbsim executable: SystemC allows one simulation per process, so every
// replay of `nbsim table2` and `nbsim explore` runs as `nbsim replay ...` in a child of its own.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace nbsim::explore {

// One child: its arguments after the executable, and the folder that receives its stdout.txt and
// stderr.txt (created when missing).
struct ChildJob {
  std::vector<std::string> args;
  std::filesystem::path dir;
};

// How a child ended. `error` says why when it did not exit with status 0: the last lines of its
// stderr, or the signal, or why it could not start.
struct ChildOutcome {
  bool ok = false;
  int exit_status = -1;  // -1 when killed by a signal or never started
  std::string error;
};

// This executable (/proc/self/exe).
std::filesystem::path self_executable();

// Runs every job, at most `parallel` at a time (at least 1), and calls on_done(index, outcome) in
// this thread as each one ends, in completion order. Returns when all have ended.
void run_children(const std::filesystem::path& exe, const std::vector<ChildJob>& jobs, int parallel,
                  const std::function<void(std::size_t, const ChildOutcome&)>& on_done);

// A short command's result: its exit status (-1 when it could not start, was killed or timed out)
// and what it wrote.
struct CommandResult {
  int status = -1;
  std::string out, err;  // stdout and stderr; err says why when the command could not start or timed out
};

// Runs argv[0] (searched in PATH) with the given arguments, collecting stdout and stderr; kills it
// and reports status -1 when it runs longer than `timeout_s` seconds. The Slurm engine's sbatch,
// squeue, scancel and scontrol calls.
CommandResult run_command(const std::vector<std::string>& argv, double timeout_s);

// True when `name` is an executable file in one of PATH's folders.
bool in_path(const std::string& name);

// The last `max_lines` non-empty lines of a text file ("" when it cannot be read).
std::string tail_lines(const std::filesystem::path& file, std::size_t max_lines);

}  // namespace nbsim::explore

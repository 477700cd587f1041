// Child processes of the nbsim executable; see child.h.
#include "pipeline/explore/child.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <deque>
#include <fstream>
#include <stdexcept>
#include <utility>

extern "C" char** environ;

namespace nbsim::explore {

namespace {

// Starts one job with stdout and stderr redirected into its folder; returns the pid, or -1 with
// `error` set when it cannot start.
pid_t spawn(const std::filesystem::path& exe, const ChildJob& job, std::string& error) {
  std::error_code ec;
  std::filesystem::create_directories(job.dir, ec);
  if (ec) {
    error = fmt::format("cannot create '{}': {}", job.dir.string(), ec.message());
    return -1;
  }
  std::vector<std::string> args;
  args.reserve(job.args.size() + 1);
  args.push_back(exe.string());
  args.insert(args.end(), job.args.begin(), job.args.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string out = (job.dir / "stdout.txt").string(), err = (job.dir / "stderr.txt").string();
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&fa, STDERR_FILENO, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, exe.c_str(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) {
    error = fmt::format("cannot start '{}': {}", exe.string(), std::strerror(rc));
    return -1;
  }
  return pid;
}

ChildOutcome outcome_of(int status, const ChildJob& job) {
  ChildOutcome o;
  if (WIFEXITED(status)) {
    o.exit_status = WEXITSTATUS(status);
    o.ok = o.exit_status == 0;
    if (!o.ok) {
      const std::string tail = tail_lines(job.dir / "stderr.txt", 5);
      o.error = tail.empty() ? fmt::format("exit status {} (no message)", o.exit_status) : tail;
    }
  } else if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    o.error = fmt::format("killed by signal {} ({})", sig, strsignal(sig));
    if (const std::string tail = tail_lines(job.dir / "stderr.txt", 5); !tail.empty()) o.error += ": " + tail;
  } else {
    o.error = "ended in an unknown way";
  }
  return o;
}

}  // namespace

std::filesystem::path self_executable() { return std::filesystem::read_symlink("/proc/self/exe"); }

std::string tail_lines(const std::filesystem::path& file, std::size_t max_lines) {
  std::ifstream in(file);
  if (!in) return {};
  std::deque<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    // A progress bar redraws one line with '\r': keep what was drawn last.
    if (const auto cr = line.rfind('\r'); cr != std::string::npos) line = line.substr(cr + 1);
    if (line.empty()) continue;
    lines.push_back(std::move(line));
    if (lines.size() > max_lines) lines.pop_front();
  }
  std::string text;
  for (const auto& l : lines) text += (text.empty() ? "" : "\n") + l;
  return text;
}

void run_children(const std::filesystem::path& exe, const std::vector<ChildJob>& jobs, int parallel,
                  const std::function<void(std::size_t, const ChildOutcome&)>& on_done) {
  const std::size_t width = parallel < 1 ? 1 : static_cast<std::size_t>(parallel);
  std::vector<std::pair<pid_t, std::size_t>> running;
  std::size_t next = 0;
  while (next < jobs.size() || !running.empty()) {
    while (next < jobs.size() && running.size() < width) {
      std::string error;
      const pid_t pid = spawn(exe, jobs[next], error);
      if (pid < 0)
        on_done(next, ChildOutcome{false, -1, error});
      else
        running.emplace_back(pid, next);
      ++next;
    }
    if (running.empty()) continue;
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error(fmt::format("waitpid failed: {}", std::strerror(errno)));
    }
    for (auto it = running.begin(); it != running.end(); ++it) {
      if (it->first != pid) continue;
      const std::size_t i = it->second;
      running.erase(it);
      on_done(i, outcome_of(status, jobs[i]));
      break;
    }
  }
}

}  // namespace nbsim::explore

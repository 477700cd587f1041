// Child processes of the nbsim executable; see child.h.
#include "pipeline/explore/child.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>

#include <poll.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstdlib>
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

CommandResult run_command(const std::vector<std::string>& argv, double timeout_s) {
  CommandResult r;
  if (argv.empty()) return r;
  int out_pipe[2], err_pipe[2];
  if (pipe2(out_pipe, O_CLOEXEC) != 0) return r.err = std::strerror(errno), r;
  if (pipe2(err_pipe, O_CLOEXEC) != 0) {
    r.err = std::strerror(errno);
    close(out_pipe[0]), close(out_pipe[1]);
    return r;
  }
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, out_pipe[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&fa, err_pipe[1], STDERR_FILENO);
  posix_spawn_file_actions_addopen(&fa, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  std::vector<std::string> args = argv;
  std::vector<char*> cargs;
  for (auto& a : args) cargs.push_back(a.data());
  cargs.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawnp(&pid, args[0].c_str(), &fa, nullptr, cargs.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  close(out_pipe[1]), close(err_pipe[1]);
  if (rc != 0) {
    close(out_pipe[0]), close(err_pipe[0]);
    r.err = fmt::format("cannot start '{}': {}", argv[0], std::strerror(rc));
    return r;
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  std::array<pollfd, 2> fds = {pollfd{out_pipe[0], POLLIN, 0}, pollfd{err_pipe[0], POLLIN, 0}};
  std::array<std::string*, 2> sinks = {&r.out, &r.err};
  bool timed_out = false;
  std::array<char, 4096> buf;
  while (fds[0].fd >= 0 || fds[1].fd >= 0) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) {
      timed_out = true;
      break;
    }
    const int n = poll(fds.data(), fds.size(), static_cast<int>(std::min<long long>(left, 1000)));
    if (n < 0 && errno != EINTR) break;
    for (std::size_t i = 0; i < fds.size(); ++i) {
      if (fds[i].fd < 0 || !(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      const ssize_t got = read(fds[i].fd, buf.data(), buf.size());
      if (got > 0) {
        sinks[i]->append(buf.data(), static_cast<std::size_t>(got));
      } else if (got == 0 || errno != EINTR) {
        close(fds[i].fd);
        fds[i].fd = -1;
      }
    }
  }
  for (auto& f : fds)
    if (f.fd >= 0) close(f.fd);
  if (timed_out) kill(pid, SIGKILL);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (timed_out) {
    r.err += fmt::format("{}'{}' did not answer within {:.0f} s", r.err.empty() ? "" : "\n", argv[0], timeout_s);
    r.status = -1;
  } else {
    r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  return r;
}

bool in_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  const std::string p = path;
  std::size_t start = 0;
  while (start <= p.size()) {
    const std::size_t end = std::min(p.find(':', start), p.size());
    const std::filesystem::path dir = end > start ? std::filesystem::path(p.substr(start, end - start)) : std::filesystem::path(".");
    if (access((dir / name).c_str(), X_OK) == 0 && std::filesystem::is_regular_file(dir / name)) return true;
    start = end + 1;
  }
  return false;
}

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

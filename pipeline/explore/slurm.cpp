// The Slurm engine of `nbsim explore`; see slurm.h.
#include "pipeline/explore/slurm.h"

#include <fmt/format.h>
#include <linux/magic.h>
#include <sys/statfs.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include "model/common/error.h"
#include "pipeline/explore/child.h"
#include "pipeline/explore/runner.h"

namespace nbsim::explore {

namespace fs = std::filesystem;

namespace {

// Tunable. How long one Slurm client command may take before it counts as no answer (a
// controller that does not answer makes them retry for MessageTimeout, 10 s by default).
constexpr double kCommandTimeoutS = 120.0;
// Tunable. A task that squeue stopped listing (MinJobAge after its end, 300 s by default, or a
// purge) is settled from its point folder after this many polls without it.
constexpr int kPollsBeforeGone = 3;
// Tunable. A task that ended COMPLETED or FAILED before its run.json or error.txt shows here (a
// network file system's attribute cache can lag behind the node that wrote them) is settled after
// this long at the latest.
constexpr double kOutcomeGraceS = 30.0;
// Tunable. After a cancel, how long to wait for Slurm to report every task ended.
constexpr double kCancelWaitS = 60.0;

std::string first_lines(const std::string& text, std::size_t n) {
  std::istringstream in(text);
  std::string line, out;
  for (std::size_t i = 0; i < n && std::getline(in, line);) {
    if (line.empty()) continue;
    out += (out.empty() ? "" : "; ") + line;
    ++i;
  }
  return out;
}

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream f(file);
  f << text;
  if (!f) throw std::runtime_error(fmt::format("cannot write {}", file.string()));
}

// One submitted task and what is known of it.
struct Task {
  const Point* point = nullptr;
  std::string job;
  std::size_t index = 0;  // the array task id
  std::string state = "PENDING";
  std::string reason;
  bool settled = false;
  bool failed = false;
  int polls_unlisted = 0;
  // When the task ended without its outcome visible in the point folder yet.
  std::optional<std::chrono::steady_clock::time_point> ended_unseen;
};

std::string task_name(const Task& t) { return fmt::format("{}_{}", t.job, t.index); }

}  // namespace

// ------------------------------------------------------------------------------------ pieces

std::optional<TaskState> parse_squeue_line(std::string_view line) {
  std::istringstream in{std::string(line)};
  std::string id, state, reason;
  if (!(in >> id >> state)) return std::nullopt;
  std::getline(in, reason);
  if (const auto b = reason.find_first_not_of(' '); b != std::string::npos) reason = reason.substr(b);
  else reason.clear();
  const auto us = id.find('_');
  if (us == std::string::npos || us == 0 || us + 1 >= id.size()) return std::nullopt;
  const std::string job = id.substr(0, us), task = id.substr(us + 1);
  if (!std::all_of(job.begin(), job.end(), ::isdigit) || !std::all_of(task.begin(), task.end(), ::isdigit)) return std::nullopt;
  if (task.size() > 9) return std::nullopt;
  return TaskState{job, static_cast<std::size_t>(std::stoul(task)), state, reason};
}

bool is_final_state(std::string_view state) {
  static constexpr std::string_view kFinal[] = {"COMPLETED", "FAILED",    "CANCELLED", "TIMEOUT",      "OUT_OF_MEMORY", "NODE_FAIL",
                                                "PREEMPTED", "BOOT_FAIL", "DEADLINE",  "SPECIAL_EXIT", "REVOKED"};
  // squeue may write "CANCELLED by 0"
  const std::string_view word = state.substr(0, state.find(' '));
  return std::find(std::begin(kFinal), std::end(kFinal), word) != std::end(kFinal);
}

std::string array_spec(std::size_t count, int max_running) {
  std::string s = fmt::format("0-{}", count == 0 ? 0 : count - 1);
  if (max_running > 0) s += fmt::format("%{}", max_running);
  return s;
}

std::string parse_sbatch_id(std::string_view answer) {
  std::string s(answer.substr(0, answer.find_first_of(";\n")));
  while (!s.empty() && (s.back() == ' ' || s.back() == '\r')) s.pop_back();
  if (s.empty() || !std::all_of(s.begin(), s.end(), ::isdigit)) return {};
  return s;
}

std::string shell_quote(std::string_view text) {
  std::string q = "'";
  for (const char c : text) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string batch_script(const fs::path& tasks_file, const fs::path& exe, const fs::path& sweep_file, const fs::path& out,
                         const std::vector<std::string>& task_args) {
  std::string args;
  for (const auto& a : task_args) {
    args += ' ';
    args += shell_quote(a);
  }
  return fmt::format(
      "#!/bin/sh\n"
      "# Written by `nbsim explore --engine slurm`: array task I of the array submitted with offset $1\n"
      "# runs the point on line $1 + I + 1 of the task list.\n"
      "set -eu\n"
      "line=$(( ${{SLURM_ARRAY_TASK_ID:?not a Slurm array task}} + $1 + 1 ))\n"
      "id=$(sed -n \"${{line}}p\" {})\n"
      "[ -n \"$id\" ] || {{ echo \"nbsim explore: no point on line $line of the task list\" >&2; exit 1; }}\n"
      "exec {} explore {} --out {} --point \"$id\"{}\n",
      shell_quote(tasks_file.string()), shell_quote(exe.string()), shell_quote(sweep_file.string()), shell_quote(out.string()), args);
}

std::vector<std::string> node_local_paths(const std::vector<fs::path>& paths) {
  std::vector<std::string> notes;
  for (const auto& p : paths) {
    struct statfs s {};
    if (statfs(p.c_str(), &s) != 0) continue;
    const auto type = static_cast<unsigned long>(s.f_type);
    if (type == TMPFS_MAGIC || type == RAMFS_MAGIC)
      notes.push_back(fmt::format("'{}' is on a {} file system, which other nodes of a cluster do not see", p.string(),
                                  type == TMPFS_MAGIC ? "tmpfs" : "ramfs"));
  }
  return notes;
}

// ------------------------------------------------------------------------------------ cluster

ClusterInfo check_cluster() {
  for (const char* tool : {"sbatch", "squeue", "scancel", "scontrol"})
    if (!in_path(tool))
      throw InputError(fmt::format(
          "--engine slurm: '{}' is not in PATH: Slurm's client commands are needed on the submitting machine (Debian: "
          "slurm-client or slurm-wlm)",
          tool));
  if (const char* conf = std::getenv("SLURM_CONF"); conf && *conf) {
    std::error_code ec;
    if (!fs::is_regular_file(conf, ec))
      throw InputError(fmt::format("--engine slurm: SLURM_CONF names '{}', which is not a file", conf));
  }
  const CommandResult r = run_command({"scontrol", "show", "config"}, kCommandTimeoutS);
  if (r.status != 0) {
    const std::string said = first_lines(r.err + "\n" + r.out, 3);
    const char* conf = std::getenv("SLURM_CONF");
    const std::string where = conf && *conf ? fmt::format("SLURM_CONF '{}'", conf) : std::string("the Slurm configuration");
    if (said.find("arse error") != std::string::npos || said.find("process configuration") != std::string::npos ||
        said.find("needs to be specified") != std::string::npos)
      throw InputError(fmt::format("--engine slurm: {} does not parse: {}", where, said));
    throw InputError(fmt::format("--engine slurm: the Slurm cluster of {} does not answer (`scontrol show config`): {}", where,
                                 said.empty() ? "no message" : said));
  }
  ClusterInfo info;
  std::istringstream in(r.out);
  for (std::string line; std::getline(in, line);) {
    const auto eq = line.find('=');
    if (eq == std::string::npos) continue;
    std::string key = line.substr(0, eq), value = line.substr(eq + 1);
    key.erase(key.find_last_not_of(' ') + 1);
    value.erase(0, value.find_first_not_of(' '));
    if (key == "MaxArraySize" && !value.empty() && std::all_of(value.begin(), value.end(), ::isdigit))
      info.max_array_size = std::max<std::size_t>(1, std::stoul(value));
    if (key == "ClusterName") info.cluster_name = value;
  }
  return info;
}

namespace {

void cancel_jobs(const std::vector<std::string>& jobs) {
  if (jobs.empty()) return;
  std::vector<std::string> argv = {"scancel"};
  argv.insert(argv.end(), jobs.begin(), jobs.end());
  run_command(argv, kCommandTimeoutS);  // a job that already ended is not an error worth stopping for
}

// Settles a task that reached a final state (or vanished: state "GONE"). A point with a run.json
// completed, whatever Slurm says of the task's end; otherwise the point failed, and its error.txt
// says why (the task's own error.txt when it wrote one).
void settle(Task& t, const SlurmOptions& o, bool cancelled_by_us) {
  t.settled = true;
  const Point& p = *t.point;
  if (point_done(o.out, p)) return;
  t.failed = true;
  const fs::path dir = point_dir(o.out, p);
  fs::create_directories(dir);
  const fs::path err = dir / "error.txt";
  const bool task_wrote = fs::exists(err) && fs::file_size(err) > 0;
  if (task_wrote && (t.state == "FAILED" || t.state == "COMPLETED" || t.state == "GONE")) return;
  std::string why;
  if (t.state == "GONE")
    why = fmt::format("Slurm task {} is no longer listed by squeue and left no result in {}", task_name(t), dir.string());
  else if (t.state.rfind("CANCELLED", 0) == 0 && cancelled_by_us)
    why = fmt::format("cancelled: Slurm task {} was cancelled (scancel) when the sweep was stopped", task_name(t));
  else if (t.state == "COMPLETED")
    why = fmt::format("Slurm task {} completed without writing a run.json with a summary", task_name(t));
  else
    why = fmt::format("Slurm task {} ended {}{}", task_name(t), t.state,
                      t.reason.empty() || t.reason == "None" ? std::string() : fmt::format(" ({})", t.reason));
  const std::string log = tail_lines(o.out / "slurm" / fmt::format("{}.out", task_name(t)), 3);
  if (!log.empty()) why += "\n" + log;
  write_text(err, why + "\n");
}

// Sleeps `seconds` in short steps, returning early when a cancel is requested.
bool sleep_unless_cancelled(double seconds, const SlurmOptions& o) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (o.cancel_requested && o.cancel_requested()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return o.cancel_requested && o.cancel_requested();
}

}  // namespace

SlurmReport run_points_slurm(const std::vector<Point>& points, const SlurmOptions& o) {
  SlurmReport report;
  std::vector<const Point*> pending;
  for (const Point& p : points) {
    if (record_refused(o.out, p)) {  // never submitted
      ++report.failed;
      continue;
    }
    if (point_done(o.out, p)) {
      ++report.resumed;
      continue;
    }
    fs::create_directories(point_dir(o.out, p));
    fs::remove(point_dir(o.out, p) / "error.txt");  // a stale error must not stand for this run's outcome
    pending.push_back(&p);
  }
  if (pending.empty()) return report;

  // The task list and the batch script of this submission, kept in OUT/slurm/.
  const fs::path slurm_dir = o.out / "slurm";
  fs::create_directories(slurm_dir);
  char stamp[32];
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  std::strftime(stamp, sizeof stamp, "%Y%m%dT%H%M%SZ", &tm);
  const std::string tag = fmt::format("submit-{}-{}", stamp, ::getpid());
  const fs::path tasks_file = slurm_dir / (tag + ".tasks"), script = slurm_dir / (tag + ".sh");
  {
    std::string list;
    for (const Point* p : pending) list += p->id + "\n";
    write_text(tasks_file, list);
    write_text(script, batch_script(tasks_file, o.exe, o.sweep_file, o.out, o.task_args));
    fs::permissions(script, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec | fs::perms::others_read |
                                fs::perms::others_exec);
  }

  // One array per MaxArraySize points.
  std::vector<Task> tasks;
  tasks.reserve(pending.size());
  const std::size_t chunk = std::max<std::size_t>(1, o.cluster.max_array_size);
  for (std::size_t offset = 0; offset < pending.size(); offset += chunk) {
    const std::size_t n = std::min(chunk, pending.size() - offset);
    std::vector<std::string> argv = {"sbatch",
                                     "--parsable",
                                     "--job-name=nbsim-explore",
                                     "--array=" + array_spec(n, o.max_running),
                                     "--chdir=" + o.workdir.string(),
                                     "--output=" + (slurm_dir / "%A_%a.out").string(),
                                     "--ntasks=1"};
    if (!o.partition.empty()) argv.push_back("--partition=" + o.partition);
    // --max-running bounds each array: with more than one, each waits for the one before.
    if (o.max_running > 0 && !report.jobs.empty()) argv.push_back("--dependency=afterany:" + report.jobs.back());
    argv.insert(argv.end(), o.sbatch_args.begin(), o.sbatch_args.end());
    argv.push_back(script.string());
    argv.push_back(std::to_string(offset));
    const CommandResult r = run_command(argv, kCommandTimeoutS);
    const std::string job = r.status == 0 ? parse_sbatch_id(r.out) : std::string();
    if (job.empty()) {
      cancel_jobs(report.jobs);
      const std::string said = first_lines(r.err + "\n" + r.out, 3);
      throw InputError(fmt::format("--engine slurm: sbatch refused the array{}: {}",
                                   report.jobs.empty() ? "" : fmt::format(" (arrays {} cancelled)", fmt::join(report.jobs, ",")),
                                   said.empty() ? "no message" : said));
    }
    report.jobs.push_back(job);
    for (std::size_t i = 0; i < n; ++i) {
      Task t;
      t.point = pending[offset + i], t.job = job, t.index = i;
      tasks.push_back(std::move(t));
    }
  }
  report.submitted = tasks.size();
  write_text(slurm_dir / (tag + ".jobs"), fmt::format("{}\n", fmt::join(report.jobs, "\n")));

  std::map<std::pair<std::string, std::size_t>, Task*> by_id;
  for (Task& t : tasks) by_id[{t.job, t.index}] = &t;
  const std::string job_list = fmt::format("{}", fmt::join(report.jobs, ","));
  auto last_answer = std::chrono::steady_clock::now();
  std::optional<std::chrono::steady_clock::time_point> cancel_deadline;

  for (;;) {
    if (!report.cancelled && o.cancel_requested && o.cancel_requested()) {
      report.cancelled = true;
      cancel_jobs(report.jobs);
      cancel_deadline = std::chrono::steady_clock::now() + std::chrono::seconds(static_cast<int>(kCancelWaitS));
    }
    const CommandResult q = run_command({"squeue", "-h", "-t", "all", "-r", "-j", job_list, "-o", "%i %T %r"}, kCommandTimeoutS);
    // squeue refuses job ids it no longer knows ("Invalid job id specified"): every task vanished.
    const bool forgotten = q.status != 0 && q.err.find("Invalid job id") != std::string::npos;
    if (q.status == 0 || forgotten) {
      last_answer = std::chrono::steady_clock::now();
      std::vector<bool> listed(tasks.size(), false);
      std::vector<std::string> unsplit;  // arrays squeue lists as one pending range ("<job>_[3-9%2]")
      std::istringstream in(q.status == 0 ? q.out : std::string());
      for (std::string line; std::getline(in, line);) {
        const auto s = parse_squeue_line(line);
        if (!s) {
          if (const auto b = line.find("_["); b != std::string::npos) unsplit.push_back(line.substr(0, b));
          continue;
        }
        const auto it = by_id.find({s->job, s->task});
        if (it == by_id.end()) continue;
        Task& t = *it->second;
        listed[static_cast<std::size_t>(&t - tasks.data())] = true;
        if (t.settled) continue;
        t.state = s->state.substr(0, s->state.find(' '));
        t.reason = s->reason;
        t.polls_unlisted = 0;
        if (!is_final_state(t.state)) continue;
        // COMPLETED leaves a run.json, FAILED (the point failed) an error.txt: wait a little for them.
        const bool outcome_visible = point_done(o.out, *t.point) || (t.state != "COMPLETED" && t.state != "FAILED") ||
                                     (t.state == "FAILED" && fs::exists(point_dir(o.out, *t.point) / "error.txt"));
        if (!outcome_visible && !t.ended_unseen) t.ended_unseen = std::chrono::steady_clock::now();
        if (outcome_visible ||
            std::chrono::duration<double>(std::chrono::steady_clock::now() - *t.ended_unseen).count() > kOutcomeGraceS)
          settle(t, o, report.cancelled);
      }
      for (std::size_t i = 0; i < tasks.size(); ++i) {
        Task& t = tasks[i];
        if (t.settled || listed[i] || std::find(unsplit.begin(), unsplit.end(), t.job) != unsplit.end()) continue;
        if (++t.polls_unlisted >= kPollsBeforeGone) {
          t.state = "GONE";
          settle(t, o, report.cancelled);
        }
      }
    } else if (std::chrono::duration<double>(std::chrono::steady_clock::now() - last_answer).count() > o.cluster_timeout_seconds) {
      for (Task& t : tasks)
        if (!t.settled) {
          t.settled = t.failed = true;
          write_text(point_dir(o.out, *t.point) / "error.txt",
                     fmt::format("squeue did not answer for {:.0f} s while Slurm task {} was {}: {}; run `nbsim explore ... "
                                 "--collect` once the array has ended\n",
                                 o.cluster_timeout_seconds, task_name(t), t.state, first_lines(q.err, 2)));
        }
    }
    if (cancel_deadline && std::chrono::steady_clock::now() > *cancel_deadline) {
      for (Task& t : tasks)
        if (!t.settled) {
          t.state = "CANCELLED";
          settle(t, o, true);
        }
    }

    SlurmProgress pr;
    pr.total = tasks.size();
    for (const Task& t : tasks) {
      pr.finished += t.settled;
      pr.failed += t.failed;
      pr.running += !t.settled && t.state == "RUNNING";
    }
    if (o.progress) o.progress(pr);
    if (pr.finished == pr.total) break;
    const bool cancel_now = sleep_unless_cancelled(report.cancelled ? std::min(o.poll_seconds, 0.5) : o.poll_seconds, o);
    (void)cancel_now;  // the loop's head acts on it
  }
  for (const Task& t : tasks) report.failed += t.failed;
  return report;
}

}  // namespace nbsim::explore

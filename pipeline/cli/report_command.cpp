// `nbsim report DIR`: the exploration report. The analysis is Python (analysis/report.py, Debian's
// matplotlib); this command finds it and the interpreter, runs it on DIR, and passes its exit
// status on. The script reads only the CSV/JSON that the other commands wrote under DIR.
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "pipeline/cli/command.h"

extern char** environ;

namespace nbsim::cli {

namespace {

namespace fs = std::filesystem;

struct ReportOptions {
  std::string dir;
  std::string python = "/usr/bin/python3";
  std::string analysis;  // folder of report.py; empty: $NBSIM_ANALYSIS_DIR, then the source tree's
};

fs::path analysis_dir(const ReportOptions& o) {
  if (!o.analysis.empty()) return o.analysis;
  if (const char* env = std::getenv("NBSIM_ANALYSIS_DIR"); env && *env) return env;
  return NBSIM_ANALYSIS_DIR;
}

int run_report(const ReportOptions& o) {
  if (!fs::is_directory(o.dir)) throw InputError(fmt::format("report folder '{}' does not exist", o.dir));
  const fs::path script = analysis_dir(o) / "report.py";
  if (!fs::is_regular_file(script))
    throw InputError(fmt::format("the analysis script '{}' is missing (set --analysis or NBSIM_ANALYSIS_DIR)", script.string()));
  if (!fs::exists(o.python))
    throw InputError(fmt::format("Python interpreter '{}' not found (scripts/setup installs python3-matplotlib)", o.python));
  std::vector<std::string> args = {o.python, script.string(), o.dir};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (const int e = posix_spawn(&pid, o.python.c_str(), nullptr, nullptr, argv.data(), environ); e != 0)
    throw std::runtime_error(fmt::format("cannot start {}: {}", o.python, std::strerror(e)));
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw std::runtime_error(fmt::format("waiting for {}: {}", o.python, std::strerror(errno)));
  if (WIFSIGNALED(status)) throw std::runtime_error(fmt::format("{} was killed by signal {}", script.string(), WTERMSIG(status)));
  return WEXITSTATUS(status);
}

}  // namespace

void add_report_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand("report", "Write DIR/report/index.html: tables and plots from the outputs under DIR");
  auto o = std::make_shared<ReportOptions>();
  cmd->add_option("DIR", o->dir, "Folder holding any of: table1.jsonl, figure4_map.csv, table2/ (nbsim table2 --out), "
                                 "sweeps/<name>/ (nbsim explore --out); or one nbsim explore --out folder itself")
      ->required();
  cmd->add_option("--python", o->python, "Python 3 interpreter with matplotlib")->capture_default_str();
  cmd->add_option("--analysis", o->analysis, "Folder of the analysis scripts (default: $NBSIM_ANALYSIS_DIR or the source tree's)");
  cmd->footer("scripts/demo makes such a folder (out/demo). The report renders every section whose inputs exist and\n"
              "lists the missing ones. Exit 0 on success, 2 when DIR holds nothing usable or an input is malformed.");
  cmd->callback([&action, o] { action = [o] { return run_report(*o); }; });
}

}  // namespace nbsim::cli

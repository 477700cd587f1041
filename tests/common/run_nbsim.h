// Runs the built `nbsim` executable (NBSIM_EXE, set by CMake) for the command-line tests and
// collects its exit status, stdout and stderr.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "tests/common/scratch.h"

namespace nbsim::testing {

struct CliResult {
  int status = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

// Runs `env NBSIM_EXE args` through the shell; `env` is "" or "NAME=value ..." (a space at the end).
inline CliResult run_nbsim_env(const std::string& env, const std::string& args) {
  CliResult r;
  const std::filesystem::path err = std::filesystem::temp_directory_path() / ("nbsim_stderr_" + std::to_string(::getpid()) + ".txt");
  const std::string cmd = env + std::string(NBSIM_EXE) + " " + args + " 2>" + err.string();
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), static_cast<int>(buf.size()), p)) r.out += buf.data();
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  std::ifstream e(err);
  r.err.assign(std::istreambuf_iterator<char>(e), {});
  std::filesystem::remove(err);
  return r;
}

inline CliResult run_nbsim(const std::string& args) { return run_nbsim_env("", args); }

// What a shell command writes on stdout (its exit status is not looked at).
inline std::string shell_output(const std::string& cmd) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return out;
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), static_cast<int>(buf.size()), p)) out += buf.data();
  pclose(p);
  return out;
}

inline bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace nbsim::testing

// Scratch folders for tests: one per test process and prefix, <temp>/<prefix>_<pid>, emptied on its
// first use in the process and removed when the process ends.
//
// Why emptied: process ids are reused. A folder left by an earlier run with the same pid (a crash,
// NBSIM_KEEP_SCRATCH, or an older build that did not clean up) would otherwise hand that run's files
// to this one: a capture cached by name, or an explore folder whose points count as done. That
// made a test compare a fresh capture with one from an older capture code (seen in CI).
// Set NBSIM_KEEP_SCRATCH=1 to keep the folders for a look after the run.
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <set>
#include <string>
#include <system_error>

namespace nbsim::testing {

namespace detail {

// The folders this process made; removed at exit by the process that made them (a forked child
// that exits must not remove its parent's folders).
class ScratchRegistry {
 public:
  // Makes `dir` empty the first time it is asked for in this process.
  void fresh(const std::filesystem::path& dir) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!made_.insert(dir.string()).second) return;
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
    std::filesystem::create_directories(dir);
  }
  ~ScratchRegistry() {
    if (::getpid() != owner_ || std::getenv("NBSIM_KEEP_SCRATCH")) return;
    for (const auto& d : made_) {
      std::error_code ec;
      std::filesystem::remove_all(d, ec);
    }
  }

 private:
  std::mutex mutex_;
  std::set<std::string> made_;
  pid_t owner_ = ::getpid();
};

inline ScratchRegistry& scratch_registry() {
  static ScratchRegistry r;
  return r;
}

}  // namespace detail

// This process's scratch folder for `prefix`: <temp>/<prefix>_<pid>, empty on first use.
inline std::filesystem::path scratch_dir(const std::string& prefix) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / (prefix + "_" + std::to_string(::getpid()));
  detail::scratch_registry().fresh(dir);
  std::filesystem::create_directories(dir);  // a test may have removed it since
  return dir;
}

// A path in it: <temp>/<prefix>_<pid>/<name>.
inline std::filesystem::path scratch_path(const std::string& prefix, const std::string& name) {
  return scratch_dir(prefix) / name;
}

}  // namespace nbsim::testing

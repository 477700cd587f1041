// A progress bar on stderr for long runs, drawn only when stderr is a terminal (so logs and CI
// output stay clean). Usage: Progress p("capture", total); p.update(done); p.finish();
#pragma once

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace nbsim::cli {

class ProgressBar {
 public:
  ProgressBar(std::string what, long long total)
      : what_(std::move(what)), total_(total), tty_(isatty(STDERR_FILENO) != 0), start_(std::chrono::steady_clock::now()) {}

  // `note` (e.g. "2 running, 1 failed") is drawn after the rate.
  void update(long long done, const std::string& note = {}) {
    if (!tty_ || total_ <= 0) return;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const int width = 30, filled = static_cast<int>(width * done / total_);
    const double rate = s > 0 ? static_cast<double>(done) / s : 0.0;
    const double eta = rate > 0 ? static_cast<double>(total_ - done) / rate : 0.0;
    std::fprintf(stderr, "\r%s [%.*s%*s] %lld/%lld  %.1f/s  eta %.0fs %s%s", what_.c_str(), filled,
                 "##############################", width - filled, "", done, total_, rate, eta, note.c_str(),
                 note.empty() ? "" : "   ");
    std::fflush(stderr);
  }

  void finish() {
    if (tty_) std::fprintf(stderr, "\n");
  }

 private:
  std::string what_;
  long long total_;
  bool tty_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace nbsim::cli

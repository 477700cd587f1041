// `nbsim capture apitrace TRACE.trace -o OUT.nbt`: a real OpenGL program's frames, from an apitrace
// trace, as a trace of technique apps. The trace is replayed headless on Mesa by apitrace's
// eglretrace with nbsim's interposer loaded (traces/apitrace/interposer.cpp), which records every
// draw's positions, state and samples passed; the recording then becomes the trace
// (traces/capture/apps/convert.h).
#include "pipeline/cli/command.h"

#include <fmt/format.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>

#include "model/common/error.h"
#include "pipeline/cli/progress.h"
#include "pipeline/explore/child.h"
#include "traces/capture/apps/convert.h"

namespace nbsim::cli {

namespace {

struct ApitraceArgs {
  std::string trace, out, frames, eglretrace = "eglretrace", interposer, keep;
  double timeout_s = 3600.0;
  bool overhead = false;
  bool allow_unhandled = false;
};

// The interposer library: --interposer, else NBSIM_INTERPOSER, else the build's.
std::filesystem::path interposer_path(const ApitraceArgs& a) {
  std::filesystem::path p = a.interposer;
  if (p.empty())
    if (const char* env = std::getenv("NBSIM_INTERPOSER")) p = env;
  if (p.empty()) p = NBSIM_INTERPOSER_PATH;
  if (!std::filesystem::is_regular_file(p))
    throw InputError(fmt::format("the interposer library '{}' is not there (build the nbsim_interpose target, or name it with --interposer)",
                                 p.string()));
  return p;
}

// "A:B" -> {A, B}; InputError naming --frames.
std::pair<std::uint32_t, std::uint32_t> parse_frames(const std::string& s) {
  unsigned a = 0, b = 0;
  char tail = 0;
  if (std::sscanf(s.c_str(), "%u:%u%c", &a, &b, &tail) != 2 || a > b || b > 10000000)
    throw InputError(fmt::format("--frames '{}': expected FIRST:LAST, swaps counted from 0, FIRST <= LAST", s));
  return {a, b};
}

// One run of eglretrace on the trace with the interposer: recording into `recording` (empty: pass
// through, stopping after the frames asked for). Returns its seconds; InputError with its stderr
// when it failed.
double run_retrace(const ApitraceArgs& a, const std::filesystem::path& lib, const std::string& recording) {
  std::vector<std::string> argv = {"env", "LD_PRELOAD=" + lib.string(), "WAFFLE_PLATFORM=surfaceless_egl"};
  if (!recording.empty()) argv.push_back("NBSIM_IP_OUT=" + recording);
  if (!a.frames.empty()) argv.push_back("NBSIM_IP_FRAMES=" + a.frames);
  argv.insert(argv.end(), {a.eglretrace, "--headless", a.trace});
  const auto t0 = std::chrono::steady_clock::now();
  const explore::CommandResult r = explore::run_command(argv, a.timeout_s);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (r.status != 0) {
    std::string err = r.err;
    if (err.size() > 2000) err = "..." + err.substr(err.size() - 2000);
    throw InputError(fmt::format("eglretrace could not replay '{}' (exit status {}):\n{}", a.trace, r.status, err));
  }
  return seconds;
}

}  // namespace

void add_apps_commands(CLI::App& app, Action& action) {
  CLI::App* capture = app.get_subcommand("capture");
  auto a = std::make_shared<ApitraceArgs>();
  auto* cmd = capture->add_subcommand(
      "apitrace", "Record a real OpenGL program's frames from an apitrace trace (eglretrace on Mesa with nbsim's interposer) as a "
                  "trace of technique apps");
  cmd->add_option("trace", a->trace, "The apitrace trace (apitrace trace -o FILE.trace PROGRAM)")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--out", a->out, "Trace file to write")->required();
  cmd->add_option("--frames", a->frames, "Frames to record, FIRST:LAST (swaps counted from 0; default: every frame)");
  cmd->add_option("--eglretrace", a->eglretrace, "apitrace's EGL replayer")->capture_default_str();
  cmd->add_option("--interposer", a->interposer, "The interposer library (default: NBSIM_INTERPOSER, else the build's)");
  cmd->add_option("--keep-recording", a->keep, "Also keep the interposer's raw recording in this file");
  cmd->add_option("--timeout", a->timeout_s, "Seconds the replay may take")->check(CLI::Range(1.0, 1e6))->capture_default_str();
  cmd->add_flag("--allow-unhandled", a->allow_unhandled,
                "Keep the trace when the program uses a GL feature the interposer does not handle (immediate mode, display "
                "lists, depth blits): its frames are marked, and the model counts them apart");
  cmd->add_flag("--overhead", a->overhead,
                "Also replay the same frames without recording and print the recording's overhead (interposed / plain replay time)");
  cmd->footer("Needs apitrace's eglretrace (Debian: apt install apitrace). Exit 2 with a message for a trace eglretrace cannot "
              "replay, an OpenGL ES trace (ES has no samples-passed query), a program that uses a GL feature the interposer does not "
              "handle (named; --allow-unhandled keeps the trace), or a frame above the trace format's limits; no trace is written "
              "then.");
  cmd->callback([&action, a] {
    action = [a] {
      if (!a->frames.empty()) parse_frames(a->frames);
      if (!explore::in_path(a->eglretrace) && !std::filesystem::is_regular_file(a->eglretrace))
        throw InputError(fmt::format("'{}' not found: nbsim capture apitrace replays the trace with apitrace's eglretrace "
                                     "(Debian: apt install apitrace)",
                                     a->eglretrace));
      const std::filesystem::path lib = interposer_path(*a);
      const std::filesystem::path recording = a->keep.empty() ? std::filesystem::path(a->out + ".recording") : std::filesystem::path(a->keep);
      struct Remove {
        std::filesystem::path p;
        bool keep;
        ~Remove() {
          std::error_code ec;
          if (!keep) std::filesystem::remove(p, ec);
        }
      } cleanup{recording, !a->keep.empty()};
      fmt::print("replaying {} with the interposer...\n", a->trace);
      std::fflush(stdout);
      const double recorded_s = run_retrace(*a, lib, recording.string());
      std::string command_line = "nbsim capture apitrace " + a->trace;  // as given: the golden outputs capture it again
      if (!a->frames.empty()) command_line += " --frames " + a->frames;
      command_line += " -o " + a->out;
      apitrace::ConvertOptions options;
      options.apitrace = std::filesystem::path(a->trace).filename().string();
      options.command_line = command_line;
      long long total = 0;
      if (!a->frames.empty()) {
        const auto [first, last] = parse_frames(a->frames);
        total = static_cast<long long>(last) - first + 1;
      }
      ProgressBar bar("convert", total);
      const apitrace::ConvertSummary s = apitrace::convert_recording(recording, a->out, options, [&](std::uint32_t done) { bar.update(static_cast<int>(done)); });
      bar.finish();
      fmt::print("recorded {} frames, {} draws ({} captured, {} not: fixed function {}, no gl_Position {}, own feedback {}, own query {}, "
                 "separable {}, indirect {}), {} clears, {} depth changes; {}: {:.2f} MB; interposed replay {:.2f} s\n",
                 s.frames, s.draws, s.captured, s.draws - s.captured, s.skipped[1], s.skipped[2], s.skipped[3], s.skipped[4], s.skipped[5],
                 s.skipped[6], s.clears, s.depth_changes, a->out, static_cast<double>(s.bytes) / 1e6, recorded_s);
      for (const auto& [name, count] : s.unhandled) fmt::print("  not captured: {} ({} times)\n", name, count);
      if (!s.unhandled.empty() && !a->allow_unhandled) {
        std::error_code ec;
        std::filesystem::remove(a->out, ec);
        std::string names;
        for (const auto& [name, count] : s.unhandled) names += fmt::format("{}{} ({} times)", names.empty() ? "" : ", ", name, count);
        throw InputError(fmt::format("the program uses GL features the interposer does not handle: {}; what they draw is not recorded, "
                                     "so the model's depth would not be GL's (no trace written; --allow-unhandled keeps it, those "
                                     "frames marked)",
                                     names));
      }
      if (a->overhead) {
        const double plain_s = run_retrace(*a, lib, "");
        fmt::print("recording overhead: interposed {:.2f} s, plain {:.2f} s, ratio {:.2f}\n", recorded_s, plain_s, recorded_s / plain_s);
      }
      return 0;
    };
  });
}

}  // namespace nbsim::cli

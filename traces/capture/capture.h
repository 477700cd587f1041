// `nbsim capture TECHNIQUE --scene NAME --path NAME`: renders a camera path through a scene with
// one technique on Mesa and writes the trace (traces/FORMAT.md). The technique, the scene and the
// camera path are chosen by name from their tables (technique.h, scenes.h, paths.h); the renderer
// does the work; this file sets it up, writes the header and streams the frames.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "traces/capture/camera.h"
#include "traces/capture/plugin.h"
#include "traces/capture/technique.h"

namespace nbsim::capture {

struct CaptureOptions {
  std::string technique = default_technique();
  std::string scene = "city";
  std::string path = "walk";
  // Whether --scene and --path were given (a technique that draws no scene refuses them, but for
  // the spelling older captures were recorded with: --scene boxes --boxes 0 --path fly).
  bool scene_given = false, path_given = false;
  int width = 512;
  int height = 512;
  int frames = 60;
  bool reversed_z = false;  // ZERO_TO_ONE clip control, depth func GREATER, clear 0
  // The options of the technique, the scene and the path by name ("mode" = "nb_hier", "seed" =
  // "1", ...); unset ones take their defaults, one that none of the three declares is an error.
  OptionValues options;
  std::string command_line;  // header property; canonical_command_line() when empty
  // A test hook (no command-line spelling): when not empty, these camera poses replace the path's,
  // one a frame (`frames` must be their number), so that a test can place the camera exactly.
  std::vector<CameraPose> poses;
};

struct CaptureSummary {
  int frames = 0;
  double seconds = 0.0;        // wall time of the whole capture
  double gl_ms = 0.0;          // summed technique time (GL, per frame)
  std::uint64_t bytes = 0;     // trace file size
  std::uint64_t draws = 0;
  // For techniques that cull objects (zero otherwise).
  std::uint64_t objects_rendered = 0, objects_visible = 0, visible_not_rendered = 0;
  // The technique's own counts (CapturedFrame::counts), summed over the frames, in first-seen order.
  std::vector<std::pair<std::string, std::uint64_t>> technique_counts;
};

// Progress callback: frames done, frames total.
using Progress = std::function<void(int, int)>;

// Throws InputError on an unknown technique, scene or path, a bad or undeclared option, a bad size
// or frame count, or a file that cannot be written. The frames go to a temporary file beside
// `out_path` ("OUT.partial"), renamed to `out_path` once the trace is whole; a capture that fails
// removes it, so a failure never leaves a partial trace (nor touches an existing `out_path`).
CaptureSummary capture(const CaptureOptions& options, const std::string& out_path, const Progress& progress = {});

// The command line that repeats a capture in the current spelling, every option spelled out:
// "nbsim capture TECHNIQUE --scene S --path P --size WxH --frames N [scene, path and technique
// options] [--reversed-z] -o OUT".
std::string canonical_command_line(const CaptureOptions& options, const std::string& out_path);

}  // namespace nbsim::capture

// `nbsim capture city`: renders a camera path through the procedural city on Mesa and writes the
// trace (traces/FORMAT.md). The renderer does the work; this file sets it up and streams frames.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "traces/capture/camera.h"
#include "traces/format/records.h"

namespace nbsim::capture {

struct CaptureOptions {
  int width = 512;
  int height = 512;
  int frames = 60;
  PathKind path = PathKind::Walk;
  std::uint32_t seed = 1;
  int objects = 6000;
  trace::TestMode mode = trace::TestMode::NBufferHier;
  bool reversed_z = false;
  int levels_every = 10;  // record the GLSL N-buffer levels every k-th frame (0: never)
  std::string command_line;
};

struct CaptureSummary {
  int frames = 0;
  double seconds = 0.0;        // wall time of the whole capture
  double gl_ms = 0.0;          // summed technique time (GL, per frame)
  std::uint64_t bytes = 0;     // trace file size
  std::uint64_t draws = 0;
  std::uint64_t objects_rendered = 0, objects_visible = 0, visible_not_rendered = 0;
};

// Progress callback: frames done, frames total.
using Progress = std::function<void(int, int)>;

CaptureSummary capture_city(const CaptureOptions& options, const std::string& out_path, const Progress& progress = {});

// "oq", "oq_hier", "nb", "nb_hier", "none"; empty optional-like: throws InputError on others.
trace::TestMode parse_test_mode(const std::string& s);

}  // namespace nbsim::capture

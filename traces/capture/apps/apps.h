// The apps technique on the capture side. Its traces are a real OpenGL program's frames, recorded
// from an apitrace trace by `nbsim capture apitrace` (convert.h, recording.h, and the interposer,
// traces/apitrace/interposer.cpp). Its renderer capture, `nbsim capture apps`, is the same kind of
// trace made by a program of the project's own: the scene drawn the way a program that never asked
// for culling draws it (the depth cleared, then every object in the frustum, in the scene's order,
// one draw call each, depth test LESS, back faces culled), recorded with the same records. It is
// the workload of the technique's bench and tests, and the native side of the check that a
// recording through apitrace gives the same draws and counters.
#pragma once

#include <memory>
#include <vector>

#include "traces/capture/technique.h"

namespace nbsim::capture {

const std::vector<OptionSpec>& apps_options();
std::unique_ptr<Technique> make_apps(const TechniqueSetup& setup);

}  // namespace nbsim::capture

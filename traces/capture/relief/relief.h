// The relief-texture technique (Baboud & Decoret; the N-buffer walk is the N-buffer paper's own
// future work) on the capture side: `nbsim capture relief`. The heightfield (--field: a procedural
// kind from model/relief/heightfield.h, or --field-file, any single-channel image OpenImageIO
// reads, heights in [0, 1]) is uploaded with its safety radius (computed, or --radius-file checked
// against the field) and GL builds its max N-buffer. Each frame views the box [0, 1]^2 x
// [0, --box-height] from its own camera: the angle from the box's up axis cycles through --angles
// (0 head-on, 89 grazing), the azimuth comes from --seed and the frame. Every --methods method
// draws the box once (role relief_box, gl_walk.h); records: RLFH and one RLFF a draw
// (traces/format/relief/relief_chunk.h). The exact reference (model/relief/reference.h) scores GL's hits:
// the capture's counts give each method's hit error.
// --frustum A replaces the box by a reverse-perspective frustum (view.h). --placement city stands the
// box in the capture's scene instead (--box-at), viewed by the observer along --path: the scene's
// depth is drawn first (role scene) and the box draws' early depth test culls what it hides.
// Otherwise the observer is not used: the scene, the camera path and the projection only satisfy the
// capture driver (use `--scene boxes --boxes 0`); --size is the viewport.
#pragma once

#include <memory>
#include <vector>

#include "traces/capture/plugin.h"
#include "traces/capture/technique.h"

namespace nbsim::capture {

const std::vector<OptionSpec>& relief_options();
std::unique_ptr<Technique> make_relief(const TechniqueSetup& setup);
// Its `nbsim bench replay` workload.
BenchPreset relief_bench_preset();

}  // namespace nbsim::capture

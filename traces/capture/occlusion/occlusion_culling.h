// The occlusion-culling technique of the N-buffer paper (sections 3.1 and 4.2) on the capture side.
// Per frame: frustum culling -> occluders (last frame's visible objects) -> [GLSL N-buffer build]
// -> bounds tests of every other object in the frustum (occlusion queries or N-buffer lookups,
// flat or over the BVH; model/scene/visibility.h decides which) -> the objects found visible ->
// ID-buffer ground truth. Records every draw with its GL counters and clip positions, the depth
// after the occluders and at the end, and every --levels-every-th frame the GLSL N-buffer levels.
#pragma once

#include <memory>
#include <vector>

#include "traces/capture/plugin.h"
#include "traces/capture/technique.h"

namespace nbsim::capture {

// --mode (oq, oq_hier, nb, nb_hier, none: the test_mode names of model/scene/frame.h) and
// --levels-every; the technique's row in techniques.cpp lists them.
const std::vector<OptionSpec>& occlusion_culling_options();

std::unique_ptr<Technique> make_occlusion_culling(const TechniqueSetup& setup);
// Its `nbsim bench replay` workload.
BenchPreset occlusion_culling_bench_preset();

}  // namespace nbsim::capture

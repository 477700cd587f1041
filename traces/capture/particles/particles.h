// The particles technique of the N-buffer paper (sections 3.2 and 4.3) on the capture side:
// point sprites of the particle systems (particle_systems.h), culled in the vertex stage.
// Per frame: the scene's objects in the frustum (role Scene, their depth) -> [the max N-buffer up
// to the level the largest sprite needs, capped by --level-cap (mode nb), or the Hi-Z pyramid
// (mode hiz)] -> the particles as GL_POINTS, depth test on, depth write off, one draw an emitter
// (role Particles; gl_Position and gl_PointSize captured), each vertex culled by --mode -> the
// reference pass (every particle, a passed-sample counter each; not a recorded draw). Records
// the scene depth ("scene"), every --levels-every-th frame the N-buffer levels, and the PRTC
// record (traces/format/particles/particles_chunk.h) with every particle's centre, depth, size, the
// decision GL took, its lookups and its reference samples.
#pragma once

#include <memory>
#include <vector>

#include "traces/capture/plugin.h"
#include "traces/capture/technique.h"

namespace nbsim::capture {

// --particles, --sprite, --mode, --level-cap, --emitters, --levels-every.
const std::vector<OptionSpec>& particles_options();

std::unique_ptr<Technique> make_particles(const TechniqueSetup& setup);
// Its `nbsim bench replay` workload.
BenchPreset particles_bench_preset();

}  // namespace nbsim::capture

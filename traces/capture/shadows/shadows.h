// The shadow-volume technique of the N-buffer paper (sections 3.3 and 4.4) on the capture side:
// stencil shadow volumes of a spot light, culled and clamped with min/max litmaps and two N-buffers.
// A caster is a scene object with a closed surface (volumes.h); open objects only receive.
// Per frame:
//  1. the observer's depth: the objects in the view frustum (role Scene; depth and stencil in one
//     DEPTH24_STENCIL8 buffer);
//  2. the litmaps: the objects in the light's frustum seen from the light, LEQUAL into the min
//     litmap (clear 1) and GEQUAL into the max litmap (clear 0), every fragment the observer does
//     not see discarded after reprojection (role Litmap, shaders/shadows/litmap.frag);
//  3. a min and a max N-buffer over them (GLSL, the shared glsl_nbuffer.h, every level);
//  4. per caster: its light-space rectangle (its bounds' 8 corners, grown by one lexel), z_min
//     (min N-buffer: the nearest visible receiver) and z_max (max N-buffer: the farthest), four
//     lookups each, read from the levels GL built; the slab of receivers [z_min, z_max] widened
//     for what litmaps cannot sample (faces of casters the observer sees that the light sees
//     edge-on or smaller than two lexels, clipped to the rectangle; a seen caster's own bounds);
//     the decision (culled when the slab's far end, plus a margin, is nearer than max(slab's near
//     end, caster_near)) and the clamp planes;
//  5. the shadow volumes of --shadow-mode, one draw a caster (role ShadowVolume): z-fail with caps
//     (Carmack's reverse), two-sided stencil in one pass (back faces INCR_WRAP, front faces
//     DECR_WRAP on depth fail), depth test LESS without depth writes, no face culling, depth clamp
//     on. Why z-fail: the camera may be inside a volume (a flyover crossing a tower's shadow, or
//     any camera under a bird's), where z-pass counts wrong; z-fail only needs closed volumes whose
//     far caps are not clipped, which depth clamp gives (the far caps at infinity, w = 0, land at
//     depth 1, behind every receiver; near-plane clipping cannot hurt z-fail, as clipped parts lie
//     in front of every receiver);
//  6. the shadow mask: stencil != 0 at a receiver pixel inside the light's frustum; and the
//     reference: the stencil cleared and every caster's infinite volume drawn (not recorded), its
//     mask and fill; the pixels where the two masks differ are counted (0 for a correct mode).
// Records: the light (LGHT), depth images "final", "litmap_min", "litmap_max", stencil images
// "stencil" (after the mode's volumes), "light_region", "shadow_mask", "shadow_mask_infinite", the
// N-buffer levels (sources "litmap_min" op min, "litmap_max" op max) every --levels-every-th frame,
// and the SHDC record (traces/format/shadows/shadows_chunk.h).
#pragma once

#include <memory>
#include <vector>

#include "traces/capture/plugin.h"
#include "traces/capture/technique.h"

namespace nbsim::capture {

// --shadow-mode, --litmap, --light, --light-fov, --levels-every, --seed.
const std::vector<OptionSpec>& shadows_options();

std::unique_ptr<Technique> make_shadows(const TechniqueSetup& setup);
// Its `nbsim bench replay` workload.
BenchPreset shadows_bench_preset();

}  // namespace nbsim::capture

// The technique table (technique.h): one row per technique. A new technique is a folder of its
// own (traces/capture/<name>/, shaders/<name>/) and one row here.
#include "traces/capture/ldi/ldi.h"
#include "traces/capture/occlusion/occlusion_culling.h"
#include "traces/capture/particles/particles.h"
#include "traces/capture/relief/relief.h"
#include "traces/capture/shadows/shadows.h"
#include "traces/capture/technique.h"

namespace nbsim::capture {

const std::vector<TechniqueRow>& technique_table() {
  static const std::vector<TechniqueRow> table = {
      {{"occlusion_culling",
        "Occlusion culling with occlusion queries or the GLSL N-buffer, flat or over the BVH (N-buffer paper, 3.1 and 4.2)",
        occlusion_culling_options()},
       make_occlusion_culling, occlusion_culling_bench_preset(), {{"city", "city"}}},
      {{"particles",
        "Point-sprite particles culled in the vertex stage: none, centre lookup, partial N-buffer or Hi-Z, with a "
        "reference pass for popping (N-buffer paper, 3.2 and 4.3)",
        particles_options()},
       make_particles, particles_bench_preset(), {}},
      {{"shadows",
        "Stencil shadow volumes of a spot light (z-fail, two-sided): infinite, culled or clamped with min/max litmaps and "
        "two N-buffers, with an infinite reference pass for the mask (N-buffer paper, 3.3 and 4.4)",
        shadows_options()},
       make_shadows, shadows_bench_preset(), {}},
      {{"ldi",
        "Layered depth images of a closed shape: viewpoint selection, depth peeling, crop, RG32UI depth-range compression and "
        "the volumetric parity test with both readers against an exact reference (Trapp & Doellner)",
        ldi_options()},
       make_ldi, ldi_bench_preset(), {}},
      {{"relief",
        "Relief textures: a heightfield in a box, each fragment's ray walked by binary search, the exact cell walk, the "
        "robust search with safety radii (two zero-radius variants) or the N-buffer empty-space walk, scored against an "
        "exact reference (Baboud & Decoret; the N-buffer paper's future work)",
        relief_options()},
       make_relief, relief_bench_preset(), {}},
  };
  return table;
}

const std::string& default_technique() { return technique_table().front().info.name; }

const TechniqueRow& find_technique(std::string_view name) { return find_row(technique_table(), name, "technique"); }

}  // namespace nbsim::capture

// The technique table (technique.h): one row per technique. A new technique is a folder of its
// own (traces/capture/<name>/, shaders/<name>/) and one row here.
#include "traces/capture/occlusion/occlusion_culling.h"
#include "traces/capture/technique.h"

namespace nbsim::capture {

const std::vector<TechniqueRow>& technique_table() {
  static const std::vector<TechniqueRow> table = {
      {{"occlusion_culling",
        "Occlusion culling with occlusion queries or the GLSL N-buffer, flat or over the BVH (N-buffer paper, 3.1 and 4.2)",
        occlusion_culling_options()},
       make_occlusion_culling},
  };
  return table;
}

const TechniqueRow& find_technique(std::string_view name) { return find_row(technique_table(), name, "technique"); }

}  // namespace nbsim::capture

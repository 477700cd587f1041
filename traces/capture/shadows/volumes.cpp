// The casters of a capture scene; see volumes.h.
#include "traces/capture/shadows/volumes.h"

#include <span>

namespace nbsim::capture {

std::vector<CasterMesh> find_casters(const CaptureScene& scene) {
  std::vector<CasterMesh> out;
  for (std::uint32_t o = 0; o < scene.objects.size(); ++o) {
    // The ground receives and never casts, in every scene (the terrain's and the plane are open
    // anyway; the city's street slab is a closed box, whose volume would only shadow its underside).
    if (o < scene.object_class.size() && scene.class_names[scene.object_class[o]] == "ground") continue;
    const MeshRange& m = scene.objects[o];
    const std::span<const std::uint32_t> triangles(scene.indices.data() + m.first_index, m.index_count - m.index_count % 3);
    if (auto c = nbsim::shadows::closed_mesh(o, triangles)) out.push_back(std::move(*c));
  }
  return out;
}

}  // namespace nbsim::capture

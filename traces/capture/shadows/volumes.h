// The shadows capture's side of the shadow-volume geometry (model/shadows/volume.h holds the
// geometry itself, shared with the model): which scene objects are casters, and the volume of a
// caster of a CaptureScene.
#pragma once

#include <glm/vec4.hpp>

#include <cstddef>
#include <vector>

#include "model/shadows/volume.h"
#include "traces/capture/scenes.h"

namespace nbsim::capture {

using LightCamera = nbsim::shadows::LightFrustum;
using nbsim::shadows::CasterMesh;
using nbsim::shadows::VolumeEnds;

// The casters of `scene`, in object order: the objects whose triangles form closed surfaces, but
// the ground (class "ground": receivers only, like every open object).
std::vector<CasterMesh> find_casters(const CaptureScene& scene);

// Appends the volume of `caster` lit from `light` to `out` (three positions a triangle).
inline void append_volume(const CaptureScene& scene, const CasterMesh& caster, const LightCamera& light, const VolumeEnds& ends,
                          std::vector<glm::vec4>& out) {
  nbsim::shadows::append_volume(scene.vertices, caster, light, ends, out);
}

// Silhouette edges of `caster` from the light (for counts and tests).
inline std::size_t silhouette_edges(const CaptureScene& scene, const CasterMesh& caster, const glm::dvec3& light) {
  return nbsim::shadows::silhouette_edges(scene.vertices, caster, light);
}

}  // namespace nbsim::capture

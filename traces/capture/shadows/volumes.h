// Shadow-volume geometry on the CPU (shadows technique): which scene objects are casters, their
// silhouette edges from a point light, and the closed volume of a caster as homogeneous world
// positions, three a triangle, counter-clockwise seen from outside the volume:
//   front cap  = the caster's light-facing triangles, at their "near" points,
//   back cap   = the same triangles at their "far" points, reversed,
//   sides      = one quad (two triangles) per silhouette edge, from its near to its far points.
// Infinite volumes take the caster's vertices as near points and their directions from the light
// (w = 0) as far points; clamped volumes take points on the same light rays at given light window
// depths (light_ray_point), and infinite volumes are cut at the same points (VolumeEnds). Also the light's window depth of a world point, and light-space
// distances for margins. Pure arithmetic on the CPU, in double precision, no GL.
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <cstdint>
#include <vector>

#include "traces/capture/scenes.h"

namespace nbsim::capture {

// A caster: an object of the scene whose triangles form closed surfaces (every directed edge of a
// triangle has exactly one triangle with the reverse edge). Open objects (the ground plane, the
// terrain) are receivers only.
struct CasterMesh {
  std::uint32_t object = 0;
  std::vector<std::array<std::uint32_t, 3>> triangles;  // scene vertex indices
  std::vector<std::array<std::int32_t, 3>> neighbour;   // triangle across edge k (v[k] -> v[k+1])
};

// The casters of `scene`, in object order.
std::vector<CasterMesh> find_casters(const CaptureScene& scene);

// A spot light's camera: pose, perspective projection (GL's [-1, 1] clip z, LESS: depth 0 at the light).
struct LightCamera {
  glm::dvec3 eye{0.0}, target{0.0, 0.0, -1.0};
  double fov_y_deg = 70.0, near_m = 1.0, far_m = 1000.0;
  glm::dmat4 view{1.0}, proj{1.0};

  // Fills view and proj; false when the frustum is degenerate (eye == target, near <= 0,
  // near >= far, a field of view outside (0, 180) degrees or a matrix that is not finite).
  bool make();
  glm::dvec4 clip(const glm::dvec3& p) const { return proj * (view * glm::dvec4(p, 1.0)); }
  // Light window depth [0, 1] of a world point in front of the light.
  double window_depth(const glm::dvec3& p) const;
  // The light window depth of the point at distance `distance_m` along the view axis, and back.
  double depth_of_distance(double distance_m) const;
  double distance_of_depth(double depth) const;
  // The point of the light ray through `p` at light window depth `depth` (in front of the light).
  glm::dvec3 light_ray_point(const glm::dvec3& p, double depth) const;
};

// Where a caster's volume is cut, in light window depth. The sides of a volume run from the
// caster's silhouette through the near plane (when set) and the far plane (when set; a vertex
// beyond it is its own far point) to infinity (w = 0). A clamped volume keeps only the piece
// between its first plane (the near plane, or the caster itself) and the far plane, capped there;
// an unclamped one keeps every piece, capped by the caster's lit faces and at infinity. The piece
// between the planes is the same triangles either way, so GL rasterizes the same depths on both,
// which is what keeps the mask bit-identical across modes: the other pieces and caps lie beyond the
// visible receivers by a margin.
struct VolumeEnds {
  bool near_plane = false, far_plane = false, clamped = false;
  double near_depth = 0.0, far_depth = 1.0;
};

// Appends the volume of `caster` lit from `light` to `out` (three positions a triangle).
void append_volume(const CaptureScene& scene, const CasterMesh& caster, const LightCamera& light, const VolumeEnds& ends,
                   std::vector<glm::vec4>& out);

// Silhouette edges of `caster` from the light (for counts and tests).
std::size_t silhouette_edges(const CaptureScene& scene, const CasterMesh& caster, const glm::dvec3& light);

}  // namespace nbsim::capture

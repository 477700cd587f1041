// Shadow-volume geometry on the CPU, shared by the capture (which draws it on GL) and the model
// (which builds the same volumes from the trace's caster meshes): the light's camera in double
// precision, closed caster meshes and their silhouettes, each caster's light-space rectangle, the
// clamp planes of its slab, and its volume as homogeneous world positions, three a triangle,
// counter-clockwise seen from outside the volume:
//   near cap = the caster's light-facing triangles, at their "near" points,
//   far cap  = the same triangles at their "far" points, reversed,
//   sides    = one quad (two triangles) per silhouette edge, from its near to its far points.
// Infinite volumes take the caster's points as near points and their directions from the light
// (w = 0) as far points; clamped volumes take points on the same light rays at given light window
// depths, and infinite volumes are cut at the same points (VolumeEnds). Pure arithmetic in double
// precision, no GL; the world positions are rounded to float once, as GL receives them.
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "model/scene/frame.h"
#include "model/shadows/caster.h"

namespace nbsim::shadows {

// A spot light's camera: pose, perspective projection (GL's [-1, 1] clip z, LESS: depth 0 at the light).
struct LightFrustum {
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

// A caster: an object whose triangles form a closed surface (every directed edge of a triangle has
// exactly one triangle with the reverse edge), as indices into a vertex array.
struct CasterMesh {
  std::uint32_t object = 0;
  std::vector<std::array<std::uint32_t, 3>> triangles;  // vertex indices
  std::vector<std::array<std::int32_t, 3>> neighbour;   // triangle across edge k (v[k] -> v[k+1])
};

// The caster of `triangles` (three vertex indices each), or nullopt when they do not form a closed
// surface (an open object is a receiver only) or are empty.
std::optional<CasterMesh> closed_mesh(std::uint32_t object, std::span<const std::uint32_t> triangles);

// Where a caster's volume is cut, in light window depth. The sides of a volume run from the
// caster's silhouette through the near plane (when set) and the far plane (when set; a point
// beyond it is its own far point) to infinity (w = 0). A point of the caster nearer the light than
// the near plane starts at the plane in a clamped volume; the faces and edges that cross the plane
// are split there, so a clamped volume starts on each light ray at the caster or at the plane,
// whichever is farther. A clamped volume keeps only the pieces between its starts and the far
// plane, capped there; an unclamped one keeps every piece, capped by the caster's lit faces and at
// infinity. The pieces between the planes are the same triangles either way, so GL rasterizes the
// same depths on both, which is what keeps the mask bit-identical across modes: the other pieces
// and caps lie beyond the visible receivers by a margin.
struct VolumeEnds {
  bool near_plane = false, far_plane = false, clamped = false;
  double near_depth = 0.0, far_depth = 1.0;
};

// Appends the volume of `caster` (indices into `vertices`) lit from `light` to `out` (three
// positions a triangle; a triangle that rounds to no area is left out).
void append_volume(std::span<const glm::vec3> vertices, const CasterMesh& caster, const LightFrustum& light, const VolumeEnds& ends,
                   std::vector<glm::vec4>& out);

// Silhouette edges of `caster` from the light (for counts and tests).
std::size_t silhouette_edges(std::span<const glm::vec3> vertices, const CasterMesh& caster, const glm::dvec3& light);

// A caster's light-space rectangle in a square litmap of side `litmap` and its bounds' light
// depths: decision Volume (to be decided on its slab), OutsideLight (wholly outside one side plane
// of the light's frustum or beyond its far plane, or its rectangle misses the litmap) or
// CrossesNear (its bounds reach behind the light's near plane; never culled or clamped).
struct CasterRect {
  Decision decision = Decision::Volume;
  std::int32_t x = 0, y = 0, w = 0, h = 0;  // the lexels its bounds touch, grown by one, clipped
  float caster_near = 0.0f, caster_far = 0.0f;
};
CasterRect caster_rect(const scene::Aabb& bounds, const LightFrustum& light, int litmap);

// The clamping rule: "edge", the paper's (the near plane whenever it is in front of some of the
// caster: faces and edges split there), or "caster" (only when the whole caster is behind it).
enum class ClampRule : std::uint8_t { Edge = 0, Caster = 1 };
inline constexpr std::array<std::string_view, 2> kClampRuleNames = {"edge", "caster"};

// The decision and planes of a caster whose bounds span light depths [caster_near, caster_far],
// from the light depths of the receivers its slab holds, [slab_min, slab_max]: culled when the far
// end, widened by the margin, is nearer than max(slab_min, caster_near); else the far plane there
// and the near plane at slab_min narrowed by the margin, as the rule allows (0: none).
struct Planes {
  bool culled = false;
  float clamp_near = 0.0f, clamp_far = 0.0f;
};
Planes slab_planes(float caster_near, float caster_far, const LightFrustum& light, double slab_min, double slab_max,
                   const ClampMargin& margin, ClampRule rule);
// The far end of a slab whose farthest receiver is at light window depth `slab_max`, pushed back by
// the margin.
double slab_far_end(const LightFrustum& light, double slab_max, const ClampMargin& margin);

// The ends of a caster's volume from its recorded planes (clamp_far +inf: none).
VolumeEnds volume_ends(float clamp_near, float clamp_far, bool clamped);

// The draw of a shadow volume as the capture records it: z-fail, two-sided stencil (back faces
// INCR_WRAP, front faces DECR_WRAP on depth fail, always passing, all bits), depth test LESS without
// writes, no face culling, depth clamp on, GL's default clip control; no clip positions yet.
scene::DrawRecord volume_draw(std::uint32_t object);

// gl_Position of the volume's vertex shader: view_proj * position in float, each row summed left
// to right with a rounding after every product and sum, as llvmpipe computes it (bit-equal with
// GL's transform feedback on every volume vertex measured).
std::array<float, 4> clip_position(const glm::mat4& view_proj, const glm::vec4& position) noexcept;
// The observer's view_proj of a frame: proj * view in float, as the capture computes it.
glm::mat4 observer_view_proj(const scene::FrameBegin& begin);

// The light camera a frame's SHDC record holds (the capture's, in double precision); throws
// InputError when it is degenerate.
LightFrustum light_of(const FrameCasters& c, std::uint64_t frame);

// The casters' meshes of a trace (SHDG), in SHDC's order.
struct CasterMeshes {
  std::vector<glm::vec3> vertices;
  std::vector<CasterMesh> meshes;  // indices into vertices
  std::vector<scene::Aabb> bounds;
};
inline constexpr std::uint32_t kCasterMeshesRecordType = 0x47444853u;  // fourcc "SHDG" (traces/format/shadows/shadows_chunk.h)
// Decodes and checks a frame's SHDG record, or nullopt when the frame has none; throws InputError
// naming the caster for a mesh that is not closed (its volume would leak) and for a damaged record.
std::optional<CasterMeshes> read_caster_meshes(const scene::Frame& f);

}  // namespace nbsim::shadows

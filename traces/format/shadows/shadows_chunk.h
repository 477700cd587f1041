// The shadows technique's chunk type (N-buffer paper, 3.3/4.4): per frame, one record of every
// shadow caster of the scene with its light-space rectangle, the visible receivers' depth range the
// min and max N-buffers gave over it, the decision and the clamp planes its shadow volume used.
// Built into the format library (technique_chunks.cpp registers it with the other techniques'
// types), so every reader decodes it. The capture side is traces/capture/shadows/.
#pragma once

#include <cstdint>

#include "traces/format/records.h"
#include "traces/format/technique_chunks.h"

namespace nbsim::trace {

inline constexpr std::uint32_t kShadowsChunk = fourcc("SHDC");
// The casters' meshes (ShadowCasterMeshes), in the first frame of a trace only: what the model
// builds shadow volumes from (model/shadows/volume.h).
inline constexpr std::uint32_t kCasterMeshesChunk = fourcc("SHDG");
// Every scene object's mesh (ShadowLitmapMeshes), in the first frame of a trace only: what the
// model draws its own litmaps from (model/shadows/litmap.h).
inline constexpr std::uint32_t kLitmapMeshesChunk = fourcc("SHDM");

// Decisions of the SHDC field `decision` (fixed values: they are in files).
enum class CasterDecision : std::uint32_t {
  Volume = 0,       // its shadow volume was drawn (clamped in mode clamped)
  Culled = 1,       // z_max (+ margin) < max(z_min, caster_near): no visible receiver behind it (dropped in culled and clamped)
  OutsideLight = 2, // its light-space rectangle misses the litmap: outside the spot's frustum (dropped likewise)
  CrossesNear = 3,  // its bounds cross the light's near plane: never culled or clamped (drawn infinite)
};

// Its description: fields in this order (every vector has `count` elements, caster c's values at
// index c), then the frame's reference fill and mask difference. Its rule: every vector has `count` elements, decision at most 3, rectangles inside the
// litmap (x, y >= 0, w, h >= 0, x + w and y + h at most litmap_size), draw -1 or a draw index.
ChunkSpec shadows_chunk_spec();

// The casters' meshes: count, object ids, bounds (six floats each), each caster's triangles as a
// range of `triangles` (three vertex indices each, into `vertices`, three floats each). Its rule:
// the vectors' lengths agree, every range and vertex index is inside its array.
ChunkSpec caster_meshes_chunk_spec();

// The litmap meshes: count, object ids, each object's triangles as a range of `triangles` (three
// vertex indices each, into `vertices`, three floats each). Its rule: the vectors' lengths agree,
// every range and vertex index is inside its array, no object twice.
ChunkSpec litmap_meshes_chunk_spec();

// Its header keys (what the replay reads to build the litmaps' N-buffers and clamp the volumes).
std::vector<HeaderKeySpec> shadows_header_keys();

}  // namespace nbsim::trace

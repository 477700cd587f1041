// The relief-texture technique's chunk types (Baboud & Decoret, and the N-buffer walk). Per frame,
// one ReliefField record (RLFH): the heightfield, its safety radius and the max N-buffer GL built
// from it, the walks' tunables and the frame's ray frame (model/relief/walk.h: the eye in texel
// space and the affine map from a pixel centre to a ray direction); and one ReliefFragments record
// (RLFF) per box draw: the method that draw ran and, for every fragment its shader ran (after the
// early depth test), the pixel, GL's hit or miss, the hit's ray parameter, and the lookups, steps
// and bisections the walk took. Conventions are model/relief/ (heightfield.h, walk.h); the box
// draws themselves are the frame's draws of role relief_box. Built into the format library
// (technique_chunks.cpp registers it). The capture side is traces/capture/relief/.
#pragma once

#include <cstdint>

#include "traces/format/records.h"
#include "traces/format/technique_chunks.h"

namespace nbsim::trace {

inline constexpr std::uint32_t kReliefFieldChunk = fourcc("RLFH");
inline constexpr std::uint32_t kReliefFragmentsChunk = fourcc("RLFF");
inline constexpr std::uint32_t kReliefDepthChunk = fourcc("RLFD");

// RLFF `hit` values (fixed: they are in files).
inline constexpr std::uint32_t kReliefMiss = 0;
inline constexpr std::uint32_t kReliefHit = 1;
inline constexpr std::uint32_t kReliefCapped = 2;  // the walk reached its iteration cap (a miss)

// ReliefField's fields:
//   size U32 (N, model/relief's kMinSize..kMaxSize), levels U32 (the N-buffer's:
//   nbuffer_level_count(N, N)), max_radius U32 (1..255), field String (what it is, e.g. "fbm:6
//   seed 7" or a file name), heights VecF32 (N*N, each in [0, 1]), radius VecF32 (N*N, whole
//   numbers in [0, max_radius]), nbuffer VecF32 (levels*N*N, as GL built it), linear_steps U32
//   (1..1024), binary_steps U32 (0..32), root_steps U32 (0..32), origin VecF32 (3), ray_a, ray_b,
//   ray_c VecF32 (3 each), view_angle F64 (degrees between the view direction and the box's up
//   axis, for reports).
// Rule: the vector lengths above, sizes and tunables in range, no NaN in any float vector, heights
// in [0, 1], radii whole and in range.
ChunkSpec relief_field_chunk_spec();

// ReliefFragments' fields:
//   draw U32 (the box draw's index in the frame), method U32 (model/relief/walk.h Method, 0..4),
//   count U32 (fragments; every vector below has this many), pixel VecU32 (y * width + x of the
//   viewport), hit VecU32 (kReliefMiss / kReliefHit / kReliefCapped), t VecF32 (the hit's ray
//   parameter, 0 on a miss), lookups VecU32, steps VecU32, bisections VecU32.
// Rule: vector lengths, method below 5, hit at most 2, no NaN t, pixels strictly increasing.
ChunkSpec relief_fragments_chunk_spec();

// ReliefDepth's fields (one per frame, when the boxes write depth: header relief_box_depth box or
// exact; model/relief/box_depth.h):
//   texel_to_clip VecF32 (16, column-major: the box's vertex transform, which the exact depth uses),
//   draws VecU32 (the frame's relief_box draws, in order), depth_crc VecU32 (per draw: the CRC-32 of
//   GL's depth buffer right after it, window depths as floats, y up, row-major).
// Rule: 16 matrix values, no NaN; one CRC per draw; draws strictly increasing.
ChunkSpec relief_depth_chunk_spec();
// Its header keys (the heightfield, the box and the walks' parameters; the replay reads
// relief_box_height, the relief table the field, its size and the angles).
std::vector<HeaderKeySpec> relief_header_keys();

}  // namespace nbsim::trace

// The layered-depth-image technique's chunk types (Trapp & Doellner: depth peeling, viewpoint
// selection, cropping, depth-range compression and the volumetric parity test). Per frame, one
// LdiImage record (LDIL): the viewpoint GL chose among the grid's directions with every
// direction's measured depth complexity and coverage, the LDI GL peeled (every layer as read back,
// +inf where a texel has no more layers), GL's crop and GL's compressed RG32UI texture; and one
// LdiTests record (LDIT): the frame's test points, GL's parity answers and fetch counts for both
// readers, and the exact double-precision reference. Conventions are model/ldi/ (ldi.h,
// compression.h, vpt.h); the peel passes themselves are the frame's draws of role ldi_peel, in
// pass order. Built into the format library (technique_chunks.cpp registers it). The capture side
// is traces/capture/ldi/.
#pragma once

#include <cstdint>

#include "traces/format/records.h"
#include "traces/format/technique_chunks.h"

namespace nbsim::trace {

inline constexpr std::uint32_t kLdiImageChunk = fourcc("LDIL");
inline constexpr std::uint32_t kLdiTestsChunk = fourcc("LDIT");
inline constexpr std::uint32_t kLdiAllLayersChunk = fourcc("LDIA");
inline constexpr std::uint32_t kLdiVolumeChunk = fourcc("LDIV");
inline constexpr std::uint32_t kLdiClipChunk = fourcc("LDIC");

// What a test point was chosen to probe (LDIT field `kind`; fixed values: they are in files).
enum class LdiPointKind : std::uint32_t {
  Random = 0,        // uniform in the LDI's texels and depth [0, 1]
  CropBoundary = 1,  // on a texel of the crop rectangle's border, or just outside it
  NearSurface = 2,   // at a layer's depth or within a few ulps of it
  Midway = 3,        // halfway between two consecutive layers of its texel (a clear answer)
};
inline constexpr std::uint32_t kLdiPointKinds = 4;

// Reference value of a point within epsilon of a surface (LDIT field `reference`): counted apart.
inline constexpr std::int32_t kLdiNearSurface = -1;

// LdiImage's rule: layers has layer_count * width * height values, compressed 2 * side * side,
// view 9, the candidate vectors grid_h * grid_v each with direction below that, the crop inside the
// LDI, and layer_count, width, height, side within model/ldi's limits.
ChunkSpec ldi_image_chunk_spec();
// LdiTests' rule: every vector has `count` elements, kind below kLdiPointKinds, answers 0 or 1,
// reference >= -1.
ChunkSpec ldi_tests_chunk_spec();
// LdiAllLayers (LDIA, one per frame beside LDIT in captures since the paper's reader; older traces
// have none): the paper's reader's answers at LDIT's points, which reads every layer of the texel:
//   count U32 (LDIT's), gl_inside_all VecU32 (0 or 1), gl_fetches_all VecU32 (d inside the crop, 0
//   outside). Rule: vector lengths, answers 0 or 1.
ChunkSpec ldi_all_layers_chunk_spec();

// LdiVolume (LDIV): one volume of the clipping and lens applications (model/ldi/clip.h), in the
// frame that built it (frame 0): its closed mesh in the unit cube, its placement in the world, and
// its LDI as GL peeled it with GL's crop and compressed texture. Rule: the mesh's vectors are
// triples, the layers layer_count x width x height, the crop inside the LDI, compressed 2 comp_side^2.
ChunkSpec ldi_volume_chunk_spec();
// LdiClip (LDIC): one a frame of those applications: the reader, the uniforms of the volume test,
// the draws it ran on with GL's per-draw answers, and the final depth buffer's CRC-32. Rule:
// volume_count 1 to 4, reader 0 to 2, view_proj 16 values, window_to_texel 16 a volume, per-draw
// vectors as long as `draws`, keep_inside 0 or 1.
ChunkSpec ldi_clip_chunk_spec();

// Its header keys (the LDI's size, grid and limits; the shape and how it was placed).
std::vector<HeaderKeySpec> ldi_header_keys();

}  // namespace nbsim::trace

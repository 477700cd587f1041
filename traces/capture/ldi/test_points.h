// Test points of the volumetric parity test (Trapp & Doellner) for the `ldi` capture, and their exact
// reference: the four kinds of traces/format/ldi/ldi_chunk.h (random, crop boundary, near a surface,
// midway between layers) chosen from GL's LDI and crop, and per point the number of surface
// crossings beyond it along its texel-centre line, in double precision (model/mesh/crossings.h),
// or kLdiNearSurface (-1) when a crossing lies within epsilon of it.
#pragma once

#include <cstdint>
#include <vector>

#include "model/ldi/ldi.h"
#include "model/mesh/crossings.h"
#include "traces/capture/ldi/peel.h"

namespace nbsim::capture {

struct LdiTestPoints {
  std::vector<std::uint32_t> kind;  // trace::LdiPointKind
  std::vector<std::int32_t> x, y;   // texel of the LDI (crop-boundary points may lie outside it)
  std::vector<float> z;             // linear depth in [0, 1]
};

// `count` points, kinds in turn (point i has kind i % 4); a kind that has nothing to probe (no
// texel with a layer, no texel with two) falls back to a random point of that kind's label.
// - Random: a uniform texel of the LDI, z uniform in [0, 1].
// - CropBoundary: a texel on the crop rectangle's border or one texel outside it (possibly outside
//   the LDI), z uniform; random texels when the crop is empty.
// - NearSurface: a texel with layers, one of its layers' depth moved by -3 to +3 ulps (0 included:
//   exactly on the layer), kept in [0, 1].
// - Midway: a texel with at least two layers, halfway between two consecutive ones (in float).
// Deterministic for a seed.
LdiTestPoints make_test_points(const ldi::Ldi& l, const Rect& crop, int count, std::uint64_t seed);

// The exact reference of each point: crossings beyond the point (mesh, in the unit cube, as peeled,
// and the view mapping), -1 when the nearest crossing is within epsilon (unit-cube units along the
// line) of it.
std::vector<std::int32_t> reference_crossings(const mesh::CrossingReference& ref, const OrthoMapping& map,
                                              const LdiTestPoints& p, double epsilon);

}  // namespace nbsim::capture

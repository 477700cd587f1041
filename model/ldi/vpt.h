// The volumetric parity test (VPT, Trapp & Doellner) on an LDI, the model side's plain core (no
// SystemC): a point is inside the shape when an odd number of the layers of its texel lie in front
// of it. Three readers of one rule, each counting the texture fetches a shader makes, so the model
// can charge them to the LDI's memory client: the full LDI, the cropped layered texture, and the
// compressed RG32UI texture (compression.h).
//
// The point: texel (x, y) of the source LDI (the crop's origin is a uniform, so callers never
// translate) and a linear depth z (ldi.h's convention). Any z but NaN is accepted.
//
// Tie rule (fixed by the design): layer k is in front of z iff depth_k < z, strictly. A point
// exactly on a front face (z == layer 0) is outside, exactly on the back face behind it (z == layer 1)
// inside: a range [s, e] of the compressed texture holds z iff s < z <= e, so both readers agree
// on every z, ties included. Missing layers (kInvalidDepth = +inf) are never in front of any z.
#pragma once

#include <cstdint>

#include "model/ldi/compression.h"
#include "model/ldi/ldi.h"

namespace nbsim::ldi {

struct VptResult {
  bool inside = false;
  // Texture fetches, one per texel read. Layered readers: the layers read, nearest first, up to
  // and including the first layer with depth >= z (a missing layer, +inf, is such a layer), at most
  // the texture's layer count. Compressed reader: 1 index fetch plus the ranges read, nearest first,
  // up to and including the first range with z <= end (the answer is then known), at most 1 + k.
  // A point whose texel is outside the texture (the crop, for the cropped and compressed readers)
  // is outside with 0 fetches: the shader compares it with the crop rectangle, a uniform.
  int fetches = 0;
  // Where the fetches go (texel numbers of the texture read, for the memory client's addresses;
  // meaningful when fetches > 0). Layered: fetch i reads texel + i * (texels per layer) (the crop's
  // or the full LDI's), texel = cy * w + cx. Compressed: fetch 0 reads the index texel `texel`,
  // fetch i >= 1 reads first_range + i - 1 (first_range = the index's offset).
  std::uint64_t texel = 0;
  std::uint32_t first_range = 0;
};

// Uncompressed, on the full LDI (x in [0, width), y in [0, height); up to layer_count() fetches).
VptResult vpt_layers(const Ldi& ldi, int x, int y, float z);
// Uncompressed, on the cropped layered texture (up to d fetches).
VptResult vpt_layers(const CroppedLdi& c, int x, int y, float z);
// The paper's reader, on the cropped layered texture: every one of the d layers of the texel is
// read and the layers in front of z counted (d fetches inside the crop, however near the point).
// The same answer as the early-exit reader above (the layers are sorted, so no layer behind the
// first one that is not in front is in front); Trapp & Doellner's O(d) against the compressed
// reader's O(d/2).
VptResult vpt_all_layers(const CroppedLdi& c, int x, int y, float z);
// Compressed. Throws InputError when the texture is damaged where the test reads it (an offset or
// a range count pointing past the texture).
VptResult vpt_ranges(const CompressedLdi& c, int x, int y, float z);

}  // namespace nbsim::ldi

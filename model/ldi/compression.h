// Lossless depth-range compression of a cropped LDI (Trapp & Doellner, section on compression), the
// model side's plain core (no SystemC): one two-channel 32-bit texture (RG32UI), an index segment
// then a range segment, which the compressed parity test (vpt.h) reads with 1 + k fetches instead
// of up to d. docs/ldi_compression.md has the layout, the formulas and the paper's code bugs.
//
// Layout (texel t is the pair (texels[2t], texels[2t + 1]), row-major in a side x side texture:
// t = ty * side + tx, row 0 first, as glTexImage2D with GL_RG_INTEGER takes it):
// - Index segment, texels [0, I) with I = w_crop * h_crop, one per cropped texel (cx, cy) at
//   t = cy * w_crop + cx: (offset, k) where offset is the texel number, counted from texel 0 of the
//   whole texture (so it includes the index segment's base I), of its first range and k its number
//   of ranges. A texel without ranges has k = 0 and the offset its ranges would have had, so the
//   offsets never decrease.
// - Range segment, texels [I, I + R): per cropped texel in index order, its ranges
//   (bits(start), bits(end)) with bits = std::bit_cast<uint32_t>, pairing layers 2j and 2j + 1.
//   A texel with an odd layer count n ends with the lone range (bits(layer n-1), bits(+inf)): the
//   invalid marker (ldi.h) as its end, which no valid depth equals, so decompression knows it holds
//   one layer, and the parity test needs no special case ([s, +inf) is "inside behind s", which is
//   what one layer with nothing behind it means). Only a texel's last range may be lone.
// - Padding, texels [I + R, side^2): zero.
// side = w_c = ceil(sqrt(I + R)); M_comp = 2 * w_c^2 values (both channels counted, as the paper's
// Table 1 does); C_ratio = M_comp / M_crop.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "model/ldi/ldi.h"

namespace nbsim::ldi {

struct CompressedLdi {
  // The source LDI's dimensions and its crop: the shader's uniforms, not texture data.
  int source_width = 0, source_height = 0, source_layers = 0;
  Crop crop;
  std::uint32_t index_texels = 0;  // I = w_crop * h_crop
  std::uint32_t range_texels = 0;  // R = sum over texels of ceil(n / 2)
  int side = 0;                    // w_c
  std::vector<std::uint32_t> texels;  // 2 * side * side values, RG interleaved

  // Texel t's two channels. Precondition: t < side * side.
  std::array<std::uint32_t, 2> texel(std::uint32_t t) const noexcept { return {texels[2 * std::size_t{t}], texels[2 * std::size_t{t} + 1]}; }
  std::uint64_t m_comp() const noexcept { return 2ull * static_cast<std::uint64_t>(side) * static_cast<std::uint64_t>(side); }
  std::uint64_t m_crop() const noexcept { return crop.m_crop(); }
  // M_comp / M_crop; nullopt for an LDI without any valid layer (M_crop = 0).
  std::optional<double> c_ratio() const noexcept;
};

// ceil(sqrt(n)), exact (no rounding of a double square root at perfect squares), for every
// n <= (2^32 - 1)^2 (the answer fits 32 bits; compress() asks for at most 2^28 * 1025).
std::uint32_t ceil_sqrt(std::uint64_t n) noexcept;

// Crops and compresses. Throws InputError when the texture's side would exceed kMaxSideTexels.
CompressedLdi compress(const Ldi& ldi);

// The LDI back, bit for bit (bit_equal(decompress(compress(L)), L) for every valid L). Checks the
// texture as it would a recorded one and throws InputError naming the texel for a damaged one:
// sizes, offsets (each equal to the previous texel's offset plus its k, starting at I), k
// (<= ceil(d / 2), the total equal to R), ranges (finite starts in [0, 1], start <= end, ends in
// [0, 1] or +inf on a texel's last range only, non-decreasing across a texel's ranges), a non-zero
// padding, and a crop that is not the bounding rectangle of the valid texels or a d not reached.
Ldi decompress(const CompressedLdi& c);

}  // namespace nbsim::ldi

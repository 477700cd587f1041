// Layered depth images (Trapp & Doellner), the model side's plain core (no SystemC): the LDI a
// depth-peeling capture records, its validation, and its crop (the bounding rectangle of the texels
// that hold a layer). Compression is compression.h, the volumetric parity test vpt.h.
//
// Conventions, stated once for model/ldi/:
// - Depth is linear depth in [0, 1] along the orthographic view direction, 0 nearest (the shape
//   scaled into the unit cube). It is NOT GL window depth of a perspective view (docs/architecture.md,
//   "Definitions"): the peel writes it into an R32F colour layer.
// - Texel (x, y), y up, x in [0, width), y in [0, height); layer k of a texel is its k-th nearest
//   surface depth, so a texel's layers are non-decreasing in k (equal depths are allowed: duplicate
//   faces that a peel did record twice).
// - A texel with n < layer_count layers holds kInvalidDepth in layers n and beyond.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "model/common/rect.h"

namespace nbsim::ldi {

// The "no layer here" marker: +infinity (fixed by the design). Valid depths are finite and in
// [0, 1], so a back face touching the unit cube's far face (depth exactly 1.0) is a valid layer and
// cannot be mistaken for a missing one, which a 1.0 sentinel (GL's depth clear value) would do. It
// also makes the parity test one comparison per fetch: +inf >= z for every test depth z, so
// "stop at the first layer >= z" stops at the first missing layer without a separate check. GL
// clears an R32F layer to it with glClearBufferfv (an R32F colour value is not clamped).
inline constexpr float kInvalidDepth = std::numeric_limits<float>::infinity();

// Limits (fixed by the design: GL 4.5's guaranteed minimums, so any conforming driver holds an LDI
// that passes them; llvmpipe's own limits are at least these). Width and height of the LDI and the
// side of the compressed texture: GL_MAX_TEXTURE_SIZE >= 16384. Stored layers:
// GL_MAX_ARRAY_TEXTURE_LAYERS >= 2048.
inline constexpr int kMaxSideTexels = 16384;
inline constexpr int kMaxLayers = 2048;

// A w x h LDI with layer_count stored layers. Immutable once validated.
class Ldi {
 public:
  // `depths` holds width * height * layer_count floats, layer-major like a layered R32F texture read
  // back with glGetTexImage: texel (x, y) of layer k at (k * height + y) * width + x. Throws
  // InputError naming the problem (and the texel and layer) when width or height is not in
  // [1, kMaxSideTexels], layer_count not in [0, kMaxLayers], the size does not match, or a depth is
  // NaN, -inf, outside [0, 1] (other than kInvalidDepth), nearer than the layer before it, or a
  // valid depth behind a missing layer.
  Ldi(int width, int height, int layer_count, std::vector<float> depths);

  // Builds an LDI from each texel's valid depths (texel (x, y) at y * width + x, nearest first);
  // layer_count is the largest list's size. Validated as above.
  static Ldi from_texels(int width, int height, const std::vector<std::vector<float>>& texel_depths);

  int width() const noexcept { return width_; }
  int height() const noexcept { return height_; }
  int layer_count() const noexcept { return layers_; }
  // Depth complexity d: the largest number of valid layers of any texel (<= layer_count()).
  int depth_complexity() const noexcept { return depth_complexity_; }
  // Layer k of texel (x, y) (kInvalidDepth past the texel's count). Preconditions: in range.
  float depth(int x, int y, int k) const noexcept {
    return depths_[(static_cast<std::size_t>(k) * height_ + y) * width_ + x];
  }
  // Number of valid layers of texel (x, y).
  int count(int x, int y) const noexcept { return counts_[static_cast<std::size_t>(y) * width_ + x]; }
  const std::vector<float>& depths() const noexcept { return depths_; }

 private:
  int width_ = 0, height_ = 0, layers_ = 0, depth_complexity_ = 0;
  std::vector<float> depths_;
  std::vector<std::uint16_t> counts_;  // <= kMaxLayers
};

// Bit-for-bit equality (dimensions and every depth's bits; +0.0 and -0.0 differ).
bool bit_equal(const Ldi& a, const Ldi& b) noexcept;

// The paper's cropping: the bounding rectangle of the texels with at least one valid layer (empty
// when there is none) and the depth complexity d. The cropped LDI keeps d layers (trailing layers
// that no texel uses are dropped), so its memory is M_crop = w_crop * h_crop * d values, one float
// channel each (the paper's unit in Table 1).
struct Crop {
  Rect rect;                 // in the LDI's texels
  int depth_complexity = 0;  // d
  std::uint64_t m_crop() const noexcept { return static_cast<std::uint64_t>(rect.area()) * depth_complexity; }
};
Crop find_crop(const Ldi& ldi) noexcept;

// The cropped LDI: crop.rect.w x crop.rect.h texels, d layers, layer-major over the crop (texel
// (cx, cy) of layer k at (k * h_crop + cy) * w_crop + cx), with the source's dimensions so the full
// LDI can be rebuilt. Empty (no depths) when no texel has a layer.
struct CroppedLdi {
  int source_width = 0, source_height = 0, source_layers = 0;
  Crop crop;
  std::vector<float> depths;
  // Layer k of source texel (x, y), which must lie inside crop.rect and k < d.
  float depth(int x, int y, int k) const noexcept {
    const Rect& r = crop.rect;
    return depths[(static_cast<std::size_t>(k) * r.h + (y - r.y)) * r.w + (x - r.x)];
  }
};
CroppedLdi crop(const Ldi& ldi);
// The full LDI back (texels outside the crop and layers past d hold kInvalidDepth): bit-equal to
// the LDI crop() was given.
Ldi uncrop(const CroppedLdi& c);

}  // namespace nbsim::ldi

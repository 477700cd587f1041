// Layered depth images: validation and cropping; see ldi.h.
#include "model/ldi/ldi.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>
#include <utility>

#include "model/common/error.h"

namespace nbsim::ldi {

namespace {

// As Rect's operator<< writes it: [x,y wxh].
std::string str(const Rect& r) { return fmt::format("[{},{} {}x{}]", r.x, r.y, r.w, r.h); }

bool is_invalid(float v) noexcept { return v == kInvalidDepth; }

void check_dimensions(int width, int height, int layer_count) {
  if (width < 1 || height < 1 || width > kMaxSideTexels || height > kMaxSideTexels)
    throw InputError(fmt::format("LDI: {}x{} texels, each side must be in [1, {}] (GL_MAX_TEXTURE_SIZE)", width,
                                 height, kMaxSideTexels));
  if (layer_count < 0 || layer_count > kMaxLayers)
    throw InputError(fmt::format("LDI: {} layers, the limit is {} (GL_MAX_ARRAY_TEXTURE_LAYERS)", layer_count,
                                 kMaxLayers));
}

}  // namespace

Ldi::Ldi(int width, int height, int layer_count, std::vector<float> depths)
    : width_(width), height_(height), layers_(layer_count), depths_(std::move(depths)) {
  check_dimensions(width, height, layer_count);
  const std::size_t texels = static_cast<std::size_t>(width) * height;
  if (depths_.size() != texels * layer_count)
    throw InputError(fmt::format("LDI: {} depths for {}x{} texels x {} layers (expected {})", depths_.size(), width,
                                 height, layer_count, texels * layer_count));
  counts_.assign(texels, 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      int n = 0;
      float previous = 0.0f;
      for (int k = 0; k < layer_count; ++k) {
        const float v = depth(x, y, k);
        const auto where = [&] { return fmt::format("LDI texel ({}, {}) layer {}", x, y, k); };
        if (std::isnan(v)) throw InputError(where() + ": depth is NaN");
        if (is_invalid(v)) continue;
        if (!(v >= 0.0f && v <= 1.0f))
          throw InputError(where() + fmt::format(": depth {} is outside [0, 1] (and not the invalid marker +inf)", v));
        if (n != k)
          throw InputError(where() + fmt::format(": valid depth {} behind missing layer {} (layers must be packed nearest first)", v, n));
        if (k > 0 && v < previous)
          throw InputError(where() + fmt::format(": depth {} is nearer than layer {}'s {} (layers out of order)", v, k - 1, previous));
        previous = v;
        ++n;
      }
      counts_[static_cast<std::size_t>(y) * width + x] = static_cast<std::uint16_t>(n);
      depth_complexity_ = std::max(depth_complexity_, n);
    }
}

Ldi Ldi::from_texels(int width, int height, const std::vector<std::vector<float>>& texel_depths) {
  check_dimensions(width, height, 0);
  const std::size_t texels = static_cast<std::size_t>(width) * height;
  if (texel_depths.size() != texels)
    throw InputError(fmt::format("LDI: {} texel lists for {}x{} texels", texel_depths.size(), width, height));
  std::size_t layers = 0;
  for (const auto& t : texel_depths) layers = std::max(layers, t.size());
  if (layers > static_cast<std::size_t>(kMaxLayers))
    throw InputError(fmt::format("LDI: a texel has {} layers, the limit is {} (GL_MAX_ARRAY_TEXTURE_LAYERS)", layers,
                                 kMaxLayers));
  std::vector<float> depths(texels * layers, kInvalidDepth);
  for (std::size_t i = 0; i < texels; ++i)
    for (std::size_t k = 0; k < texel_depths[i].size(); ++k) depths[k * texels + i] = texel_depths[i][k];
  return Ldi(width, height, static_cast<int>(layers), std::move(depths));
}

bool bit_equal(const Ldi& a, const Ldi& b) noexcept {
  if (a.width() != b.width() || a.height() != b.height() || a.layer_count() != b.layer_count()) return false;
  return std::equal(a.depths().begin(), a.depths().end(), b.depths().begin(),
                    [](float u, float v) { return std::bit_cast<std::uint32_t>(u) == std::bit_cast<std::uint32_t>(v); });
}

Crop find_crop(const Ldi& ldi) noexcept {
  int x0 = ldi.width(), y0 = ldi.height(), x1 = -1, y1 = -1;
  for (int y = 0; y < ldi.height(); ++y)
    for (int x = 0; x < ldi.width(); ++x)
      if (ldi.count(x, y) > 0) {
        x0 = std::min(x0, x), x1 = std::max(x1, x);
        y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
  Crop c;
  c.depth_complexity = ldi.depth_complexity();
  if (x1 >= 0) c.rect = Rect{x0, y0, x1 - x0 + 1, y1 - y0 + 1};
  return c;
}

CroppedLdi crop(const Ldi& ldi) {
  CroppedLdi c;
  c.source_width = ldi.width(), c.source_height = ldi.height(), c.source_layers = ldi.layer_count();
  c.crop = find_crop(ldi);
  const Rect& r = c.crop.rect;
  c.depths.resize(static_cast<std::size_t>(r.area()) * c.crop.depth_complexity);
  for (int k = 0; k < c.crop.depth_complexity; ++k)
    for (int y = r.y; y < r.y1(); ++y)
      for (int x = r.x; x < r.x1(); ++x)
        c.depths[(static_cast<std::size_t>(k) * r.h + (y - r.y)) * r.w + (x - r.x)] = ldi.depth(x, y, k);
  return c;
}

Ldi uncrop(const CroppedLdi& c) {
  check_dimensions(c.source_width, c.source_height, c.source_layers);
  const Rect& r = c.crop.rect;
  const int d = c.crop.depth_complexity;
  if (d < 0 || d > c.source_layers || (!r.empty() && (r.x < 0 || r.y < 0 || r.x1() > c.source_width || r.y1() > c.source_height)))
    throw InputError(fmt::format("cropped LDI: crop {} with d = {} does not fit the {}x{} x {} layers source", str(r), d,
                                 c.source_width, c.source_height, c.source_layers));
  if (c.depths.size() != static_cast<std::size_t>(r.area()) * d)
    throw InputError(fmt::format("cropped LDI: {} depths for crop {} x {} layers", c.depths.size(), str(r), d));
  const std::size_t w = static_cast<std::size_t>(c.source_width), h = static_cast<std::size_t>(c.source_height);
  std::vector<float> depths(w * h * c.source_layers, kInvalidDepth);
  for (int k = 0; k < d; ++k)
    for (int y = r.y; y < r.y1(); ++y)
      for (int x = r.x; x < r.x1(); ++x) depths[(k * h + y) * w + x] = c.depth(x, y, k);
  return Ldi(c.source_width, c.source_height, c.source_layers, std::move(depths));
}

}  // namespace nbsim::ldi

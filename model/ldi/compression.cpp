// Lossless depth-range compression of a cropped LDI and its checked decompression; see compression.h.
#include "model/ldi/compression.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

#include "model/common/error.h"

namespace nbsim::ldi {

namespace {

// As Rect's operator<< writes it: [x,y wxh].
std::string str(const Rect& r) { return fmt::format("[{},{} {}x{}]", r.x, r.y, r.w, r.h); }

std::uint32_t bits(float v) noexcept { return std::bit_cast<std::uint32_t>(v); }
float as_float(std::uint32_t u) noexcept { return std::bit_cast<float>(u); }

}  // namespace

std::optional<double> CompressedLdi::c_ratio() const noexcept {
  if (m_crop() == 0) return std::nullopt;
  return static_cast<double>(m_comp()) / static_cast<double>(m_crop());
}

std::uint32_t ceil_sqrt(std::uint64_t n) noexcept {
  // The double's root is within one of the answer; start at most 2^32 - 1 so r * r cannot wrap.
  auto r = std::min<std::uint64_t>(static_cast<std::uint64_t>(std::sqrt(static_cast<double>(n))), 0xFFFFFFFFull);
  while (r > 0 && r * r > n) --r;
  while (r * r < n) ++r;
  return static_cast<std::uint32_t>(r);
}

CompressedLdi compress(const Ldi& ldi) {
  CompressedLdi c;
  c.source_width = ldi.width(), c.source_height = ldi.height(), c.source_layers = ldi.layer_count();
  c.crop = find_crop(ldi);
  const Rect& r = c.crop.rect;
  const std::uint64_t index = static_cast<std::uint64_t>(r.area());
  std::uint64_t ranges = 0;
  for (int y = r.y; y < r.y1(); ++y)
    for (int x = r.x; x < r.x1(); ++x) ranges += static_cast<std::uint64_t>(ldi.count(x, y) + 1) / 2;
  const std::uint32_t side = ceil_sqrt(index + ranges);
  if (side > static_cast<std::uint32_t>(kMaxSideTexels))
    throw InputError(fmt::format("compressed LDI: {} index + {} range texels need a {}x{} texture, above the limit {} "
                                 "(GL_MAX_TEXTURE_SIZE)", index, ranges, side, side, kMaxSideTexels));
  c.index_texels = static_cast<std::uint32_t>(index);
  c.range_texels = static_cast<std::uint32_t>(ranges);
  c.side = static_cast<int>(side);
  c.texels.assign(2 * std::size_t{side} * side, 0u);
  // The running texel number of the next range, from texel 0 of the whole texture: the range
  // segment starts right after the index segment, so the first offset is I, not 0.
  std::uint32_t next = c.index_texels;
  std::uint32_t t = 0;
  for (int y = r.y; y < r.y1(); ++y)
    for (int x = r.x; x < r.x1(); ++x, ++t) {
      const int n = ldi.count(x, y);
      const auto k = static_cast<std::uint32_t>(n + 1) / 2;
      c.texels[2 * std::size_t{t}] = next;
      c.texels[2 * std::size_t{t} + 1] = k;
      for (int layer = 0; layer < n; layer += 2, ++next) {
        c.texels[2 * std::size_t{next}] = bits(ldi.depth(x, y, layer));
        // A lone last layer (odd n) gets the invalid marker as its end.
        c.texels[2 * std::size_t{next} + 1] = bits(layer + 1 < n ? ldi.depth(x, y, layer + 1) : kInvalidDepth);
      }
    }
  return c;
}

Ldi decompress(const CompressedLdi& c) {
  const Rect& r = c.crop.rect;
  const int d = c.crop.depth_complexity;
  const auto fail = [](const std::string& what) { throw InputError("compressed LDI: " + what); };
  if (c.source_width < 1 || c.source_height < 1 || c.source_width > kMaxSideTexels || c.source_height > kMaxSideTexels ||
      c.source_layers < 0 || c.source_layers > kMaxLayers)
    fail(fmt::format("source {}x{} x {} layers is outside the limits ({} texels a side, {} layers)", c.source_width,
                     c.source_height, c.source_layers, kMaxSideTexels, kMaxLayers));
  if (r.w < 0 || r.h < 0 || (!r.empty() && (r.x < 0 || r.y < 0 || r.x1() > c.source_width || r.y1() > c.source_height)))
    fail(fmt::format("crop {} is not inside the {}x{} source", str(r), c.source_width, c.source_height));
  if (d < 0 || d > c.source_layers) fail(fmt::format("d = {} is not in [0, {}] (the source's layers)", d, c.source_layers));
  if (c.index_texels != static_cast<std::uint64_t>(r.area()))
    fail(fmt::format("{} index texels for a {}x{} crop", c.index_texels, r.w, r.h));
  const std::uint64_t used = std::uint64_t{c.index_texels} + c.range_texels;
  if (c.side < 0 || c.side > kMaxSideTexels || static_cast<std::uint32_t>(c.side) != ceil_sqrt(used))
    fail(fmt::format("side {} is not ceil(sqrt({} + {}))", c.side, c.index_texels, c.range_texels));
  const std::uint64_t total = static_cast<std::uint64_t>(c.side) * static_cast<std::uint64_t>(c.side);
  if (c.texels.size() != 2 * total) fail(fmt::format("{} values for a {}x{} RG texture", c.texels.size(), c.side, c.side));

  const std::size_t w = static_cast<std::size_t>(c.source_width), h = static_cast<std::size_t>(c.source_height);
  std::vector<float> depths(w * h * c.source_layers, kInvalidDepth);
  std::uint64_t next = c.index_texels;
  int max_layers = 0, x0 = c.source_width, y0 = c.source_height, x1 = -1, y1 = -1;
  std::uint32_t t = 0;
  for (int y = r.y; y < r.y1(); ++y)
    for (int x = r.x; x < r.x1(); ++x, ++t) {
      const auto [offset, k] = c.texel(t);
      const auto where = [&] { return fmt::format("index texel {} (LDI texel ({}, {}))", t, x, y); };
      if (offset != next) fail(where() + fmt::format(": offset {}, expected {} (the previous offset plus its k)", offset, next));
      if (k > static_cast<std::uint32_t>(d + 1) / 2 || next + k > used)
        fail(where() + fmt::format(": {} ranges, more than ceil(d/2) = {} or past the range segment's end {}", k, (d + 1) / 2, used));
      int n = 0;
      float previous = 0.0f;
      for (std::uint32_t j = 0; j < k; ++j) {
        const auto [sb, eb] = c.texel(static_cast<std::uint32_t>(next + j));
        const float s = as_float(sb), e = as_float(eb);
        const auto range = [&] { return where() + fmt::format(" range {} (texel {}) [{}, {}]", j, next + j, s, e); };
        if (!(s >= 0.0f && s <= 1.0f) || s < previous) fail(range() + ": start not in [0, 1] or nearer than the range before");
        const bool lone = e == kInvalidDepth;
        if (lone && j + 1 != k) fail(range() + ": a lone layer (end +inf) that is not the texel's last range");
        if (!lone && !(e >= s && e <= 1.0f)) fail(range() + ": end not in [start, 1] nor +inf");
        if (n + (lone ? 1 : 2) > d) fail(range() + fmt::format(": more than d = {} layers", d));
        depths[(static_cast<std::size_t>(n++) * h + y) * w + x] = s;
        if (!lone) depths[(static_cast<std::size_t>(n++) * h + y) * w + x] = e;
        previous = e;
      }
      next += k;
      max_layers = std::max(max_layers, n);
      if (n > 0) x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  if (next != used) fail(fmt::format("the index's ranges end at texel {}, the range segment at {}", next, used));
  for (std::uint64_t p = used; p < total; ++p)
    if (c.texels[2 * p] != 0 || c.texels[2 * p + 1] != 0) fail(fmt::format("padding texel {} is not zero", p));
  if (max_layers != d) fail(fmt::format("d = {} but the deepest texel has {} layers", d, max_layers));
  const Rect bounds = x1 < 0 ? Rect{} : Rect{x0, y0, x1 - x0 + 1, y1 - y0 + 1};
  if (bounds != r) fail(fmt::format("crop {} is not the bounding rectangle {} of the texels with a layer", str(r), str(bounds)));
  return Ldi(c.source_width, c.source_height, c.source_layers, std::move(depths));
}

}  // namespace nbsim::ldi

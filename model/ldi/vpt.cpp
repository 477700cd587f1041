// The volumetric parity test, uncompressed and compressed, with its fetch counts; see vpt.h.
#include "model/ldi/vpt.h"

#include <fmt/format.h>

#include <bit>
#include <cmath>

#include "model/common/error.h"

namespace nbsim::ldi {

namespace {

void check_depth(float z) {
  if (std::isnan(z)) throw InputError("volumetric parity test: the point's depth is NaN");
}

// Reads layers nearest first until one is not in front of z; parity of those that are.
template <class Fetch>
VptResult walk_layers(int layers, float z, Fetch fetch) {
  VptResult res;
  int in_front = 0;
  for (int k = 0; k < layers; ++k) {
    ++res.fetches;
    if (!(fetch(k) < z)) break;  // >= z, or +inf (missing): nothing behind it is in front either
    ++in_front;
  }
  res.inside = (in_front & 1) != 0;
  return res;
}

}  // namespace

VptResult vpt_layers(const Ldi& ldi, int x, int y, float z) {
  check_depth(z);
  if (x < 0 || y < 0 || x >= ldi.width() || y >= ldi.height()) return {};
  VptResult res = walk_layers(ldi.layer_count(), z, [&](int k) { return ldi.depth(x, y, k); });
  res.texel = static_cast<std::uint64_t>(y) * static_cast<std::uint64_t>(ldi.width()) + static_cast<std::uint64_t>(x);
  return res;
}

VptResult vpt_layers(const CroppedLdi& c, int x, int y, float z) {
  check_depth(z);
  const Rect& r = c.crop.rect;
  if (!r.contains(x, y)) return {};
  VptResult res = walk_layers(c.crop.depth_complexity, z, [&](int k) { return c.depth(x, y, k); });
  res.texel = static_cast<std::uint64_t>(y - r.y) * static_cast<std::uint64_t>(r.w) + static_cast<std::uint64_t>(x - r.x);
  return res;
}

VptResult vpt_all_layers(const CroppedLdi& c, int x, int y, float z) {
  check_depth(z);
  const Rect& r = c.crop.rect;
  if (!r.contains(x, y)) return {};
  VptResult res;
  int in_front = 0;
  for (int k = 0; k < c.crop.depth_complexity; ++k) {
    ++res.fetches;
    in_front += c.depth(x, y, k) < z ? 1 : 0;
  }
  res.inside = (in_front & 1) != 0;
  res.texel = static_cast<std::uint64_t>(y - r.y) * static_cast<std::uint64_t>(r.w) + static_cast<std::uint64_t>(x - r.x);
  return res;
}

VptResult vpt_ranges(const CompressedLdi& c, int x, int y, float z) {
  check_depth(z);
  const Rect& r = c.crop.rect;
  if (!r.contains(x, y)) return {};
  const std::uint64_t total = static_cast<std::uint64_t>(c.side) * static_cast<std::uint64_t>(c.side);
  const auto t = static_cast<std::uint32_t>((y - r.y) * static_cast<std::int64_t>(r.w) + (x - r.x));
  if (t >= total || c.texels.size() < 2 * total)
    throw InputError(fmt::format("compressed LDI: index texel {} is outside the {}x{} texture", t, c.side, c.side));
  VptResult res;
  res.fetches = 1;
  res.texel = t;
  const auto [offset, k] = c.texel(t);
  res.first_range = offset;
  if (std::uint64_t{offset} + k > total)
    throw InputError(fmt::format("compressed LDI: index texel {} has ranges [{}, {}) past the {}x{} texture", t, offset,
                                 std::uint64_t{offset} + k, c.side, c.side));
  for (std::uint32_t j = 0; j < k; ++j) {
    ++res.fetches;
    const auto [sb, eb] = c.texel(offset + j);
    const float s = std::bit_cast<float>(sb), e = std::bit_cast<float>(eb);
    if (z <= s) return res;  // in front of this range: an even number of layers before it, outside
    if (z <= e) {            // s < z <= e (a lone layer's e is +inf: everything behind s)
      res.inside = true;
      return res;
    }
  }
  return res;  // behind every range
}

}  // namespace nbsim::ldi

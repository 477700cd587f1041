// Hi-Z pyramid construction and queries; see pyramid.h.
#include "model/hiz/pyramid.h"

#include <algorithm>
#include <string>

#include "model/common/error.h"
#include "model/nbuffer/covering.h"

namespace nbsim {

HiZPyramid::HiZPyramid(const DepthImage& depth, HiZConfig config) : config_(config), width_(depth.width), height_(depth.height) {
  if (width_ < 1 || height_ < 1) throw InputError("Hi-Z pyramid needs an image of at least 1x1");
  DepthImage base(width_, height_, 0.0f);
  for (std::size_t i = 0; i < base.size(); ++i) base.texels[i] = quantize_toward_far(depth.texels[i], config.format, config.op);
  levels_.push_back(std::move(base));
  while (levels_.back().width > 1 || levels_.back().height > 1) {
    const DepthImage& src = levels_.back();
    DepthImage dst((src.width + 1) / 2, (src.height + 1) / 2, neutral_depth(config.op));
    for (int y = 0; y < dst.height; ++y) {
      for (int x = 0; x < dst.width; ++x) {
        float v = neutral_depth(config.op);
        // The 2x2 children, skipping those past an odd edge (outside pixels are neutral).
        for (int cy = 2 * y; cy < std::min(2 * y + 2, src.height); ++cy)
          for (int cx = 2 * x; cx < std::min(2 * x + 2, src.width); ++cx) v = farther(config.op, v, src.at(cx, cy));
        dst.at(x, y) = v;
      }
    }
    levels_.push_back(std::move(dst));
  }
}

QueryResult HiZPyramid::query(const Rect& r) const {
  if (r.empty()) throw InputError("empty Hi-Z query rectangle (width and height must be at least 1)");
  const Rect c = clip(r, width_, height_);
  if (c.empty()) throw InputError("Hi-Z query rectangle lies outside the image");
  // Texels of level k are 2^k wide; a span of at most 2^k pixels touches at most two of them.
  const int k = std::min(ceil_log2(static_cast<unsigned>(std::max(c.w, c.h))), level_count() - 1);
  QueryResult q;
  q.level = k;
  q.value = neutral_depth(config_.op);
  const int tx0 = c.x >> k, tx1 = (c.x1() - 1) >> k, ty0 = c.y >> k, ty1 = (c.y1() - 1) >> k;
  NBSIM_CHECK(tx1 - tx0 <= 1 && ty1 - ty0 <= 1, "Hi-Z query reads more than 2x2 texels");
  for (int ty = ty0; ty <= ty1; ++ty) {
    for (int tx = tx0; tx <= tx1; ++tx) {
      q.texels[static_cast<std::size_t>(q.texel_count++)] = {tx, ty};
      q.value = farther(config_.op, q.value, texel(k, tx, ty));
    }
  }
  return q;
}

long long HiZPyramid::storage_bytes() const noexcept {
  long long n = 0;
  for (const auto& l : levels_) n += static_cast<long long>(l.size());
  return n * nbsim::storage_bytes(config_.format);
}

}  // namespace nbsim

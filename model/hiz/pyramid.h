// Hierarchical-Z pyramid: the baseline the N-buffer is compared with. A max- (or min-) reduction
// mip chain: level k has ceil(W / 2^k) x ceil(H / 2^k) texels and texel (x, y) holds the farthest
// depth of the level-0 pixels [x 2^k, (x + 1) 2^k) x [y 2^k, (y + 1) 2^k) inside the image, so it
// stays conservative at non-power-of-two sizes. Plain C++ core of the Hi-Z units; no SystemC.
#pragma once

#include <vector>

#include "model/common/depth.h"
#include "model/common/query.h"
#include "model/common/rect.h"
#include "model/common/storage.h"

namespace nbsim {

struct HiZConfig {
  FarOp op = FarOp::Max;
  StorageFormat format = StorageFormat::F32;
};

class HiZPyramid {
 public:
  explicit HiZPyramid(const DepthImage& depth, HiZConfig config = {});

  // Farthest depth of r (clipped to the image) from at most 2x2 texels of the first level whose
  // texels are at least as large as the rectangle's longer side. Throws InputError when r is empty
  // or outside the image.
  QueryResult query(const Rect& r) const;

  int level_count() const noexcept { return static_cast<int>(levels_.size()); }
  int level_width(int k) const noexcept { return levels_[static_cast<std::size_t>(k)].width; }
  int level_height(int k) const noexcept { return levels_[static_cast<std::size_t>(k)].height; }
  float texel(int k, int x, int y) const noexcept { return levels_[static_cast<std::size_t>(k)].at(x, y); }
  const DepthImage& level(int k) const noexcept { return levels_[static_cast<std::size_t>(k)]; }
  const HiZConfig& config() const noexcept { return config_; }
  long long storage_bytes() const noexcept;

 private:
  HiZConfig config_;
  int width_ = 0, height_ = 0;
  std::vector<DepthImage> levels_;  // levels_[0] is the quantized depth, the last one is 1x1
};

}  // namespace nbsim

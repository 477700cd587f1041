// The exact reference of a relief ray (heightfield.h's conventions): the first point where the ray
// meets the bilinear surface, in double precision. Cell by cell along the ray (every cell the ray's
// horizontal projection crosses, in order, the virtual border cells included), the height above
// the surface along the ray inside a cell is a quadratic in t; its first root in the cell's
// parameter interval is the hit (a tangent touch, a double root, counts as a hit).
#pragma once

#include <array>
#include <vector>

#include "model/relief/heightfield.h"

namespace nbsim::relief {

struct ReferenceHit {
  bool hit = false;
  double t = 0.0;  // the ray parameter of the hit (valid when hit)
};

// Block maxima that let the reference skip stretches of a ray far above the surface without
// solving them cell by cell; the answer is the same, bit for bit, with or without them (each
// skipped cell would have been skipped by the per-cell clearance test, see reference.cpp). Cells
// (ci, cj), ci and cj in [-2, N + 1] (the reference's clamped range), are grouped in blocks of
// kBlock x kBlock; a block's maximum is the highest corner of every cell in it or next to it (the
// ring of neighbours covers a cell that rounding of a piece's midpoint would find across the
// block's edge). Build once per heightfield; (N + 4)^2 / kBlock^2 doubles.
class ReferenceBlocks {
 public:
  static constexpr int kBlock = 8;  // cells a side. Tunable (8 was chosen, not tuned).
  explicit ReferenceBlocks(const Heightfield& field);
  // The block of cell index c (in [-2, N + 1]) along one axis, and its cells' range [first, last].
  static int block_of(int c) noexcept { return (c + 2) / kBlock; }
  static int first_cell(int b) noexcept { return b * kBlock - 2; }
  static int last_cell(int b) noexcept { return (b + 1) * kBlock - 3; }
  double max(int bi, int bj) const noexcept { return max_[static_cast<std::size_t>(bj) * blocks_ + static_cast<std::size_t>(bi)]; }

 private:
  int blocks_ = 0;  // a side
  std::vector<double> max_;
};

// The ray p(t) = origin + t * direction (texel space), from t_enter to t_exit (the caller's box
// interval, t_enter <= t_exit). A ray whose start is already below the surface hits at t_enter.
// `blocks` (of this field; may be null) only makes it faster.
ReferenceHit reference_hit(const Heightfield& field, const std::array<double, 3>& origin, const std::array<double, 3>& direction,
                           double t_enter, double t_exit, const ReferenceBlocks* blocks = nullptr);

}  // namespace nbsim::relief

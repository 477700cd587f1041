// Brute-force references and test images for the depth-query tests of tests/model (N-buffer,
// Hi-Z, storage formats). Slow on purpose: every answer comes from scanning level-0 pixels, never
// from the structures under test. Conventions as in model/common/depth.h (y up, row-major).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "model/common/depth.h"
#include "model/common/query.h"
#include "model/common/rect.h"
#include "model/nbuffer/covering.h"

namespace nbsim::ref {

// "[x,y wxh]", for failure messages.
inline std::string str(const Rect& r) {
  std::string s(1, '[');  // appended piece by piece: GCC 12 warns (-Wrestrict) on "[" + string
  s.append(std::to_string(r.x)).append(",").append(std::to_string(r.y)).append(" ");
  s.append(std::to_string(r.w)).append("x").append(std::to_string(r.h)).append("]");
  return s;
}

// ---------------------------------------------------------------------------------------------
// Deterministic randomness. std::uniform_*_distribution differ between standard libraries, so
// values are derived from the raw std::mt19937 output, whose sequence the standard fixes.

// A float in [0, 1) with 24 random bits (every value exactly representable).
inline float unit_float(std::mt19937& rng) { return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f); }

// A float in [lo, hi).
inline float uniform_float(std::mt19937& rng, float lo, float hi) { return lo + (hi - lo) * unit_float(rng); }

// An integer in [lo, hi] (hi >= lo). The modulo bias is irrelevant for tests.
inline int uniform_int(std::mt19937& rng, int lo, int hi) {
  const auto span = static_cast<std::uint32_t>(static_cast<long long>(hi) - lo + 1);
  return lo + static_cast<int>(rng() % span);
}

// An integer in [1, n] drawn log-uniformly: small sizes are as common as large ones.
inline int log_uniform_size(std::mt19937& rng, int n) {
  int bits = 0;
  while ((1LL << bits) < n) ++bits;
  const int b = uniform_int(rng, 0, bits);
  const int hi = static_cast<int>(std::min<long long>(n, 1LL << b));
  return uniform_int(rng, std::max(1, hi / 2), hi);
}

// A random rectangle for a width x height image with log-uniform sides. With allow_outside it
// may stick out of the image on any side (but always overlaps it).
inline Rect random_rect(std::mt19937& rng, int width, int height, bool allow_outside) {
  Rect r;
  if (allow_outside && uniform_int(rng, 0, 3) == 0) {
    r.w = log_uniform_size(rng, 2 * width + 2);
    r.h = log_uniform_size(rng, 2 * height + 2);
    r.x = uniform_int(rng, 1 - r.w, width - 1);
    r.y = uniform_int(rng, 1 - r.h, height - 1);
  } else {
    r.w = log_uniform_size(rng, width);
    r.h = log_uniform_size(rng, height);
    r.x = uniform_int(rng, 0, width - r.w);
    r.y = uniform_int(rng, 0, height - r.h);
  }
  return r;
}

// ---------------------------------------------------------------------------------------------
// Brute-force answers.

// Farthest depth of the pixels of r inside the image; the neutral depth when there are none.
inline float farthest(const DepthImage& img, FarOp op, const Rect& r) {
  const Rect c = clip(r, img.width, img.height);
  float v = neutral_depth(op);
  for (int y = c.y; y < c.y1(); ++y)
    for (int x = c.x; x < c.x1(); ++x) v = farther(op, v, img.at(x, y));
  return v;
}

// The N-buffer definition: level `level` at (x, y) is the farthest of [x, x + 2^level) x
// [y, y + 2^level) clipped to the image.
inline float level_texel(const DepthImage& img, FarOp op, int level, int x, int y) {
  return farthest(img, op, {x, y, 1 << level, 1 << level});
}

// Every level 0..count-1 of the N-buffer of img, each texel scanned on its own.
inline std::vector<DepthImage> nbuffer_levels(const DepthImage& img, FarOp op, int count) {
  std::vector<DepthImage> levels;
  for (int i = 0; i < count; ++i) {
    DepthImage l(img.width, img.height, 0.0f);
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) l.at(x, y) = level_texel(img, op, i, x, y);
    levels.push_back(std::move(l));
  }
  return levels;
}

// Calls fn(rect, farthest) for every rectangle inside the image, computing the farthest depth
// incrementally (column maxima over the rows y0..y1, then a running maximum along x). Far
// cheaper than scanning each rectangle, and still independent of any structure under test.
template <class Fn>
void for_each_rect(const DepthImage& img, FarOp op, Fn&& fn) {
  std::vector<float> col(static_cast<std::size_t>(img.width));
  for (int y0 = 0; y0 < img.height; ++y0) {
    std::fill(col.begin(), col.end(), neutral_depth(op));
    for (int y1 = y0; y1 < img.height; ++y1) {
      for (int x = 0; x < img.width; ++x) col[static_cast<std::size_t>(x)] = farther(op, col[static_cast<std::size_t>(x)], img.at(x, y1));
      for (int x0 = 0; x0 < img.width; ++x0) {
        float run = neutral_depth(op);
        for (int x1 = x0; x1 < img.width; ++x1) {
          run = farther(op, run, col[static_cast<std::size_t>(x1)]);
          fn(Rect{x0, y0, x1 - x0 + 1, y1 - y0 + 1}, run);
        }
      }
    }
  }
}

// Farthest depth of a rectangle on large images: a sparse table per row answers a row span in
// two lookups, the rows are scanned one by one. Used where scanning every pixel is too slow.
class RowTable {
 public:
  RowTable(const DepthImage& img, FarOp op) : op_(op), width_(img.width), height_(img.height) {
    tables_.push_back(img.texels);
    for (int k = 1; (1 << k) <= width_; ++k) {
      const std::vector<float>& prev = tables_.back();
      std::vector<float> next(prev.size(), neutral_depth(op));
      const int half = 1 << (k - 1);
      for (int y = 0; y < height_; ++y)
        for (int x = 0; x + (1 << k) <= width_; ++x) {
          const std::size_t i = static_cast<std::size_t>(y) * width_ + x;
          next[i] = farther(op, prev[i], prev[i + half]);
        }
      tables_.push_back(std::move(next));
    }
  }

  float farthest(const Rect& r) const {
    const Rect c = clip(r, width_, height_);
    float v = neutral_depth(op_);
    if (c.empty()) return v;
    int k = 0;
    while ((2 << k) <= c.w) ++k;
    const std::vector<float>& t = tables_[static_cast<std::size_t>(k)];
    for (int y = c.y; y < c.y1(); ++y) {
      const std::size_t row = static_cast<std::size_t>(y) * width_;
      v = farther(op_, v, farther(op_, t[row + c.x], t[row + c.x1() - (1 << k)]));
    }
    return v;
  }

 private:
  FarOp op_;
  int width_, height_;
  std::vector<std::vector<float>> tables_;  // tables_[k][y * W + x]: farthest of row y, [x, x + 2^k)
};

// The first pixel of r that none of the squares [t.x, t.x + side) x [t.y, t.y + side) covers.
// Exact: the square edges cut r into cells that are either inside or outside each square.
inline std::optional<std::pair<int, int>> first_uncovered(const Rect& r, std::span<const Texel> squares, int side) {
  std::array<int, 10> xs{}, ys{};  // r's two edges and two per square, at most four squares
  std::size_t n = 0;
  xs[0] = r.x, xs[1] = r.x1(), ys[0] = r.y, ys[1] = r.y1(), n = 2;
  for (const Texel& t : squares.first(std::min<std::size_t>(squares.size(), 4))) {
    xs[n] = std::clamp(t.x, r.x, r.x1()), ys[n] = std::clamp(t.y, r.y, r.y1()), ++n;
    xs[n] = std::clamp(t.x + side, r.x, r.x1()), ys[n] = std::clamp(t.y + side, r.y, r.y1()), ++n;
  }
  std::sort(xs.begin(), xs.begin() + static_cast<std::ptrdiff_t>(n));
  std::sort(ys.begin(), ys.begin() + static_cast<std::ptrdiff_t>(n));
  for (std::size_t j = 0; j + 1 < n; ++j) {
    if (ys[j] == ys[j + 1]) continue;
    for (std::size_t i = 0; i + 1 < n; ++i) {
      if (xs[i] == xs[i + 1]) continue;
      const int px = xs[i], py = ys[j];
      const bool covered = std::any_of(squares.begin(), squares.end(), [&](const Texel& t) {
        return px >= t.x && px < t.x + side && py >= t.y && py < t.y + side;
      });
      if (!covered) return std::pair{px, py};
    }
  }
  return std::nullopt;
}

// ---------------------------------------------------------------------------------------------
// Test images. Values stay inside [0, 1]; "far" means far under the op the image is made for.

inline DepthImage constant(int w, int h, float v) { return DepthImage(w, h, v); }

// Uniform random depths in [lo, hi).
inline DepthImage uniform(int w, int h, std::uint32_t seed, float lo = 0.0f, float hi = 1.0f) {
  std::mt19937 rng(seed);
  DepthImage img(w, h, 0.0f);
  for (float& t : img.texels) t = uniform_float(rng, lo, hi);
  return img;
}

// Depths drawn from {0.25, 0.5, 0.75}: many ties, so "farthest" is reached by many pixels.
inline DepthImage three_values(int w, int h, std::uint32_t seed) {
  std::mt19937 rng(seed);
  DepthImage img(w, h, 0.0f);
  for (float& t : img.texels) t = 0.25f * static_cast<float>(uniform_int(rng, 1, 3));
  return img;
}

// A random background in [0.2, 0.6) (Max) or [0.4, 0.8) (Min) and one pixel at the far plane of
// `op`: a query is right only if its squares include that pixel exactly when they should.
inline DepthImage one_far_pixel(int w, int h, int px, int py, FarOp op, std::uint32_t seed) {
  DepthImage img = op == FarOp::Max ? uniform(w, h, seed, 0.2f, 0.6f) : uniform(w, h, seed, 0.4f, 0.8f);
  img.at(px, py) = far_limit(op);
  return img;
}

// Alternating a and b like a chess board; (0, 0) holds a.
inline DepthImage checkerboard(int w, int h, float a, float b) {
  DepthImage img(w, h, a);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.at(x, y) = ((x + y) & 1) ? b : a;
  return img;
}

// Ramps in (0, 1] along x (dx), y (dy) or both; a negative step makes the ramp fall. Under Max the
// farthest pixel of a rectangle then sits on one of its edges or corners.
inline DepthImage ramp(int w, int h, int dx, int dy) {
  DepthImage img(w, h, 0.0f);
  const int span = std::max(1, std::abs(dx) * (w - 1) + std::abs(dy) * (h - 1));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int ix = dx >= 0 ? x : w - 1 - x, iy = dy >= 0 ? y : h - 1 - y;
      const int v = std::abs(dx) * ix + std::abs(dy) * iy;
      img.at(x, y) = static_cast<float>(v + 1) / static_cast<float>(span + 1);
    }
  return img;
}

// The reversed-Z mirror: d -> 1 - d, so an image made for Max tests the same geometry under Min.
inline DepthImage mirror(const DepthImage& img) {
  DepthImage m = img;
  for (float& t : m.texels) t = 1.0f - t;
  return m;
}

// Coordinates in [0, n) next to level borders (2^k - 1, 2^k) and image borders (0, 1, n - 2, n - 1).
inline std::vector<int> border_positions(int n) {
  std::vector<int> p{0, 1, n - 2, n - 1};
  for (int k = 1; (1 << k) <= n; ++k) p.insert(p.end(), {(1 << k) - 1, 1 << k});
  std::vector<int> out;
  for (int v : p)
    if (v >= 0 && v < n) out.push_back(v);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

struct NamedImage {
  std::string name;
  DepthImage image;
};

// The adversarial images for `op` (made for Max, mirrored for Min): constant, far plane,
// checkerboard, ramps in every direction, three values, uniform random, and one far pixel on
// pairs of border positions (all pairs, or max_far_pixels of them picked at random).
inline std::vector<NamedImage> adversarial_images(int w, int h, FarOp op, std::uint32_t seed, int max_far_pixels = 16) {
  std::vector<NamedImage> out;
  auto add = [&](std::string name, DepthImage img) {
    if (op == FarOp::Min) img = mirror(img), name += " (reversed Z)";
    out.push_back({std::move(name), std::move(img)});
  };
  add("constant 0.5", constant(w, h, 0.5f));
  add("far plane 1.0", constant(w, h, 1.0f));
  add("checkerboard", checkerboard(w, h, 0.3f, 0.7f));
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      if (dx || dy) add("ramp " + std::to_string(dx) + "," + std::to_string(dy), ramp(w, h, dx, dy));
  add("three values", three_values(w, h, seed));
  add("uniform", uniform(w, h, seed + 1));
  const std::vector<int> xs = border_positions(w), ys = border_positions(h);
  // All pairs when they are few; otherwise a seeded shuffle of them, cut to max_far_pixels.
  std::vector<std::pair<int, int>> pairs;
  for (const int py : ys)
    for (const int px : xs) pairs.emplace_back(px, py);
  std::mt19937 rng(seed);
  for (std::size_t i = pairs.size(); i > 1; --i)
    std::swap(pairs[i - 1], pairs[static_cast<std::size_t>(uniform_int(rng, 0, static_cast<int>(i) - 1))]);
  pairs.resize(std::min(pairs.size(), static_cast<std::size_t>(max_far_pixels)));
  std::uint32_t k = 0;
  for (const auto& [px, py] : pairs) {
    // Built for the op directly (its far pixel is at the op's far limit): no mirroring.
    out.push_back({"far pixel at " + std::to_string(px) + "," + std::to_string(py) +
                       (op == FarOp::Min ? " (reversed Z)" : ""),
                   one_far_pixel(w, h, px, py, op, seed + 2 + k++)});
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// The rules every N-buffer answer obeys (docs/architecture.md, "Definitions": query), checked one
// by one.

// floor(log2 v) and ceil(log2 v) for v >= 1, written independently of covering.h.
inline int log2_floor(long long v) {
  int n = 0;
  while ((2LL << n) <= v) ++n;
  return n;
}
inline int log2_ceil(long long v) {
  int n = 0;
  while ((1LL << n) < v) ++n;
  return n;
}

// The level a full N-buffer with `levels` levels reads for the clipped rectangle c under `spec`:
// the paper's q = S / 2, or q / 4 for a row or column no more than q / 2 thick (Fig. 3), with S the
// smallest power of two at least max(w, h); the corners' floor(log2 max(w, h)); one square's
// ceil(log2 max(w, h)) (the corners' of the top level when that is too high).
inline int expected_level(const Rect& c, CoveringSpec spec, int levels) {
  const int m = std::max(c.w, c.h);
  const int one = log2_ceil(m);
  if (spec.kind == CoveringKind::Paper) {
    if (one == 0) return 0;
    const long long q = 1LL << (one - 1);
    const bool thin = (c.w > q && 2LL * c.h <= q) || (c.h > q && 2LL * c.w <= q);
    return thin ? one - 2 : one - 1;
  }
  if (spec.kind == CoveringKind::One && one <= levels - 1) return one;
  return std::min(log2_floor(m), levels - 1);
}

// Checks the answer q of a fully built width x height N-buffer with `levels` levels to the
// clipped rectangle c, whose true farthest depth is `truth`. square_far(level, x, y) must give
// the brute-force farthest depth of the square of that texel, clipped to the image. Returns ""
// when every rule holds, else one line per broken rule, naming it.
template <class SquareFar>
std::string check_nbuffer_answer(int width, int height, FarOp op, int levels, const Rect& c, CoveringSpec spec,
                                 const QueryResult& q, float truth, SquareFar&& square_far) {
  std::string err;  // stays empty (no allocation) while every rule holds
  auto fail = [&](const std::string& rule) {
    err += err.empty() ? str(c) + " " + covering_name(spec) + ": " : std::string("; ");
    err += rule;
  };
  if (!q.complete) fail("complete: a full build answered complete=false");
  const int level = expected_level(c, spec, levels);
  if (q.level != level) fail("level: read level " + std::to_string(q.level) + ", expected " + std::to_string(level));
  if (q.level < 0 || q.level >= levels) return err;
  const int side = 1 << q.level;
  // Along each axis: one square when the side fits in a square, else ceil(side length / square).
  const auto per_axis = [side](int len) { return len > side ? (len + side - 1) / side : 1; };
  const int want_count = per_axis(c.w) * per_axis(c.h);
  if (q.texel_count < 1 || q.texel_count > 4) {
    fail("at most four: read " + std::to_string(q.texel_count) + " texels");
    return err;
  }
  if (q.texel_count != want_count)
    fail("count: read " + std::to_string(q.texel_count) + " texels, the covering needs " + std::to_string(want_count));
  const std::span<const Texel> read = q.read();
  float over_squares = neutral_depth(op);
  bool inside = true;
  for (const Texel& t : read) {
    if (t.x < 0 || t.y < 0 || t.x >= width || t.y >= height) {
      fail("anchor: texel " + std::to_string(t.x) + "," + std::to_string(t.y) + " outside the image");
      inside = false;
      continue;
    }
    over_squares = farther(op, over_squares, square_far(q.level, t.x, t.y));
  }
  if (!inside) return err;
  if (const auto hole = first_uncovered(c, read, side))
    fail("cover: no square read covers pixel " + std::to_string(hole->first) + "," + std::to_string(hole->second));
  if (!at_least_as_far(op, q.value, truth))
    fail("conservative: answered " + std::to_string(q.value) + ", nearer than the true farthest " + std::to_string(truth));
  if (q.value != over_squares)
    fail("union: answered " + std::to_string(q.value) + ", the squares read hold " + std::to_string(over_squares));
  if (c.w >= side && c.h >= side) {  // no side shorter than a square: the covering is exact
    for (const Texel& t : read) {
      const Rect sq = clip({t.x, t.y, side, side}, width, height);
      if (sq.x < c.x || sq.y < c.y || sq.x1() > c.x1() || sq.y1() > c.y1())
        fail("exact: both sides are at least " + std::to_string(side) + " but square " + str(sq) + " reads pixels outside");
    }
  }
  // The paper's rows overhang downward (top alignment) unless that would leave the image.
  if (spec.kind == CoveringKind::Paper && c.h < side) {
    const int want_y = spec.align == CoveringAlign::Top ? std::max(0, c.y1() - side) : c.y;
    for (const Texel& t : read)
      if (t.y != want_y) fail("align: a row's square starts at y " + std::to_string(t.y) + ", expected " + std::to_string(want_y));
  }
  return err;
}

// ---------------------------------------------------------------------------------------------
// Collects rule violations found in a loop; reports the count and the first few.
class Failures {
 public:
  void add(const std::string& what) {
    if (count_++ < kShown) shown_ += "\n  " + what;
  }
  long long count() const noexcept { return count_; }
  std::string summary() const {
    return std::to_string(count_) + " violation(s); first ones:" + shown_;
  }

 private:
  static constexpr long long kShown = 8;
  long long count_ = 0;
  std::string shown_;
};

}  // namespace nbsim::ref

// N-buffer construction, queries and incremental updates; see nbuffer.h.
#include "model/nbuffer/nbuffer.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <new>
#include <numeric>
#include <string>

#include "model/common/error.h"

#if defined(__linux__)
#include <sys/mman.h>
#endif
#if defined(__x86_64__)
#include <immintrin.h>
#endif

// The hot row loops get an AVX2 clone next to the baseline one on x86-64 (GCC and Clang pick one
// when the program loads); elsewhere they are compiled once, for the target. NBSIM_BASELINE_ONLY
// leaves the AVX2 clone out: the test binary nbuffer_baseline_tests runs the baseline loops so.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(NBSIM_BASELINE_ONLY)
#define NBSIM_ROW_LOOP_CLONES [[gnu::target_clones("avx2", "default")]]
#else
#define NBSIM_ROW_LOOP_CLONES
#endif

namespace nbsim {

namespace {
constexpr std::size_t huge_page_bytes = std::size_t{2} << 20;  // x86-64 transparent huge page. Fixed.
constexpr std::size_t cache_line_bytes = 64;                    // x86-64 cache line. Fixed.

std::align_val_t level_alignment(std::size_t bytes) noexcept {
  return std::align_val_t{bytes >= huge_page_bytes ? huge_page_bytes : cache_line_bytes};
}
}  // namespace

void* allocate_level_storage(std::size_t bytes) {
  void* p = ::operator new(bytes, level_alignment(bytes));
#if defined(MADV_HUGEPAGE)
  // Advice only: where the kernel has no huge pages to give, the build is merely slower.
  if (bytes >= huge_page_bytes) ::madvise(p, bytes / huge_page_bytes * huge_page_bytes, MADV_HUGEPAGE);
#endif
  return p;
}

void free_level_storage(void* p, std::size_t bytes) noexcept { ::operator delete(p, level_alignment(bytes)); }

namespace {

template <FarOp Op>
inline float far2(float a, float b) noexcept {
  if constexpr (Op == FarOp::Max) return a > b ? a : b;
  else return a < b ? a : b;
}

// out[x] for x in [x0, x1) of a level whose rows below are `a` (row y) and `b` (row y + s, or
// null past the top edge): the farthest of a[x], a[x + s], b[x], b[x + s], skipping what lies
// outside the image. Written as plain loops so that the compiler vectorizes them.
template <FarOp Op>
[[gnu::always_inline]] inline void reduce_row(const float* a, const float* b, float* out, int x0, int x1, int width, int s) noexcept {
  const int split = std::clamp(width - s, x0, x1);  // x < split has x + s inside the image
  if (b) {
    for (int x = x0; x < split; ++x) out[x] = far2<Op>(far2<Op>(a[x], a[x + s]), far2<Op>(b[x], b[x + s]));
    for (int x = split; x < x1; ++x) out[x] = far2<Op>(a[x], b[x]);
  } else {
    for (int x = x0; x < split; ++x) out[x] = far2<Op>(a[x], a[x + s]);
    for (int x = split; x < x1; ++x) out[x] = a[x];
  }
}

NBSIM_ROW_LOOP_CLONES void reduce_row(FarOp op, const float* a, const float* b, float* out, int x0, int x1, int width, int s) noexcept {
  if (op == FarOp::Max) reduce_row<FarOp::Max>(a, b, out, x0, x1, width, s);
  else reduce_row<FarOp::Min>(a, b, out, x0, x1, width, s);
}

// What apply_row did to one row: texels rewritten, and the first and last of them.
struct RowChange {
  long long count = 0;
  int first = 0, last = -1;
};

// Writes each row[x] that differs (!=) from out[x], x in [x0, x1). A count first, then a select
// over the span from the first to the last difference: both vectorize, and a row without changes
// is only read.
NBSIM_ROW_LOOP_CLONES RowChange apply_row(const float* __restrict row, float* __restrict out, int x0,
                                          int x1) noexcept {
  RowChange c;
  for (int x = x0; x < x1; ++x) c.count += out[x] != row[x];
  if (c.count == 0) return c;
  c.first = x0;
  while (!(out[c.first] != row[c.first])) ++c.first;
  c.last = x1 - 1;
  while (!(out[c.last] != row[c.last])) --c.last;
  for (int x = c.first; x <= c.last; ++x) out[x] = out[x] != row[x] ? row[x] : out[x];
  return c;
}

// Rectangle levels: row [x0, x1) of a level from the row `a` of its parent, one step of `s` texels
// horizontally (a[x] and a[x + s]), or vertically with `b` the parent's row s above (null past
// the image's top: a[x] alone).
template <FarOp Op>
[[gnu::always_inline]] inline void reduce_rect_row(const float* a, const float* b, float* out, int x0, int x1, int width,
                                                   int s, bool horizontal) noexcept {
  if (horizontal) {
    const int split = std::clamp(width - s, x0, x1);
    for (int x = x0; x < split; ++x) out[x] = far2<Op>(a[x], a[x + s]);
    for (int x = split; x < x1; ++x) out[x] = a[x];
  } else if (b) {
    for (int x = x0; x < x1; ++x) out[x] = far2<Op>(a[x], b[x]);
  } else {
    for (int x = x0; x < x1; ++x) out[x] = a[x];
  }
}

NBSIM_ROW_LOOP_CLONES void reduce_rect_row(FarOp op, const float* a, const float* b, float* out, int x0, int x1, int width, int s,
                                           bool horizontal) noexcept {
  if (op == FarOp::Max) reduce_rect_row<FarOp::Max>(a, b, out, x0, x1, width, s, horizontal);
  else reduce_rect_row<FarOp::Min>(a, b, out, x0, x1, width, s, horizontal);
}

void grow(Rect& box, int x, int y) noexcept {
  if (box.empty()) { box = {x, y, 1, 1}; return; }
  const int x0 = std::min(box.x, x), y0 = std::min(box.y, y);
  const int x1 = std::max(box.x1(), x + 1), y1 = std::max(box.y1(), y + 1);
  box = {x0, y0, x1 - x0, y1 - y0};
}

}  // namespace

long long UpdateStats::total_recomputed() const noexcept {
  return std::accumulate(texels_recomputed.begin(), texels_recomputed.end(), 0LL);
}
long long UpdateStats::total_changed() const noexcept {
  return std::accumulate(texels_changed.begin(), texels_changed.end(), 0LL);
}

std::vector<std::pair<int, int>> rect_levels(int width, int height, int max_aspect_log2) {
  const int lx = std::max(1, ceil_log2(static_cast<unsigned>(width))), ly = std::max(1, ceil_log2(static_cast<unsigned>(height)));
  const auto allowed = [&](int i, int j) {
    return max_aspect_log2 < 0 || std::abs(i - j) <= max_aspect_log2 || (i > j && j == ly - 1) || (j > i && i == lx - 1);
  };
  std::vector<std::pair<int, int>> out;
  for (int s = 0; s <= lx + ly - 2; ++s)
    for (int i = 0; i < lx; ++i)
      if (const int j = s - i; j >= 0 && j < ly && allowed(i, j)) out.emplace_back(i, j);
  return out;
}

NBuffer::NBuffer(int width, int height, NBufferConfig config) : width_(width), height_(height), config_(config) {
  if (width < 1 || height < 1)
    throw InputError("N-buffer size must be at least 1x1, got " + std::to_string(width) + "x" + std::to_string(height));
  if (config.max_level < -1)
    throw InputError("N-buffer max_level must be -1 (all levels) or at least 0, got " + std::to_string(config.max_level));
  if (config.shape == LevelShape::Rect) {
    if (config.max_level != -1)
      throw InputError("rectangle levels are built whole: max_level must be -1, got " + std::to_string(config.max_level));
    if (config.max_aspect_log2 != -1 && config.max_aspect_log2 < 1)
      throw InputError("rectangle levels: max_aspect_log2 must be -1 (every level) or at least 1 (0 would be the square "
                       "levels), got " + std::to_string(config.max_aspect_log2));
    levels_x_ = std::max(1, ceil_log2(static_cast<unsigned>(width)));
    levels_y_ = std::max(1, ceil_log2(static_cast<unsigned>(height)));
    exponents_ = nbsim::rect_levels(width, height, config.max_aspect_log2);
    plane_of_.assign(static_cast<std::size_t>(levels_x_) * static_cast<std::size_t>(levels_y_), -1);
    for (std::size_t p = 0; p < exponents_.size(); ++p)
      plane_of_[static_cast<std::size_t>(exponents_[p].first + levels_x_ * exponents_[p].second)] = static_cast<int>(p);
    parent_.assign(exponents_.size(), -1);
    horizontal_.assign(exponents_.size(), 1);
    for (std::size_t p = 1; p < exponents_.size(); ++p) {
      const auto [i, j] = exponents_[p];
      const bool h = i >= j;  // wider (or square): from the level half as wide
      const int from = plane_of_[static_cast<std::size_t>(h ? (i - 1) + levels_x_ * j : i + levels_x_ * (j - 1))];
      NBSIM_CHECK(from >= 0 && static_cast<std::size_t>(from) < p, "rectangle level built before its parent");
      parent_[p] = from;
      horizontal_[p] = h ? 1 : 0;
    }
    full_levels_ = levels_ = static_cast<int>(exponents_.size());
  } else {
    full_levels_ = nbuffer_level_count(width, height);
    levels_ = config.max_level < 0 ? full_levels_ : std::min(config.max_level, full_levels_ - 1) + 1;
  }
  const long long bytes = static_cast<long long>(levels_) * static_cast<long long>(pixels()) * 4;
  if (bytes > kMaxNBufferBytes)
    throw InputError("an N-buffer of " + std::to_string(levels_) + (has_rect_levels() ? " rectangle" : "") + " levels of " +
                     std::to_string(width) + "x" + std::to_string(height) + " floats needs " + std::to_string(bytes >> 20) +
                     " MiB, above the limit of " + std::to_string(kMaxNBufferBytes >> 20) + " MiB" +
                     (has_rect_levels() ? " (fewer rectangle levels: a max_aspect_log2 of 1 or 2; or a resolution divisor)" : ""));
  data_.assign(static_cast<std::size_t>(levels_) * pixels(), far_limit(config.op));
}

std::pair<int, int> NBuffer::level_exponents(int level) const noexcept {
  return has_rect_levels() ? exponents_[static_cast<std::size_t>(level)] : std::pair{level, level};
}

std::string NBuffer::level_label(int level) const {
  if (!has_rect_levels()) return std::to_string(level);
  const auto [i, j] = exponents_[static_cast<std::size_t>(level)];
  return std::to_string(1 << i) + "x" + std::to_string(1 << j);
}

Covering NBuffer::covering(const Rect& clipped, CoveringSpec spec) const {
  if (!has_rect_levels()) return cover(clipped, spec, full_levels_ - 1);
  Covering c = cover_rect(clipped, levels_x_, levels_y_, config_.max_aspect_log2, spec.align);
  c.level = plane_of_[static_cast<std::size_t>(c.log2_w + levels_x_ * c.log2_h)];
  NBSIM_CHECK(c.level >= 0, "a rectangle covering reads a level that is not built");
  return c;
}

long long NBuffer::rect_reduce(int p, const Rect& region, Rect& changed) {
  const auto [i, j] = exponents_[static_cast<std::size_t>(p)];
  const bool h = horizontal_[static_cast<std::size_t>(p)] != 0;
  const int s = 1 << ((h ? i : j) - 1);
  const float* src = level_ptr(parent_[static_cast<std::size_t>(p)]);
  float* dst = level_ptr(p);
  std::vector<float> row(static_cast<std::size_t>(width_));
  long long count = 0;
  for (int y = region.y; y < region.y1(); ++y) {
    const float* a = src + static_cast<std::size_t>(y) * width_;
    const float* b = !h && y + s < height_ ? a + static_cast<std::size_t>(s) * width_ : nullptr;
    reduce_rect_row(config_.op, a, b, row.data(), region.x, region.x1(), width_, s, h);
    const RowChange c = apply_row(row.data(), dst + static_cast<std::size_t>(y) * width_, region.x, region.x1());
    count += c.count;
    if (c.count) { grow(changed, c.first, y); grow(changed, c.last, y); }
  }
  return count;
}

UpdateStats NBuffer::rect_update_from(Rect changed0, UpdateStats stats) {
  // Plane p texel (x, y) reads its parent at x and x + s (or y and y + s): a change in box B of the
  // parent reaches [B.x - s, B.x1) (or [B.y - s, B.y1)) of p; only the texels that change go on.
  std::vector<Rect> changed(exponents_.size());
  changed[0] = changed0;
  for (std::size_t p = 1; p < exponents_.size(); ++p) {
    const Rect& from = changed[static_cast<std::size_t>(parent_[p])];
    if (from.empty()) continue;
    const auto [i, j] = exponents_[p];
    const bool h = horizontal_[p] != 0;
    const int s = 1 << ((h ? i : j) - 1);
    const Rect reach = clip(h ? Rect{from.x - s, from.y, from.w + s, from.h} : Rect{from.x, from.y - s, from.w, from.h + s}, width_,
                            height_);
    stats.texels_recomputed[p] = reach.area();
    stats.texels_changed[p] = rect_reduce(static_cast<int>(p), reach, changed[p]);
  }
  return stats;
}

NBuffer::NBuffer(const DepthImage& depth, NBufferConfig config) : NBuffer(depth.width, depth.height, config) {
  build(depth);
}

namespace {

// Banded builds (NBuffer::build_banded, for levels that fit in the last-level cache). A level pass
// costs about what copying its plane costs plus its arithmetic, and the two overlap poorly. So the
// build (1) runs level 0 and the levels with steps up to build_band_max_step band by band, top
// down, so that the rows a level reads were written a moment ago and are still in cache, (2)
// computes G rows y, y + s, ..., y + (G - 1) s of a level together from the G + 1 rows below (G = 4;
// 2 or single rows where four do not fit), so that each horizontal pair far(a[x], a[x + s]) is
// loaded and reduced once instead of twice, and (3) runs its row loops in an AVX2 clone where the
// CPU has AVX2 (NBSIM_ROW_LOOP_CLONES), on levels in huge pages (allocate_level_storage). Where the
// levels do not fit in the cache it costs more than the row build below (at 1024x1024 about 1.45
// times the level-by-level copy on a 32 MiB-L3 host where the row build takes 0.85 to 0.93;
// docs/results.md, Table 1). The two constants are tunable: (64, 64) and the pairs (64, 16),
// (32, 32), (128, 64), (128, 128) and (64, all) timed within the noise of one another with
// `nbsim bench nbuffer --only build` at 1024x1024 on the project's shared 2-core machines.
constexpr int build_band_rows = 64;      // rows per band
constexpr int build_band_max_step = 64;  // levels with s <= this are banded; the others go plane by plane

// Rows y, y + s, ..., y + (G - 1) s of level i + 1 (`out`, rows `row_step` floats apart) from rows
// y .. y + G s of level i (`in`), all inside the image. Same reduction order as reduce_row, so the
// results are bit-identical to it (signed zeros and NaNs included).
template <FarOp Op, int G>
[[gnu::always_inline]] inline void reduce_row_group(const float* __restrict in, float* __restrict out,
                                                     std::ptrdiff_t row_step, int width, int s) noexcept {
  const int split = std::clamp(width - s, 0, width);  // x < split has x + s inside the image
  for (int x = 0; x < split; ++x) {
    float h[G + 1];
    for (int k = 0; k <= G; ++k) h[k] = far2<Op>(in[k * row_step + x], in[k * row_step + x + s]);
    for (int k = 0; k < G; ++k) out[k * row_step + x] = far2<Op>(h[k], h[k + 1]);
  }
  for (int x = split; x < width; ++x)
    for (int k = 0; k < G; ++k) out[k * row_step + x] = far2<Op>(in[k * row_step + x], in[(k + 1) * row_step + x]);
}

// Rows [y0, y1) of a level with step s from the level below (`src`), whose rows [y0, height) must
// be final. Groups of four rows, then of two, where their source rows exist; single rows elsewhere.
template <FarOp Op>
[[gnu::always_inline]] inline void reduce_rows(const float* src, float* dst, int width, int height, int s, int y0,
                                               int y1) noexcept {
  const std::size_t w = static_cast<std::size_t>(width);
  const std::ptrdiff_t row_step = static_cast<std::ptrdiff_t>(s) * width;
  int y = y0;
  for (; y + 4 * s <= y1 && y + 5 * s <= height; y += 4 * s)
    for (int r = y; r < y + s; ++r) reduce_row_group<Op, 4>(src + r * w, dst + r * w, row_step, width, s);
  for (; y + 2 * s <= y1 && y + 3 * s <= height; y += 2 * s)
    for (int r = y; r < y + s; ++r) reduce_row_group<Op, 2>(src + r * w, dst + r * w, row_step, width, s);
  for (; y < y1; ++y)
    reduce_row<Op>(src + y * w, y + s < height ? src + (y + s) * w : nullptr, dst + y * w, 0, width, width, s);
}

NBSIM_ROW_LOOP_CLONES void reduce_rows(FarOp op, const float* src, float* dst, int width, int height, int s,
                                       int y0, int y1) noexcept {
  if (op == FarOp::Max) reduce_rows<FarOp::Max>(src, dst, width, height, s, y0, y1);
  else reduce_rows<FarOp::Min>(src, dst, width, height, s, y0, y1);
}


// Row builds (NBuffer::build_rows, for levels larger than the last-level cache) go row by row,
// from the top row down, and compute every level of a row before the next row. With s = 2^(i-1),
// level i's texel (x, y) is far(h_i(y)[x], h_i(y+s)[x]) (h_i(y)[x] alone past the top edge), where
// h_i(y)[x] = far(L_{i-1}(y)[x], L_{i-1}(y)[x+s]) (L_{i-1}(y)[x] past the right edge) is the
// horizontal pair level i reads in row y: the reduction order of reduce_row, so the levels are
// bit-identical to the level-by-level definition (signed zeros and NaNs included). A row of level
// i gives level i + 1's pairs of that row at once, and each level keeps only its pairs' last s + 1
// rows, in a ring (BuildRows): about half a plane in all, where a level-by-level build rereads
// every plane it wrote. Where the CPU has AVX2, the planes are written with non-temporal stores in
// the loop that computes them: the build never reads them back, and keeping them out of the caches
// keeps the rings in. docs/results.md (Table 1) has the measurements and the designs tried before.

// The build's scratch rows: one row T (a level's row just computed) and, for each level i >= 1, a
// ring of min(2^(i-1) + 1, height) rows of its pairs h_i. Rows are 16-float aligned and padded past
// the width (the vector loops run to a multiple of 8 and read a few texels beyond it), and one
// cache line longer than a multiple of 64 bytes would make them, so that rows 4 KiB apart in a
// plane are not 4 KiB apart here and the rows a loop reads do not share cache sets.
struct BuildRows {
  std::size_t stride = 0;
  float* t = nullptr;
  std::vector<float*> ring;  // ring[i]: level i's first ring row (ring[0] unused)
  std::vector<int> cap;      // rows in ring[i]
  float* pairs(int i, int y) const noexcept {
    return ring[static_cast<std::size_t>(i)] + static_cast<std::size_t>(y % cap[static_cast<std::size_t>(i)]) * stride;
  }
};

// The size of the largest cache cpu0 has (Linux sysfs: one instance, as its cores see it; glibc's
// sysconf may give the whole socket's sum), 16 MiB where the system does not say.
std::size_t last_level_cache_bytes() noexcept {
  static const std::size_t bytes = [] {
    std::size_t best = 0;
    for (int index = 0; index < 8; ++index) {
      std::ifstream in("/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(index) + "/size");
      std::size_t size = 0;
      char unit = 0;
      if (!(in >> size)) continue;
      in >> unit;
      best = std::max(best, unit == 'K' ? size << 10 : unit == 'M' ? size << 20 : size);
    }
    return best > 0 ? best : std::size_t{16} << 20;
  }();
  return bytes;
}

std::size_t build_row_stride(int width) noexcept { return (static_cast<std::size_t>(width) + 15) / 16 * 16 + 16; }

std::size_t build_rows_floats(int width, int height, int levels) noexcept {
  std::size_t rows = 1;
  for (int i = 1; i < levels; ++i) rows += static_cast<std::size_t>(std::min((1LL << (i - 1)) + 1, static_cast<long long>(height)));
  return rows * build_row_stride(width);
}

BuildRows make_build_rows(float* base, int width, int height, int levels) {
  BuildRows r;
  r.stride = build_row_stride(width);
  r.t = base;
  r.ring.assign(static_cast<std::size_t>(levels), nullptr);
  r.cap.assign(static_cast<std::size_t>(levels), 1);
  float* p = base + r.stride;
  for (int i = 1; i < levels; ++i) {
    r.cap[static_cast<std::size_t>(i)] = static_cast<int>(std::min((1LL << (i - 1)) + 1, static_cast<long long>(height)));
    r.ring[static_cast<std::size_t>(i)] = p;
    p += static_cast<std::size_t>(r.cap[static_cast<std::size_t>(i)]) * r.stride;
  }
  return r;
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(NBSIM_BASELINE_ONLY)
#define NBSIM_STREAMING_BUILD 1

bool has_avx2() noexcept {
  static const bool yes = __builtin_cpu_supports("avx2");
  return yes;
}

// out[0, width) = in[0, width) with non-temporal stores where `out` is 32-byte aligned.
[[gnu::target("avx2")]] void stream_row(const float* in, float* out, int width) noexcept {
  int x = 0;
  for (; x < width && (reinterpret_cast<std::uintptr_t>(out + x) & 31) != 0; ++x) out[x] = in[x];
  for (; x + 8 <= width; x += 8) _mm256_stream_ps(out + x, _mm256_loadu_ps(in + x));
  for (; x < width; ++x) out[x] = in[x];
}

template <FarOp Op>
[[gnu::target("avx2"), gnu::always_inline]] inline __m256 far8(__m256 u, __m256 v) noexcept {
  if constexpr (Op == FarOp::Max) return _mm256_max_ps(u, v);  // u > v ? u : v per lane, as far2
  else return _mm256_min_ps(u, v);
}

// One level row: v = far(a, b) (a where b is null), stored to t (when not null) and streamed to
// `plane` (when not null: 32-byte aligned, width a multiple of 8), and, when h is not null, the
// next level's pairs h[x] = far(v[x], v[x + step]) (v[x] for x >= width - step). x runs down by
// eights: for a step of 1, 2 or 4 (Shift = step) v[x + step] comes from this vector and the one
// before, shifted in registers; for a step of 8 or more (Shift = 8) it is read back from t, already
// written. b, t and h are BuildRows rows; a is one too, or a level-0 row whose width is a multiple
// of 8.
template <FarOp Op, int Shift>
[[gnu::target("avx2")]] void level_row_avx2(const float* a, const float* b, float* t, float* plane, float* h, int width,
                                            int step) noexcept {
  const int split = width - step;  // x < split pairs with x + step
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  __m256 above = _mm256_setzero_ps();  // v at x + 8 (lanes past the width only meet lanes >= split)
  for (int x = (width + 7) / 8 * 8 - 8; x >= 0; x -= 8) {
    __m256 v = _mm256_loadu_ps(a + x);
    if (b) v = far8<Op>(v, _mm256_load_ps(b + x));
    if (t) _mm256_store_ps(t + x, v);
    if (plane) _mm256_stream_ps(plane + x, v);
    if (h) {
      __m256 next;  // v at x + step
      if constexpr (Shift == 8) {
        next = _mm256_load_ps(t + x + step);
      } else {
        const __m256 mid = _mm256_permute2f128_ps(v, above, 0x21);  // v at x + 4
        if constexpr (Shift == 4) next = mid;
        else
          next = _mm256_castsi256_ps(_mm256_alignr_epi8(_mm256_castps_si256(mid), _mm256_castps_si256(v), 4 * Shift));
      }
      __m256 p = v;
      if (x + 8 <= split) p = far8<Op>(v, next);
      else if (x < split)
        p = _mm256_blendv_ps(v, far8<Op>(v, next), _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(split - x), lane)));
      _mm256_store_ps(h + x, p);
    }
    above = v;
  }
}

// level_row_avx2 with the shift of `step` and the far operation as template arguments.
void level_row(FarOp op, const float* a, const float* b, float* t, float* plane, float* h, int width, int step) noexcept {
  const auto run = [&]<FarOp Op>() {
    switch (step) {
      case 1: return level_row_avx2<Op, 1>(a, b, t, plane, h, width, step);
      case 2: return level_row_avx2<Op, 2>(a, b, t, plane, h, width, step);
      case 4: return level_row_avx2<Op, 4>(a, b, t, plane, h, width, step);
      default: return level_row_avx2<Op, 8>(a, b, t, plane, h, width, step);
    }
  };
  if (op == FarOp::Max) run.template operator()<FarOp::Max>();
  else run.template operator()<FarOp::Min>();
}
#else
#define NBSIM_STREAMING_BUILD 0
#endif

// The row build streams its planes out (AVX2 on x86-64, and not the baseline-only test build).
bool streaming_build() noexcept {
#if NBSIM_STREAMING_BUILD
  return has_avx2();
#else
  return false;
#endif
}

}  // namespace

void NBuffer::build(const DepthImage& depth, BuildPath path) {
  NBSIM_CHECK(depth.width == width_ && depth.height == height_, "depth image size differs from the N-buffer's");
  if (has_rect_levels()) return build_rect(depth);
  if (on_demand_) std::fill(current_.begin(), current_.end(), std::uint8_t{1});
  if (path == BuildPath::Auto)  // rows only where they stream: without it they cost about twice the bands
    path = streaming_build() && static_cast<std::size_t>(levels_) * pixels() * sizeof(float) > last_level_cache_bytes()
               ? BuildPath::Rows
               : BuildPath::Banded;
  if (path == BuildPath::Banded) build_banded(depth);
  else build_rows(depth);
}

void NBuffer::build_rows(const DepthImage& depth) {
  const std::size_t need = build_rows_floats(width_, height_, levels_);
  if (build_rows_.size() < need) build_rows_.assign(need, 0.0f);
  const BuildRows rows = make_build_rows(build_rows_.data(), width_, height_, levels_);
  const FarOp op = config_.op;
  const std::size_t w = static_cast<std::size_t>(width_);
  [[maybe_unused]] const bool streaming = streaming_build();  // read only where NBSIM_STREAMING_BUILD
  // Copies a computed row to its plane (streamed where it can).
  const auto put = [&](const float* row, float* out) {
#if NBSIM_STREAMING_BUILD
    if (streaming) return stream_row(row, out, width_);
#endif
    std::copy(row, row + width_, out);
  };
  for (int y = height_ - 1; y >= 0; --y) {
    const float* l0 = depth.texels.data() + y * w;
    if (config_.format != StorageFormat::F32) {
      for (int x = 0; x < width_; ++x) rows.t[x] = quantize_toward_far(l0[x], config_.format, op);
      l0 = rows.t;
    }
    float* out0 = level_ptr(0) + y * w;
    float* h1 = levels_ > 1 ? rows.pairs(1, y) : nullptr;
#if NBSIM_STREAMING_BUILD
    if (streaming && width_ % 8 == 0 && (reinterpret_cast<std::uintptr_t>(out0) & 31) == 0) {
      level_row(op, l0, nullptr, nullptr, out0, h1, width_, 1);
    } else
#endif
    {
      put(l0, out0);
      if (h1) reduce_rect_row(op, l0, nullptr, h1, 0, width_, width_, 1, true);  // the pairs: a horizontal step
    }
    for (int i = 1; i < levels_; ++i) {
      const int s = 1 << (i - 1);
      const float* a = rows.pairs(i, y);
      const float* b = y + s < height_ ? rows.pairs(i, y + s) : nullptr;
      float* h = i + 1 < levels_ ? rows.pairs(i + 1, y) : nullptr;
      float* out = level_ptr(i) + y * w;
#if NBSIM_STREAMING_BUILD
      if (streaming) {
        const bool aligned = width_ % 8 == 0 && (reinterpret_cast<std::uintptr_t>(out) & 31) == 0;
        level_row(op, a, b, rows.t, aligned ? out : nullptr, h, width_, 2 * s);
        if (!aligned) stream_row(rows.t, out, width_);
        continue;
      }
#endif
      const float* row = a;
      if (b) {
        reduce_rect_row(op, a, b, rows.t, 0, width_, width_, s, false);  // far(a[x], b[x]): a vertical step
        row = rows.t;
      }
      std::copy(row, row + width_, out);
      if (h) reduce_rect_row(op, row, nullptr, h, 0, width_, width_, 2 * s, true);
    }
  }
#if NBSIM_STREAMING_BUILD
  if (streaming) _mm_sfence();  // the streamed stores are ordered before whatever reads the levels next
#endif
}

void NBuffer::build_banded(const DepthImage& depth) {
  // Level i's rows [y0, y1) need level i - 1's rows [y0, y1 + s): bands go from the top down.
  int banded = 1;  // levels [1, banded) are built band by band
  while (banded < levels_ && (1 << (banded - 1)) <= build_band_max_step) ++banded;
  const std::size_t w = static_cast<std::size_t>(width_);
  float* l0 = level_ptr(0);
  for (int y1 = height_; y1 > 0; y1 -= build_band_rows) {
    const int y0 = std::max(0, y1 - build_band_rows);
    const float* in = depth.texels.data() + y0 * w;
    float* out = l0 + y0 * w;
    const std::size_t n = static_cast<std::size_t>(y1 - y0) * w;
    if (config_.format == StorageFormat::F32) std::copy(in, in + n, out);
    else for (std::size_t i = 0; i < n; ++i) out[i] = quantize_toward_far(in[i], config_.format, config_.op);
    for (int i = 1; i < banded; ++i)
      reduce_rows(config_.op, level_ptr(i - 1), level_ptr(i), width_, height_, 1 << (i - 1), y0, y1);
  }
  for (int i = banded; i < levels_; ++i)
    reduce_rows(config_.op, level_ptr(i - 1), level_ptr(i), width_, height_, 1 << (i - 1), 0, height_);
}

void NBuffer::build_rect(const DepthImage& depth) {
  const std::size_t n = pixels();
  float* l0 = level_ptr(0);
  if (config_.format == StorageFormat::F32) std::copy(depth.texels.begin(), depth.texels.end(), l0);
  else for (std::size_t i = 0; i < n; ++i) l0[i] = quantize_toward_far(depth.texels[i], config_.format, config_.op);
  for (int p = 1; p < levels_; ++p) {
    const auto [i, j] = exponents_[static_cast<std::size_t>(p)];
    const bool h = horizontal_[static_cast<std::size_t>(p)] != 0;
    const int s = 1 << ((h ? i : j) - 1);
    const float* src = level_ptr(parent_[static_cast<std::size_t>(p)]);
    float* dst = level_ptr(p);
    for (int y = 0; y < height_; ++y) {
      const float* a = src + static_cast<std::size_t>(y) * width_;
      reduce_rect_row(config_.op, a, !h && y + s < height_ ? a + static_cast<std::size_t>(s) * width_ : nullptr,
                      dst + static_cast<std::size_t>(y) * width_, 0, width_, width_, s, h);
    }
  }
}


QueryResult NBuffer::query(const Rect& r, CoveringSpec covering) const {
  if (r.empty())
    throw InputError("empty query rectangle " + std::to_string(r.x) + "," + std::to_string(r.y) + "," +
                     std::to_string(r.w) + "," + std::to_string(r.h) + " (width and height must be at least 1)");
  const Rect c = clip(r, width_, height_);
  if (c.empty())
    throw InputError("query rectangle " + std::to_string(r.x) + "," + std::to_string(r.y) + "," +
                     std::to_string(r.w) + "," + std::to_string(r.h) + " lies outside the " +
                     std::to_string(width_) + "x" + std::to_string(height_) + " image");
  QueryResult q;
  const Covering cov = this->covering(c, covering);
  q.level = cov.level;
  if (cov.level >= levels_) {  // partial build: the level is missing, answer the far limit
    q.value = far_limit(config_.op);
    q.complete = false;
    return q;
  }
  q.value = neutral_depth(config_.op);
  for (int i = 0; i < cov.count; ++i) {
    // The squares of a clipped rectangle start inside the image; they may reach past its right and
    // top edges, where the level already treats pixels as neutral.
    const Texel t{cov.squares[static_cast<std::size_t>(i)].x, cov.squares[static_cast<std::size_t>(i)].y};
    q.texels[static_cast<std::size_t>(q.texel_count++)] = t;
    q.value = farther(config_.op, q.value, texel(cov.level, t.x, t.y));
  }
  return q;
}

UpdateStats NBuffer::new_stats() const {
  UpdateStats s;
  s.texels_recomputed.assign(static_cast<std::size_t>(levels_), 0);
  s.texels_changed.assign(static_cast<std::size_t>(levels_), 0);
  s.texels_invalidated.assign(static_cast<std::size_t>(levels_), 0);
  return s;
}

void NBuffer::set_on_demand(bool on) {
  if (on && has_rect_levels()) throw InputError("an on-demand N-buffer has square levels only (levels=rect cannot be computed on demand)");
  on_demand_ = on;
  if (on) current_.assign(static_cast<std::size_t>(levels_) * pixels(), 1);  // the levels as they stand are current
  else current_.clear();
}

long long NBuffer::current_texels(int level) const noexcept {
  if (!on_demand_) return static_cast<long long>(pixels());
  const auto begin = current_.begin() + static_cast<std::ptrdiff_t>(offset(level));
  return std::count(begin, begin + static_cast<std::ptrdiff_t>(pixels()), std::uint8_t{1});
}

void NBuffer::replace_on_demand(const DepthImage& depth) {
  NBSIM_CHECK(on_demand_, "replace_on_demand needs an on-demand N-buffer");
  NBSIM_CHECK(depth.width == width_ && depth.height == height_, "depth image size differs from the N-buffer's");
  std::copy(depth.texels.begin(), depth.texels.end(), level_ptr(0));
  std::fill(current_.begin() + static_cast<std::ptrdiff_t>(offset(1)), current_.end(), std::uint8_t{0});
}

void NBuffer::ensure(int level, int x, int y, UpdateStats& stats) {
  NBSIM_CHECK(level >= 0 && level < levels_ && x >= 0 && y >= 0 && x < width_ && y < height_, "N-buffer texel out of range");
  if (!on_demand_ || level == 0) return;
  const std::size_t k = offset(level) + static_cast<std::size_t>(y) * width_ + x;
  if (current_[k]) return;
  // Its four sources (inside the image) first, then the texel: level - 1 at x, x + s and y, y + s.
  const int s = 1 << (level - 1);
  const bool right = x + s < width_, up = y + s < height_;
  ensure(level - 1, x, y, stats);
  if (right) ensure(level - 1, x + s, y, stats);
  if (up) ensure(level - 1, x, y + s, stats);
  if (right && up) ensure(level - 1, x + s, y + s, stats);
  const float* src = level_ptr(level - 1);
  const std::size_t j = static_cast<std::size_t>(y) * width_ + x;
  float v = src[j];
  if (right) v = farther(config_.op, v, src[j + s]);
  if (up) {
    const std::size_t u = j + static_cast<std::size_t>(s) * width_;
    v = farther(config_.op, v, src[u]);
    if (right) v = farther(config_.op, v, src[u + s]);
  }
  ++stats.texels_recomputed[static_cast<std::size_t>(level)];
  float& dst = data_[k];
  if (dst != v) ++stats.texels_changed[static_cast<std::size_t>(level)];
  dst = v;
  current_[k] = 1;
}

void NBuffer::ensure_all(UpdateStats& stats) {
  if (!on_demand_) return;
  for (int i = 1; i < levels_; ++i)
    for (int y = 0; y < height_; ++y)
      for (int x = 0; x < width_; ++x) ensure(i, x, y, stats);
}

void NBuffer::invalidate_from(std::vector<Texel>& changed, UpdateStats& stats) {
  std::vector<Texel> next;
  for (int i = 1; i < levels_ && !changed.empty(); ++i) {
    const int s = 1 << (i - 1);
    next.clear();
    std::uint8_t* cur = current_.data() + offset(i);
    for (const Texel t : changed)
      for (int dy = 0; dy <= s; dy += s)
        for (int dx = 0; dx <= s; dx += s) {
          const int x = t.x - dx, y = t.y - dy;
          if (x < 0 || y < 0) continue;
          std::uint8_t& c = cur[static_cast<std::size_t>(y) * width_ + x];
          if (!c) continue;  // stale already, and so is every texel that reads it
          c = 0;
          next.push_back({x, y});
        }
    stats.texels_invalidated[static_cast<std::size_t>(i)] += static_cast<long long>(next.size());
    std::swap(changed, next);
  }
}

UpdateStats NBuffer::update(const DepthImage& depth, const Rect& dirty) {
  NBSIM_CHECK(depth.width == width_ && depth.height == height_, "depth image size differs from the N-buffer's");
  UpdateStats stats = new_stats();
  const Rect r = clip(dirty, width_, height_);
  if (r.empty()) return stats;

  if (on_demand_) {  // level 0 pixel by pixel, then the texels that read a changed one are marked stale
    std::vector<Texel> changed;
    float* l0 = level_ptr(0);
    for (int y = r.y; y < r.y1(); ++y)
      for (int x = r.x; x < r.x1(); ++x) {
        const std::size_t k = static_cast<std::size_t>(y) * width_ + x;
        const float v = quantize_toward_far(depth.texels[k], config_.format, config_.op);
        if (l0[k] != v) changed.push_back({x, y});
        l0[k] = v;
      }
    stats.texels_recomputed[0] = r.area();
    stats.texels_changed[0] = static_cast<long long>(changed.size());
    invalidate_from(changed, stats);
    return stats;
  }
  // Level 0: copy the dirty pixels, note the bounding box of those that changed.
  Rect changed;
  std::vector<float> row(static_cast<std::size_t>(width_));
  for (int y = r.y; y < r.y1(); ++y) {
    const float* in = depth.texels.data() + static_cast<std::size_t>(y) * width_;
    if (config_.format != StorageFormat::F32) {
      for (int x = r.x; x < r.x1(); ++x) row[static_cast<std::size_t>(x)] = quantize_toward_far(in[x], config_.format, config_.op);
      in = row.data();
    }
    const RowChange c = apply_row(in, level_ptr(0) + static_cast<std::size_t>(y) * width_, r.x, r.x1());
    stats.texels_changed[0] += c.count;
    if (c.count) { grow(changed, c.first, y); grow(changed, c.last, y); }
  }
  stats.texels_recomputed[0] = r.area();
  if (has_rect_levels()) return rect_update_from(changed, std::move(stats));

  // Level i: a texel at (x, y) reads level i - 1 at x and x + s, y and y + s, so a change in box B
  // of level i - 1 reaches [B.x - s, B.x1) x [B.y - s, B.y1) of level i, clipped to the image.
  for (int i = 1; i < levels_ && !changed.empty(); ++i) {
    const int s = 1 << (i - 1);
    const Rect reach = clip({changed.x - s, changed.y - s, changed.w + s, changed.h + s}, width_, height_);
    changed = {};
    const float* src = level_ptr(i - 1);
    float* dst = level_ptr(i);
    for (int y = reach.y; y < reach.y1(); ++y) {
      const float* a = src + static_cast<std::size_t>(y) * width_;
      const float* b = y + s < height_ ? a + static_cast<std::size_t>(s) * width_ : nullptr;
      reduce_row(config_.op, a, b, row.data(), reach.x, reach.x1(), width_, s);
      const RowChange c = apply_row(row.data(), dst + static_cast<std::size_t>(y) * width_, reach.x, reach.x1());
      stats.texels_changed[static_cast<std::size_t>(i)] += c.count;
      if (c.count) { grow(changed, c.first, y); grow(changed, c.last, y); }
    }
    stats.texels_recomputed[static_cast<std::size_t>(i)] = reach.area();
  }
  return stats;
}

UpdateStats NBuffer::update(std::span<const PixelWrite> writes) {
  UpdateStats stats = new_stats();
  if (stamp_.size() != pixels()) { stamp_.assign(pixels(), 0); epoch_ = 0; }
  auto next_epoch = [this] {
    if (++epoch_ == 0) { std::fill(stamp_.begin(), stamp_.end(), 0u); epoch_ = 1; }
  };

  // Reject the whole batch before touching level 0: a half-applied batch would leave level 0
  // out of step with the levels above it.
  for (const PixelWrite& w : writes)
    if (w.x < 0 || w.y < 0 || w.x >= width_ || w.y >= height_)
      throw InputError("pixel write at (" + std::to_string(w.x) + "," + std::to_string(w.y) + ") outside the " +
                       std::to_string(width_) + "x" + std::to_string(height_) + " image");

  // Level 0: apply the writes in order; note each pixel the first time it changes, with its value
  // before the batch.
  std::vector<Texel> changed, next;
  std::vector<float> before;
  next_epoch();
  float* l0 = level_ptr(0);
  for (const PixelWrite& w : writes) {
    const std::size_t k = static_cast<std::size_t>(w.y) * width_ + w.x;
    const float v = quantize_toward_far(w.depth, config_.format, config_.op);
    ++stats.texels_recomputed[0];
    if (l0[k] == v) continue;
    if (stamp_[k] != epoch_) { stamp_[k] = epoch_; changed.push_back({w.x, w.y}); before.push_back(l0[k]); }
    l0[k] = v;
  }
  // A pixel written twice may end where it started: keep (and count) only net changes, so that
  // such a pixel recomputes nothing above level 0.
  std::size_t kept = 0;
  for (std::size_t j = 0; j < changed.size(); ++j) {
    const Texel t = changed[j];
    if (l0[static_cast<std::size_t>(t.y) * width_ + t.x] != before[j]) changed[kept++] = t;
  }
  changed.resize(kept);
  stats.texels_changed[0] = static_cast<long long>(changed.size());
  if (on_demand_) {
    invalidate_from(changed, stats);
    return stats;
  }
  if (has_rect_levels()) {  // the changed pixels' box goes up the rectangle levels
    Rect box;
    for (const Texel t : changed) grow(box, t.x, t.y);
    return rect_update_from(box, std::move(stats));
  }

  // Level i: a changed texel (x, y) of level i - 1 is read by the level-i texels at x or x - s and
  // y or y - s. Recompute each of those once; only those whose value changes propagate further.
  for (int i = 1; i < levels_ && !changed.empty(); ++i) {
    const int s = 1 << (i - 1);
    next_epoch();
    next.clear();
    const float* src = level_ptr(i - 1);
    float* dst = level_ptr(i);
    for (const Texel t : changed) {
      for (int dy = 0; dy <= s; dy += s) {
        for (int dx = 0; dx <= s; dx += s) {
          const int x = t.x - dx, y = t.y - dy;
          if (x < 0 || y < 0) continue;
          const std::size_t k = static_cast<std::size_t>(y) * width_ + x;
          if (stamp_[k] == epoch_) continue;
          stamp_[k] = epoch_;
          float v = src[k];
          if (x + s < width_) v = farther(config_.op, v, src[k + s]);
          if (y + s < height_) {
            const std::size_t up = k + static_cast<std::size_t>(s) * width_;
            v = farther(config_.op, v, src[up]);
            if (x + s < width_) v = farther(config_.op, v, src[up + s]);
          }
          ++stats.texels_recomputed[static_cast<std::size_t>(i)];
          if (dst[k] != v) { dst[k] = v; next.push_back({x, y}); }
        }
      }
    }
    stats.texels_changed[static_cast<std::size_t>(i)] = static_cast<long long>(next.size());
    std::swap(changed, next);
  }
  return stats;
}

DepthImage NBuffer::level_image(int i) const {
  DepthImage img;
  img.width = width_;
  img.height = height_;
  const auto l = level(i);
  img.texels.assign(l.begin(), l.end());
  return img;
}

long long NBuffer::storage_bytes() const noexcept {
  return static_cast<long long>(levels_) * static_cast<long long>(pixels()) * nbsim::storage_bytes(config_.format);
}

}  // namespace nbsim

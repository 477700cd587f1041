// The N-buffer (Décoret 2005): a stack of same-resolution depth maps where level i holds, at
// (x, y), the farthest depth of the 2^i x 2^i square [x, x + 2^i) x [y, y + 2^i). Pixels outside
// the image are neutral. Plain C++ core of the N-buffer unit (model/nbuffer); no SystemC here.
//
// Level 0 is a quantized copy of the depth buffer (storage format), level i + 1 is built from four
// texels of level i (Fig. 2). Queries answer a rectangle with at most four lookups (covering.h).
// Updates apply changed level-0 pixels and rewrite, per level, only the texels to their left and
// below that can change, stopping where a recomputed texel keeps its value.
#pragma once

#include <cstddef>
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "model/common/depth.h"
#include "model/common/query.h"
#include "model/common/rect.h"
#include "model/common/storage.h"
#include "model/nbuffer/covering.h"

namespace nbsim {

// The neighbourhoods the levels hold. Fixed values.
//   square: level i holds 2^i x 2^i squares (the paper's N-buffer);
//   rect:   level (i, j) holds 2^i x 2^j rectangles, for i < ceil(log2 W) and j < ceil(log2 H) (the
//           paper's future work, like RIP-maps): every rectangle is read exactly with at most four
//           lookups (covering.h cover_rect), for about ceil(log2 H) times the square levels' memory.
enum class LevelShape : std::uint8_t { Square = 0, Rect = 1 };
inline constexpr std::array<std::string_view, 2> kLevelShapeNames = {"square", "rect"};

// The most memory an N-buffer's levels may take (floats in memory, whatever the storage format:
// 4 GiB, a sixth of the project's machines). Tunable.
inline constexpr long long kMaxNBufferBytes = 4LL << 30;

struct NBufferConfig {
  FarOp op = FarOp::Max;
  StorageFormat format = StorageFormat::F32;
  // Highest level built (a partial build models only what a scene needs: sprites of at most 32 px
  // need levels up to 5). -1 builds all nbuffer_level_count(W, H) levels. Tunable. Square levels
  // only (rectangle levels are always built whole).
  int max_level = -1;
  LevelShape shape = LevelShape::Square;
  // Rectangle levels: only those with |i - j| <= max_aspect_log2 (and the last row and column of
  // levels, which the covering needs), -1 for all; at least 1. Tunable.
  int max_aspect_log2 = -1;
};

// The rectangle levels (i, j) an image of width x height has, in build order (a level after the
// one it is built from), for `max_aspect_log2` (see NBufferConfig).
std::vector<std::pair<int, int>> rect_levels(int width, int height, int max_aspect_log2);

// Memory for the levels. Buffers of 2 MiB and more start on a 2 MiB boundary and, on Linux, are
// offered transparent huge pages (madvise), so that the build's ten-odd row streams, one to four
// per level, do not miss the TLB at every row (a fifth or more of a 1024x1024 build); smaller ones start
// on a cache-line boundary, so that the build's vector stores never straddle two lines when rows
// are a multiple of 16 texels.
void* allocate_level_storage(std::size_t bytes);
void free_level_storage(void* p, std::size_t bytes) noexcept;

template <class T>
struct LevelAllocator {
  using value_type = T;
  LevelAllocator() noexcept = default;
  template <class U>
  LevelAllocator(const LevelAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) { return static_cast<T*>(allocate_level_storage(n * sizeof(T))); }
  void deallocate(T* p, std::size_t n) noexcept { free_level_storage(p, n * sizeof(T)); }
  friend bool operator==(const LevelAllocator&, const LevelAllocator&) noexcept { return true; }
};

// One changed level-0 pixel and its new depth.
struct PixelWrite {
  int x = 0;
  int y = 0;
  float depth = 0.0f;
};

// Work done by an update, per level (index = level).
struct UpdateStats {
  std::vector<long long> texels_recomputed;  // texels read-modify-written (4 reads each above level 0)
  std::vector<long long> texels_changed;     // of those, texels whose stored value changed
  // On demand (NBuffer::set_on_demand): level texels marked stale because a pixel they read changed
  // (a flag cleared, no texel read or written).
  std::vector<long long> texels_invalidated;

  long long total_recomputed() const noexcept;
  long long total_changed() const noexcept;
};

class NBuffer {
 public:
  // An N-buffer of the given size, every texel at the far limit (a cleared depth buffer).
  NBuffer(int width, int height, NBufferConfig config = {});
  // Builds from a depth image.
  explicit NBuffer(const DepthImage& depth, NBufferConfig config = {});

  // How build() computes the levels; every path gives the same texels, bit for bit.
  enum class BuildPath {
    Auto,    // Rows where the levels do not fit in the last-level cache and the CPU has AVX2, else Banded
    Banded,  // levels 0-7 band by band, the others plane by plane
    Rows,    // row by row, every level of a row at once, the planes streamed out (AVX2 CPUs)
  };
  // Replaces level 0 with `depth` (same size) and rebuilds every level.
  void build(const DepthImage& depth, BuildPath path = BuildPath::Auto);

  // Farthest depth of r (clipped to the image) with at most four lookups, placed by `covering`
  // (covering.h; rectangle levels read cover_rect's rectangles, with the covering's alignment).
  // Throws InputError when r is empty or lies outside the image. When the level the covering needs
  // was not built, the answer is the far limit with complete == false (conservative, never wrong).
  QueryResult query(const Rect& r, CoveringSpec covering = {}) const;
  // The covering query() reads for a rectangle already clipped to the image; its level is the
  // plane read (for rectangle levels, the plane of its 2^log2_w x 2^log2_h rectangles).
  Covering covering(const Rect& clipped, CoveringSpec spec) const;

  // On demand ("model only what a scene needs"): levels above 0 are computed when a query reads
  // them. update() writes level 0 and marks stale the level texels that read a changed pixel (the
  // texels still current, and recursively those that read them: a current texel's four sources are
  // always current, so the marking stops where it meets a stale texel); ensure() computes a stale
  // texel from the level below, recursively, and keeps it until a pixel under it changes. Every
  // answer equals a full build's. build() still builds every level (a clear writes them all).
  // Square levels only: InputError for rectangle levels.
  void set_on_demand(bool on);
  bool on_demand() const noexcept { return on_demand_; }
  // Makes texel (level, x, y) current (in the image), counting the texels it computed in `stats`.
  void ensure(int level, int x, int y, UpdateStats& stats);
  // Makes every texel current (before the levels are read out whole).
  void ensure_all(UpdateStats& stats);
  // On demand: level 0 replaced by `depth` (same size) and every texel above it stale, as after a
  // clear and a new level 0 (no texel above level 0 computed, none invalidated one by one).
  void replace_on_demand(const DepthImage& depth);
  // Texels of `level` that are current (every one when not on demand).
  long long current_texels(int level) const noexcept;
  UpdateStats new_stats() const;

  // Incremental updates; the result equals a full rebuild from the new level 0.
  // The pixels of `depth` inside `dirty` replace level 0's (depth must be the N-buffer's size).
  UpdateStats update(const DepthImage& depth, const Rect& dirty);
  // Each write replaces one level-0 pixel (the last write to a pixel wins).
  UpdateStats update(std::span<const PixelWrite> writes);

  int width() const noexcept { return width_; }
  int height() const noexcept { return height_; }
  const NBufferConfig& config() const noexcept { return config_; }
  // Levels this image would have in full, and levels actually built (max_level + 1).
  int full_level_count() const noexcept { return full_levels_; }
  int level_count() const noexcept { return levels_; }
  int top_level() const noexcept { return levels_ - 1; }
  bool has_rect_levels() const noexcept { return config_.shape == LevelShape::Rect; }
  // The neighbourhood of plane `level`: 2^i x 2^j (square levels: i = j = level).
  std::pair<int, int> level_exponents(int level) const noexcept;
  // "3" for square level 3, "8x4" for the rectangle level of 8 x 4 neighbourhoods.
  std::string level_label(int level) const;

  float texel(int level, int x, int y) const noexcept {
    return data_[offset(level) + static_cast<std::size_t>(y) * width_ + x];
  }
  std::span<const float> level(int i) const noexcept { return {data_.data() + offset(i), pixels()}; }
  DepthImage level_image(int i) const;

  // Bytes the levels occupy in memory in the storage format.
  long long storage_bytes() const noexcept;

 private:
  std::size_t pixels() const noexcept { return static_cast<std::size_t>(width_) * height_; }
  std::size_t offset(int level) const noexcept { return static_cast<std::size_t>(level) * pixels(); }
  float* level_ptr(int i) noexcept { return data_.data() + offset(i); }
  void build_banded(const DepthImage& depth);
  void build_rows(const DepthImage& depth);
  void build_rect(const DepthImage& depth);
  // On demand: marks stale the texels above level 0 that read the changed level-0 texels.
  void invalidate_from(std::vector<Texel>& changed, UpdateStats& stats);
  // Rectangle levels: plane `p` from its parent plane over the texels [x0, x1) x [y0, y1); returns
  // the changed texels' count and grows `changed` by their box.
  long long rect_reduce(int p, const Rect& region, Rect& changed);
  UpdateStats rect_update_from(Rect changed0, UpdateStats stats);

  int width_ = 0, height_ = 0;
  NBufferConfig config_;
  int full_levels_ = 1, levels_ = 1;
  std::vector<float, LevelAllocator<float>> data_;  // levels_ planes of width_ * height_ texels
  std::vector<float, LevelAllocator<float>> build_rows_;  // build()'s scratch rows (nbuffer.cpp, BuildRows), kept between builds
  std::vector<std::uint32_t> stamp_;   // per-pixel visit marks for set updates (lazily sized)
  std::uint32_t epoch_ = 0;
  // Rectangle levels: each plane's exponents, the plane it is built from (-1 for level 0) and
  // whether that step is horizontal; the plane of each (i, j) (i + levels_x * j; -1: not built).
  std::vector<std::pair<int, int>> exponents_;
  std::vector<int> parent_;
  std::vector<std::uint8_t> horizontal_;
  std::vector<int> plane_of_;
  int levels_x_ = 1, levels_y_ = 1;
  // On demand: a flag per texel of every level (level 0's always 1): the texel is current.
  bool on_demand_ = false;
  std::vector<std::uint8_t> current_;
};

}  // namespace nbsim

// NBufferTest: construction and queries of model/nbuffer/nbuffer.h against the brute-force
// reference of tests/common/reference.h (NBufferReferenceTest checks that reference itself).
#include "model/nbuffer/nbuffer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "tests/common/reference.h"

namespace nbsim {
namespace {

constexpr FarOp kOps[] = {FarOp::Max, FarOp::Min};
constexpr CoveringSpec kKinds[] = {{CoveringKind::Paper, CoveringAlign::Top},
                                   {CoveringKind::Paper, CoveringAlign::Bottom},
                                   {CoveringKind::Corners, CoveringAlign::Bottom},
                                   {CoveringKind::One, CoveringAlign::Top}};

std::string name_of(FarOp op) { return std::string(to_string(op)); }

// Every level texel of nb against the brute-force definition; violations go to f.
void expect_levels_match(const NBuffer& nb, const DepthImage& img, FarOp op, const std::string& what, ref::Failures& f) {
  for (int i = 0; i < nb.level_count(); ++i)
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        const float want = ref::level_texel(img, op, i, x, y), got = nb.texel(i, x, y);
        if (got != want)
          f.add(what + ": level " + std::to_string(i) + " texel " + std::to_string(x) + "," + std::to_string(y) +
                " holds " + std::to_string(got) + ", the farthest of its square is " + std::to_string(want));
      }
}

// Queries every rectangle inside img with both coverings and checks every rule of a query. The
// sanitizer job (scripts/sanitize sets NBSIM_SANITIZED) checks every fourth rectangle of the same
// enumeration, the same ones every run: it looks for memory errors on these paths, which a quarter
// of the rectangles walk as well, and the Release suite checks every one.
void check_every_rect(const DepthImage& img, FarOp op, const std::string& what, ref::Failures& f) {
  const NBuffer nb(img, {.op = op});
  const std::vector<DepthImage> levels = ref::nbuffer_levels(img, op, nb.level_count());
  auto square_far = [&](int l, int x, int y) { return levels[static_cast<std::size_t>(l)].at(x, y); };
  static const std::size_t stride = std::getenv("NBSIM_SANITIZED") ? 4 : 1;
  std::size_t seen = 0;
  ref::for_each_rect(img, op, [&](const Rect& r, float truth) {
    if (seen++ % stride != 0) return;
    for (const CoveringSpec kind : kKinds) {
      const QueryResult q = nb.query(r, kind);
      const std::string e =
          ref::check_nbuffer_answer(img.width, img.height, op, nb.level_count(), r, kind, q, truth, square_far);
      if (!e.empty()) f.add(what + " " + e);
    }
  });
}

// Random rectangles (some sticking out of the image) on a large image, truth from row tables.
void check_random_rects(const DepthImage& img, FarOp op, int count, std::uint32_t seed, ref::Failures& f) {
  const NBuffer nb(img, {.op = op});
  const ref::RowTable table(img, op);
  auto square_far = [&](int l, int x, int y) { return table.farthest({x, y, 1 << l, 1 << l}); };
  std::mt19937 rng(seed);
  for (int n = 0; n < count; ++n) {
    const Rect r = ref::random_rect(rng, img.width, img.height, true);
    const Rect c = clip(r, img.width, img.height);
    const float truth = table.farthest(c);
    for (const CoveringSpec kind : kKinds) {
      const QueryResult q = nb.query(r, kind);
      const std::string e =
          ref::check_nbuffer_answer(img.width, img.height, op, nb.level_count(), c, kind, q, truth, square_far);
      if (!e.empty()) f.add(name_of(op) + " query " + ref::str(r) + " clipped to " + e);
    }
  }
}

// ---------------------------------------------------------------------------------------------

// The reference's incremental rectangle enumeration and row tables agree with plain scanning.
TEST(NBufferReferenceTest, EnumerationAndRowTablesMatchScanning) {
  for (const FarOp op : kOps) {
    const DepthImage img = ref::uniform(13, 9, 7);
    long long rects = 0;
    ref::Failures f;
    ref::for_each_rect(img, op, [&](const Rect& r, float truth) {
      ++rects;
      if (truth != ref::farthest(img, op, r)) f.add("for_each_rect " + ref::str(r));
    });
    EXPECT_EQ(rects, (13 * 14 / 2) * (9 * 10 / 2)) << "for_each_rect must visit every rectangle once";
    const ref::RowTable table(img, op);
    for (int y = -2; y < 11; ++y)
      for (int x = -2; x < 15; ++x)
        for (int h = 1; h < 12; ++h)
          for (int w = 1; w < 17; ++w)
            if (table.farthest({x, y, w, h}) != ref::farthest(img, op, {x, y, w, h})) f.add("RowTable " + ref::str({x, y, w, h}));
    EXPECT_EQ(f.count(), 0) << name_of(op) << ": " << f.summary();
  }
}

// The reference coverage check finds holes and accepts true coverings.
TEST(NBufferReferenceTest, FirstUncoveredFindsHoles) {
  const Texel two[] = {{0, 0}, {4, 0}};
  EXPECT_FALSE(ref::first_uncovered({0, 0, 8, 4}, two, 4)) << "two squares side by side tile 8x4";
  const auto hole = ref::first_uncovered({0, 0, 9, 4}, two, 4);
  ASSERT_TRUE(hole) << "column 8 is outside both squares";
  EXPECT_EQ(hole->first, 8);
  const Texel four[] = {{0, 0}, {3, 0}, {0, 3}, {3, 3}};
  EXPECT_FALSE(ref::first_uncovered({0, 0, 7, 7}, four, 4)) << "four overlapping squares cover 7x7";
  const Texel three[] = {{0, 0}, {3, 0}, {0, 3}};
  const auto corner = ref::first_uncovered({0, 0, 7, 7}, three, 4);
  ASSERT_TRUE(corner) << "the top-right corner is missing";
  EXPECT_EQ(*corner, (std::pair{4, 4}));
}

// Level count and storage follow ceil(log2(max(W, H))), at least 1, for any size.
TEST(NBufferTest, LevelCountAndStorage) {
  struct Row { int w, h, levels; const char* why; };
  const Row rows[] = {
      {1, 1, 1, "a 1x1 image keeps level 0"},       {2, 1, 1, "2 pixels: level 0's pairs suffice"},
      {3, 1, 2, "3 pixels need a 2-wide level"},     {1, 7, 3, "column: height decides"},
      {640, 480, 10, "Table 1 640x480"},             {1024, 1024, 10, "Table 1 1024^2"},
      {1025, 3, 11, "one pixel past a power of two"}, {17, 31, 5, "odd sizes round up"},
  };
  for (const Row& row : rows) {
    const NBuffer nb(row.w, row.h, {.format = StorageFormat::U16});
    EXPECT_EQ(nb.level_count(), row.levels) << row.w << "x" << row.h << ": " << row.why;
    EXPECT_EQ(nb.full_level_count(), row.levels) << row.why;
    EXPECT_EQ(nb.top_level(), row.levels - 1) << row.why;
    EXPECT_EQ(nb.storage_bytes(), static_cast<long long>(row.levels) * row.w * row.h * 2) << "U16 levels take 2 bytes a texel";
  }
}

// Sizes below 1x1 are the user's error.
TEST(NBufferTest, RejectsEmptySizes) {
  EXPECT_THROW(NBuffer(0, 5), InputError);
  EXPECT_THROW(NBuffer(5, 0), InputError);
  EXPECT_THROW(NBuffer(-1, -1), InputError);
  EXPECT_THROW(NBuffer(DepthImage(0, 0, 0.0f)), InputError);
}

// A new N-buffer is a cleared depth buffer: every level and every query answers the far limit.
TEST(NBufferTest, ClearedBufferAnswersFarLimit) {
  for (const FarOp op : kOps) {
    const NBuffer nb(37, 21, {.op = op});
    for (int i = 0; i < nb.level_count(); ++i)
      for (const float t : nb.level(i)) ASSERT_EQ(t, far_limit(op)) << name_of(op) << " level " << i;
    const QueryResult q = nb.query({3, 4, 20, 9});
    EXPECT_EQ(q.value, far_limit(op)) << name_of(op) << ": cleared depth is the far plane";
    EXPECT_TRUE(q.complete);
  }
}

// Every level of a built N-buffer equals the definition (farthest of the clipped 2^i square).
TEST(NBufferTest, LevelsMatchDefinition) {
  const std::pair<int, int> sizes[] = {{1, 1}, {1, 7}, {7, 1}, {5, 3}, {2, 2}, {16, 16}, {17, 31}, {33, 64}, {70, 70}};
  for (const FarOp op : kOps)
    for (const auto& [w, h] : sizes) {
      ref::Failures f;
      const DepthImage images[] = {ref::uniform(w, h, 11), ref::three_values(w, h, 12), ref::ramp(w, h, -1, 1)};
      for (const DepthImage& img : images) {
        const NBuffer nb(img, {.op = op});
        ASSERT_EQ(nb.level_count(), ref::log2_ceil(std::max({w, h, 2})));
        expect_levels_match(nb, img, op, name_of(op) + " " + std::to_string(w) + "x" + std::to_string(h), f);
        const DepthImage l0 = nb.level_image(0);
        EXPECT_EQ(l0.texels, img.texels) << "level 0 is the depth buffer (F32 is exact)";
      }
      EXPECT_EQ(f.count(), 0) << f.summary();
    }
}

// Every level of larger builds (several bands of rows, steps past 16) equals the definition;
// each texel's square is scanned row by row with the reference row tables.
TEST(NBufferTest, LevelsMatchDefinitionLarge) {
  const std::pair<int, int> sizes[] = {{130, 200}, {257, 65}, {1, 1000}, {641, 479}};
  for (const FarOp op : kOps)
    for (const auto& [w, h] : sizes) {
      const DepthImage img = ref::uniform(w, h, 13);
      const NBuffer nb(img, {.op = op});
      const ref::RowTable table(img, op);
      ref::Failures f;
      for (int i = 0; i < nb.level_count(); ++i)
        for (int y = 0; y < h; ++y)
          for (int x = 0; x < w; ++x)
            if (nb.texel(i, x, y) != table.farthest({x, y, 1 << i, 1 << i}))
              f.add("level " + std::to_string(i) + " texel " + std::to_string(x) + "," + std::to_string(y) +
                    " is not the farthest of its square");
      EXPECT_EQ(f.count(), 0) << name_of(op) << " " << w << "x" << h << ": " << f.summary();
    }
}

// Every rectangle of small and odd-sized adversarial images obeys every query rule, both ops.
TEST(NBufferTest, EveryRectSmallAdversarial) {
  const std::pair<int, int> sizes[] = {{1, 1}, {1, 7}, {7, 1}, {2, 2}, {3, 3}, {5, 3}, {4, 9}, {8, 8}, {16, 16}, {17, 31}};
  for (const FarOp op : kOps)
    for (const auto& [w, h] : sizes) {
      ref::Failures f;
      for (const ref::NamedImage& img : ref::adversarial_images(w, h, op, 21))
        check_every_rect(img.image, op, std::to_string(w) + "x" + std::to_string(h) + " " + img.name, f);
      EXPECT_EQ(f.count(), 0) << name_of(op) << " " << w << "x" << h << ": " << f.summary();
    }
}

// Every rectangle of 32x33 and 19x64 images with one far pixel next to level and image borders.
void check_far_pixels_at_borders(FarOp op) {
  const std::pair<int, int> sizes[] = {{32, 33}, {19, 64}};
  for (const auto& [w, h] : sizes) {
    ref::Failures f;
    int images = 0;
    for (const ref::NamedImage& img : ref::adversarial_images(w, h, op, 31, 20))
      if (img.name.starts_with("far pixel")) {
        ++images;
        check_every_rect(img.image, op, std::to_string(w) + "x" + std::to_string(h) + " " + img.name, f);
      }
    EXPECT_EQ(images, 20) << "20 far-pixel positions per size";
    EXPECT_EQ(f.count(), 0) << name_of(op) << " " << w << "x" << h << ": " << f.summary();
  }
}

// Every rectangle around one far pixel at level and image borders (positions 2^k - 1, 2^k, W - 1).
TEST(NBufferTest, EveryRectFarPixelAtBordersMax) { check_far_pixels_at_borders(FarOp::Max); }

// The same with reversed Z: the far pixel is at depth 0 and the farthest is the minimum.
TEST(NBufferTest, EveryRectFarPixelAtBordersMin) { check_far_pixels_at_borders(FarOp::Min); }

// Every rectangle of a random 33x64 image (distinct depths: any extra or missing pixel shows).
TEST(NBufferTest, EveryRect33x64) {
  for (const FarOp op : kOps) {
    ref::Failures f;
    check_every_rect(ref::uniform(33, 64, 41), op, "uniform 33x64", f);
    EXPECT_EQ(f.count(), 0) << name_of(op) << ": " << f.summary();
  }
}

// Every rectangle of a random 70x70 image (three levels of non-power-of-two overhang), Max.
TEST(NBufferTest, EveryRect70x70Max) {
  ref::Failures f;
  check_every_rect(ref::uniform(70, 70, 51), FarOp::Max, "uniform 70x70", f);
  EXPECT_EQ(f.count(), 0) << f.summary();
}

// Every rectangle of a reversed-Z random 69x70 image, Min.
TEST(NBufferTest, EveryRect69x70ReversedZ) {
  ref::Failures f;
  check_every_rect(ref::mirror(ref::uniform(69, 70, 52)), FarOp::Min, "reversed-Z uniform 69x70", f);
  EXPECT_EQ(f.count(), 0) << f.summary();
}

// Rectangles sticking out of the image on any side answer as their clipped part does.
TEST(NBufferTest, PartlyOutsideRectsAreClipped) {
  const std::pair<int, int> sizes[] = {{13, 9}, {1, 5}, {8, 8}};
  for (const FarOp op : kOps)
    for (const auto& [w, h] : sizes) {
      const DepthImage img = ref::uniform(w, h, 61);
      const NBuffer nb(img, {.op = op});
      const std::vector<DepthImage> levels = ref::nbuffer_levels(img, op, nb.level_count());
      auto square_far = [&](int l, int x, int y) { return levels[static_cast<std::size_t>(l)].at(x, y); };
      ref::Failures f;
      for (int y = -h - 1; y <= h; ++y)
        for (int x = -w - 1; x <= w; ++x)
          for (int rh = 1; rh <= 2 * h + 3; ++rh)
            for (int rw = 1; rw <= 2 * w + 3; ++rw) {
              const Rect r{x, y, rw, rh};
              const Rect c = clip(r, w, h);
              if (c.empty()) continue;
              for (const CoveringSpec kind : kKinds) {
                const QueryResult q = nb.query(r, kind), qc = nb.query(c, kind);
                if (q.value != qc.value || q.level != qc.level || q.texel_count != qc.texel_count || q.texels != qc.texels)
                  f.add("clip: " + ref::str(r) + " answers differently from its clipped part " + ref::str(c));
                const std::string e = ref::check_nbuffer_answer(w, h, op, nb.level_count(), c, kind, q,
                                                                ref::farthest(img, op, c), square_far);
                if (!e.empty()) f.add(ref::str(r) + " clipped to " + e);
              }
            }
      EXPECT_EQ(f.count(), 0) << name_of(op) << " " << w << "x" << h << ": " << f.summary();
    }
}

// Empty rectangles and rectangles entirely outside the image are the user's error.
TEST(NBufferTest, EmptyOrOutsideRectsThrow) {
  const NBuffer nb(ref::uniform(16, 8, 71));
  struct Row { Rect r; const char* why; };
  const Row rows[] = {
      {{0, 0, 0, 4}, "zero width"},        {{0, 0, 4, 0}, "zero height"},
      {{3, 3, -2, 4}, "negative width"},   {{16, 0, 4, 4}, "starts at the right edge"},
      {{0, 8, 4, 4}, "starts at the top edge"}, {{-4, 0, 4, 4}, "ends at the left edge"},
      {{0, -4, 4, 4}, "ends at the bottom edge"}, {{100, 100, 1, 1}, "far outside"},
  };
  for (const Row& row : rows)
    for (const CoveringSpec kind : kKinds) EXPECT_THROW(nb.query(row.r, kind), InputError) << row.why;
  EXPECT_NO_THROW(nb.query({-4, -4, 5, 5})) << "one pixel inside is enough";
}

// 20k random rectangles on 641x479 (non-power-of-two, Table 1's 640x480 plus one).
TEST(NBufferTest, RandomRects641x479) {
  for (const FarOp op : kOps) {
    ref::Failures f;
    check_random_rects(op == FarOp::Max ? ref::uniform(641, 479, 81) : ref::mirror(ref::uniform(641, 479, 81)), op,
                       20000, 82, f);
    EXPECT_EQ(f.count(), 0) << name_of(op) << ": " << f.summary();
  }
}

// 20k random rectangles on a 1x1000 column (one-pixel-wide rectangles, tall levels).
TEST(NBufferTest, RandomRects1x1000) {
  for (const FarOp op : kOps) {
    ref::Failures f;
    check_random_rects(ref::uniform(1, 1000, 91), op, 20000, 92, f);
    check_random_rects(ref::uniform(1000, 1, 93), op, 20000, 94, f);
    EXPECT_EQ(f.count(), 0) << name_of(op) << ": " << f.summary();
  }
}

// 20k random rectangles on 1024x1024 (power of two: the top level's four squares tile the image).
TEST(NBufferTest, RandomRects1024x1024) {
  for (const FarOp op : kOps) {
    ref::Failures f;
    check_random_rects(ref::three_values(1024, 1024, 101), op, 10000, 102, f);
    check_random_rects(ref::uniform(1024, 1024, 103), op, 10000, 104, f);
    EXPECT_EQ(f.count(), 0) << name_of(op) << ": " << f.summary();
  }
}

// Hand-checked answers for the hard cases; each row says why it is there.
TEST(NBufferTest, EdgeCases) {
  // Background b, optional far pixel at (fx, fy) with depth fv.
  struct Row {
    const char* why;
    int w, h;
    FarOp op;
    float background;
    int fx, fy;  // -1: none
    float fv;
    Rect r;
    CoveringSpec kind;
    float value;
    int level, count;
  };
  constexpr auto Max = FarOp::Max;
  constexpr auto Min = FarOp::Min;
  // Four: the corner covering with bottom alignment (a trace's when its header names none); One:
  // one square.
  constexpr CoveringSpec Four{CoveringKind::Corners, CoveringAlign::Bottom};
  constexpr CoveringSpec One{CoveringKind::One, CoveringAlign::Bottom};
  constexpr CoveringSpec Paper{CoveringKind::Paper, CoveringAlign::Top};
  const Row rows[] = {
      {"equal depth: every pixel 0.5, the answer is exactly 0.5", 16, 16, Max, 0.5f, -1, -1, 0, {3, 3, 9, 5}, Four, 0.5f, 3, 2},
      {"far plane: a buffer at 1.0 answers 1.0", 16, 16, Max, 1.0f, -1, -1, 0, {0, 0, 16, 16}, Four, 1.0f, 3, 4},
      {"far plane pixel inside the rectangle wins", 16, 16, Max, 0.4f, 7, 9, 1.0f, {5, 5, 6, 6}, Four, 1.0f, 2, 4},
      {"reversed Z: the farthest is the minimum", 16, 16, Min, 0.7f, 5, 5, 0.1f, {2, 2, 8, 8}, Four, 0.1f, 3, 1},
      {"reversed Z: a near pixel outside the rectangle is ignored", 16, 16, Min, 0.7f, 10, 2, 0.1f, {2, 2, 8, 8}, Four, 0.7f, 3, 1},
      {"reversed Z far plane: cleared to 0 answers 0", 9, 9, Min, 0.0f, -1, -1, 0, {1, 1, 7, 3}, Four, 0.0f, 2, 2},
      {"level border: far pixel at x = 2^4 - 1 is the last column of [0, 16)", 32, 32, Max, 0.25f, 15, 0, 0.9f, {0, 0, 16, 16}, Four, 0.9f, 4, 1},
      {"level border: far pixel at x = 2^4 is just past [0, 16), exact square", 32, 32, Max, 0.25f, 16, 0, 0.9f, {0, 0, 16, 16}, Four, 0.25f, 4, 1},
      {"level border: far pixel at x = 2^3 just right of a stacked pair", 32, 32, Max, 0.25f, 8, 4, 0.9f, {0, 0, 8, 12}, Four, 0.25f, 3, 2},
      {"overhang reads extra pixels: square [0,16)^2 for a 16x3 rectangle", 32, 32, Max, 0.25f, 3, 10, 0.9f, {0, 0, 16, 3}, Four, 0.9f, 4, 1},
      {"one square overhangs: 5x5 reads [0,8)^2", 32, 32, Max, 0.25f, 7, 7, 0.9f, {0, 0, 5, 5}, One, 0.9f, 3, 1},
      {"four squares of 5x5 stay inside it", 32, 32, Max, 0.25f, 7, 7, 0.9f, {0, 0, 5, 5}, Four, 0.25f, 2, 4},
      {"image border: square past the right edge reads neutral pixels", 17, 17, Max, 0.25f, 16, 16, 0.9f, {12, 12, 5, 5}, One, 0.9f, 3, 1},
      {"image border: square past the top edge, far pixel at the corner", 17, 17, Max, 0.25f, 16, 16, 0.9f, {16, 16, 1, 1}, Four, 0.9f, 0, 1},
      {"non-power-of-two: whole 5x3 image is two squares of level 2", 5, 3, Max, 0.25f, 4, 2, 0.9f, {0, 0, 5, 3}, Four, 0.9f, 2, 2},
      {"non-power-of-two: whole 641x479 with one square falls back to four", 641, 479, Max, 0.25f, 640, 478, 0.9f, {0, 0, 641, 479}, One, 0.9f, 9, 2},
      {"non-power-of-two: 1x1000 column, level 9 at the top", 1, 1000, Max, 0.25f, 0, 999, 0.9f, {0, 0, 1, 1000}, Four, 0.9f, 9, 2},
      {"power of two: whole 1024^2 image is four squares of level 9", 1024, 1024, Max, 0.25f, 1023, 1023, 0.9f, {0, 0, 1024, 1024}, Four, 0.9f, 9, 4},
      {"1-pixel rectangle reads level 0 once", 16, 16, Max, 0.25f, 6, 6, 0.9f, {6, 6, 1, 1}, Four, 0.9f, 0, 1},
      {"1-pixel rectangle next to the far pixel does not see it", 16, 16, Max, 0.25f, 6, 6, 0.9f, {7, 6, 1, 1}, One, 0.25f, 0, 1},
      {"1x1 image", 1, 1, Max, 0.3f, -1, -1, 0, {0, 0, 1, 1}, One, 0.3f, 0, 1},
      {"rectangle larger than the image is clipped to it", 6, 6, Max, 0.25f, 5, 0, 0.9f, {-10, -10, 40, 40}, Four, 0.9f, 2, 4},
      {"1-pixel-high row: squares overhang upward only, x = 31 past its end is not read", 40, 3, Max, 0.25f, 31, 0, 0.9f, {0, 0, 31, 1}, Four, 0.25f, 4, 2},
      {"1-pixel-high row: squares overhang upward into a far pixel", 40, 3, Max, 0.25f, 20, 2, 0.9f, {0, 0, 31, 1}, Four, 0.9f, 4, 2},
      {"paper: a 16x3 row is four level-2 squares, moved up to y = 0, not the pixel at y = 10", 32, 32, Max, 0.25f, 3, 10, 0.9f,
       {0, 0, 16, 3}, Paper, 0.25f, 2, 4},
      {"paper: a row reads down from its top edge, not the pixel above it", 40, 16, Max, 0.25f, 20, 13, 0.9f, {0, 12, 31, 1}, Paper,
       0.25f, 3, 4},
      {"paper: a row reads down from its top edge into a far pixel below it", 40, 16, Max, 0.25f, 20, 6, 0.9f, {0, 12, 31, 1}, Paper,
       0.9f, 3, 4},
      {"paper: a power-of-two square is four quadrants of the level below", 32, 32, Max, 0.25f, 15, 0, 0.9f, {0, 0, 16, 16}, Paper,
       0.9f, 3, 4},
      {"paper: the whole 641x479 image spans two quadrants side by side: two squares of level 9", 641, 479, Max, 0.25f, 640,
       478, 0.9f, {0, 0, 641, 479}, Paper, 0.9f, 9, 2},
  };
  for (const Row& row : rows) {
    DepthImage img(row.w, row.h, row.background);
    if (row.fx >= 0) img.at(row.fx, row.fy) = row.fv;
    const NBuffer nb(img, {.op = row.op});
    const QueryResult q = nb.query(row.r, row.kind);
    EXPECT_EQ(q.value, row.value) << row.why;
    EXPECT_EQ(q.level, row.level) << row.why;
    EXPECT_EQ(q.texel_count, row.count) << row.why;
    EXPECT_TRUE(q.complete) << row.why;
    const Rect c = clip(row.r, row.w, row.h);
    const std::string e = ref::check_nbuffer_answer(row.w, row.h, row.op, nb.level_count(), c, row.kind, q,
                                                    ref::farthest(img, row.op, c), [&](int l, int x, int y) {
                                                      return ref::level_texel(img, row.op, l, x, y);
                                                    });
    EXPECT_EQ(e, "") << row.why;
  }
}

}  // namespace
}  // namespace nbsim

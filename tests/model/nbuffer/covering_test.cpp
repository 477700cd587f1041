// CoveringTest: the coverings of model/nbuffer/covering.h: the paper's five cases (Fig. 3) with
// their levels and top alignment, the corner and one-square variants, against brute force on every
// box size and many positions of odd and power-of-two images.
#include "model/nbuffer/covering.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <utility>
#include <vector>

#include "model/nbuffer/nbuffer.h"

namespace nbsim {
namespace {

constexpr CoveringSpec kPaper{CoveringKind::Paper, CoveringAlign::Top};
constexpr CoveringSpec kPaperBottom{CoveringKind::Paper, CoveringAlign::Bottom};
constexpr CoveringSpec kCorners{CoveringKind::Corners, CoveringAlign::Bottom};
constexpr CoveringSpec kAll[] = {kPaper,
                                 kPaperBottom,
                                 kCorners,
                                 {CoveringKind::Corners, CoveringAlign::Top},
                                 {CoveringKind::One, CoveringAlign::Top},
                                 {CoveringKind::One, CoveringAlign::Bottom}};

// The number of levels follows ceil(log2(max(W, H))), at least 1 (Table 1's 8, 9, 10, 10).
TEST(CoveringTest, LevelCountMatchesTable1) {
  EXPECT_EQ(nbuffer_level_count(256, 256), 8);
  EXPECT_EQ(nbuffer_level_count(512, 512), 9);
  EXPECT_EQ(nbuffer_level_count(640, 480), 10);
  EXPECT_EQ(nbuffer_level_count(1024, 1024), 10);
  EXPECT_EQ(nbuffer_level_count(1, 1), 1) << "a 1x1 image still has level 0";
  EXPECT_EQ(nbuffer_level_count(2, 1), 1);
  EXPECT_EQ(nbuffer_level_count(3, 1), 2);
  EXPECT_EQ(nbuffer_level_count(1, 1000), 10);
}

TEST(CoveringTest, NamesRoundTrip) {
  for (const CoveringSpec& s : kAll) EXPECT_EQ(parse_covering_name(covering_name(s)), s) << covering_name(s);
  EXPECT_EQ(covering_name(kPaper), "paper/top");
  EXPECT_FALSE(parse_covering_name("four/top"));
  EXPECT_FALSE(parse_covering_name("paper"));
  EXPECT_FALSE(parse_covering_name("paper/left"));
}

// Each of the five cases of Fig. 3, by the rectangle that defines it, with the level (q = S / 2 or
// q / 4) and the squares the paper places (rows flush with the top edge).
TEST(CoveringTest, PaperFiveCases) {
  struct Row {
    const char* why;
    Rect r;
    CoveringCase kase;
    int level;
    std::vector<std::pair<int, int>> squares;
  };
  const Row rows[] = {
      {"all four quadrants: S = 16, q = 8, corners", {3, 5, 12, 13}, CoveringCase::FourQuadrants, 3, {{3, 5}, {7, 5}, {3, 10}, {7, 10}}},
      {"a power-of-two square: four quadrants of half its side", {3, 5, 16, 16}, CoveringCase::FourQuadrants, 3,
       {{3, 5}, {11, 5}, {3, 13}, {11, 13}}},
      {"side by side: w > q >= h > q/2, flush with the top (y + h - q)", {3, 5, 12, 6}, CoveringCase::TwoSideBySide, 3,
       {{3, 3}, {7, 3}}},
      {"h == q: side by side, exact", {3, 5, 12, 8}, CoveringCase::TwoSideBySide, 3, {{3, 5}, {7, 5}}},
      {"stacked: turned, at the left edge", {3, 5, 6, 12}, CoveringCase::TwoStacked, 3, {{3, 5}, {3, 9}}},
      {"in a row: h <= q/2, squares of q/2 every q/2, the last flush with the right", {10, 200, 100, 10}, CoveringCase::FourInARow, 5,
       {{10, 178}, {42, 178}, {74, 178}, {78, 178}}},
      {"in a row, three squares are enough (w <= 3 q/2)", {0, 40, 20, 3}, CoveringCase::FourInARow, 3, {{0, 35}, {8, 35}, {12, 35}}},
      {"in a column", {7, 1, 3, 30}, CoveringCase::FourInAColumn, 3, {{7, 1}, {7, 9}, {7, 17}, {7, 23}}},
      {"1x1: level 0", {4, 4, 1, 1}, CoveringCase::FourQuadrants, 0, {{4, 4}}},
      {"2x1: two texels of level 0", {4, 4, 2, 1}, CoveringCase::TwoSideBySide, 0, {{4, 4}, {5, 4}}},
      {"3x1: q = 2, a row of three level-0 texels", {4, 4, 3, 1}, CoveringCase::FourInARow, 0, {{4, 4}, {5, 4}, {6, 4}}},
      {"a row at the bottom edge: moved up to y = 0", {5, 0, 40, 3}, CoveringCase::FourInARow, 4, {{5, 0}, {21, 0}, {29, 0}}},
      {"side by side at the bottom edge: moved up to y = 0", {0, 2, 12, 5}, CoveringCase::TwoSideBySide, 3, {{0, 0}, {4, 0}}},
  };
  for (const Row& row : rows) {
    const Covering c = cover(row.r, kPaper, 30);
    EXPECT_EQ(c.kase, row.kase) << row.why;
    EXPECT_EQ(covering_case(row.r.w, row.r.h), row.kase) << row.why;
    EXPECT_EQ(c.level, row.level) << row.why;
    EXPECT_EQ(level_needed(row.r, CoveringKind::Paper), row.level) << row.why;
    std::vector<std::pair<int, int>> got;
    for (int i = 0; i < c.count; ++i) got.emplace_back(c.squares[static_cast<std::size_t>(i)].x, c.squares[static_cast<std::size_t>(i)].y);
    EXPECT_EQ(got, row.squares) << row.why;
  }
  // The bottom alignment puts a row at the rectangle's y; the corner covering reads level
  // floor(log2 max) = 6 there, two 64-pixel squares from y = 200 up.
  EXPECT_EQ(cover({10, 200, 100, 10}, kPaperBottom, 30).squares[0].y, 200);
  const Covering old = cover({10, 200, 100, 10}, kCorners, 30);
  EXPECT_EQ(old.level, 6);
  ASSERT_EQ(old.count, 2);
  EXPECT_EQ(old.squares[0].x, 10);
  EXPECT_EQ(old.squares[1].x, 46);
  EXPECT_EQ(old.squares[0].y, 200);
}

// The pixels a covering's squares cover, as a mask over their bounding box.
struct SquarePixels {
  int x0 = 0, y0 = 0, w = 0, h = 0;
  std::vector<std::uint8_t> mask;
  explicit SquarePixels(const Covering& c) {
    int x1 = c.squares[0].x, y1 = c.squares[0].y;
    x0 = x1, y0 = y1;
    for (int i = 1; i < c.count; ++i) {
      x0 = std::min(x0, c.squares[static_cast<std::size_t>(i)].x), x1 = std::max(x1, c.squares[static_cast<std::size_t>(i)].x);
      y0 = std::min(y0, c.squares[static_cast<std::size_t>(i)].y), y1 = std::max(y1, c.squares[static_cast<std::size_t>(i)].y);
    }
    w = x1 - x0 + c.side(), h = y1 - y0 + c.side();
    mask.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0);
    for (int i = 0; i < c.count; ++i)
      for (int y = 0; y < c.side(); ++y)
        for (int x = 0; x < c.side(); ++x)
          mask[static_cast<std::size_t>(c.squares[static_cast<std::size_t>(i)].y - y0 + y) * static_cast<std::size_t>(w) +
               static_cast<std::size_t>(c.squares[static_cast<std::size_t>(i)].x - x0 + x)] = 1;
  }
  bool has(int x, int y) const {
    return x >= x0 && y >= y0 && x < x0 + w && y < y0 + h &&
           mask[static_cast<std::size_t>(y - y0) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x - x0)];
  }
  long long count() const { return std::count(mask.begin(), mask.end(), std::uint8_t{1}); }
};

// The paper's level for a w x h box: q (or q/2 in a row or column), as Fig. 3 places it.
int paper_level(int w, int h) {
  int s = 1;
  while (s < std::max(w, h)) s *= 2;
  if (s == 1) return 0;
  const int q = s / 2;
  const bool row = w > q && 2 * h <= q, column = w <= q && 2 * w <= q;
  int side = row || column ? q / 2 : q, level = 0;
  while ((1 << level) < side) ++level;
  return level;
}

// Every box size up to 40x40 at positions all over images of odd and power-of-two sizes (and
// clipped, as a query clips): the squares hold the box, are at most four of one level and start
// inside the image; the paper's covering reads the paper's level with its rows flush with the
// box's top (or at y = 0 where that would start below the image); the union's area is the
// brute-force count.
TEST(CoveringTest, BruteForceEveryBoxSize) {
  std::mt19937 rng(7);
  for (const auto& [iw, ih] : {std::pair{37, 23}, std::pair{32, 64}, std::pair{1, 40}, std::pair{41, 1}, std::pair{64, 64}}) {
    const int top = nbuffer_level_count(iw, ih) - 1;
    for (int h = 1; h <= std::min(ih, 40); ++h) {
      for (int w = 1; w <= std::min(iw, 40); ++w) {
        std::vector<std::pair<int, int>> at = {{0, 0}, {iw - w, ih - h}, {0, ih - h}, {iw - w, 0}};
        for (int k = 0; k < 3; ++k)
          at.emplace_back(std::uniform_int_distribution<int>(0, iw - w)(rng), std::uniform_int_distribution<int>(0, ih - h)(rng));
        for (const auto& [x, y] : at) {
          const Rect r{x, y, w, h};
          for (const CoveringSpec& spec : kAll) {
            const Covering c = cover(r, spec, top);
            SCOPED_TRACE(testing::Message() << covering_name(spec) << " box " << x << "," << y << " " << w << "x" << h << " in "
                                            << iw << "x" << ih);
            ASSERT_GE(c.count, 1);
            ASSERT_LE(c.count, 4);
            ASSERT_LE(c.level, top);
            const SquarePixels px(c);
            for (int yy = y; yy < y + h; ++yy)
              for (int xx = x; xx < x + w; ++xx) ASSERT_TRUE(px.has(xx, yy)) << "pixel " << xx << "," << yy << " not covered";
            for (int i = 0; i < c.count; ++i) {
              const Square s = c.squares[static_cast<std::size_t>(i)];
              ASSERT_TRUE(s.x >= 0 && s.y >= 0 && s.x < iw && s.y < ih) << "a square starts outside the image";
            }
            ASSERT_EQ(covered_area(c), px.count());
            ASSERT_EQ(c.kase, covering_case(w, h));
            if (spec.kind != CoveringKind::Paper) continue;
            ASSERT_EQ(c.level, paper_level(w, h));
            if (c.side() > h) {  // a row overhangs vertically: flush with the top, or the bottom
              const int want = spec.align == CoveringAlign::Top ? std::max(0, y + h - c.side()) : y;
              for (int i = 0; i < c.count; ++i) ASSERT_EQ(c.squares[static_cast<std::size_t>(i)].y, want);
            }
          }
        }
      }
    }
  }
}

// The query reads exactly the covering's texels and answers the farthest depth over the squares'
// pixels inside the image (pixels outside are neutral), which is at least the box's farthest.
TEST(CoveringTest, QueryIsTheFarthestOverTheSquares) {
  std::mt19937 rng(11);
  for (const auto& [iw, ih] : {std::pair{37, 23}, std::pair{16, 16}, std::pair{1, 9}}) {
    DepthImage d(iw, ih, 0.0f);
    for (float& v : d.texels) v = std::uniform_real_distribution<float>(0.0f, 1.0f)(rng);
    const NBuffer nb(d);
    for (int k = 0; k < 1500; ++k) {
      const int w = std::uniform_int_distribution<int>(1, iw)(rng), h = std::uniform_int_distribution<int>(1, ih)(rng);
      const Rect r{std::uniform_int_distribution<int>(0, iw - w)(rng), std::uniform_int_distribution<int>(0, ih - h)(rng), w, h};
      for (const CoveringSpec& spec : kAll) {
        const QueryResult q = nb.query(r, spec);
        const Covering c = cover(r, spec, nb.full_level_count() - 1);
        ASSERT_EQ(q.level, c.level);
        ASSERT_EQ(q.texel_count, c.count);
        float over_squares = 0.0f, over_box = 0.0f;
        const SquarePixels px(c);
        for (int y = px.y0; y < px.y0 + px.h; ++y)
          for (int x = px.x0; x < px.x0 + px.w; ++x)
            if (x < iw && y < ih && px.has(x, y)) over_squares = std::max(over_squares, d.at(x, y));
        for (int y = r.y; y < r.y1(); ++y)
          for (int x = r.x; x < r.x1(); ++x) over_box = std::max(over_box, d.at(x, y));
        ASSERT_EQ(q.value, over_squares) << covering_name(spec);
        ASSERT_GE(q.value, over_box);
      }
    }
  }
}

// Boxes that clip: larger than the image, past each edge; width or height 1; a 1-pixel-wide image.
TEST(CoveringTest, HardCases) {
  DepthImage d(33, 17, 0.25f);
  d.at(32, 16) = 0.75f;  // the top-right corner
  d.at(0, 0) = 0.5f;
  const NBuffer nb(d);
  struct Row {
    const char* why;
    Rect r;
    float value;
    bool one_square_too = true;  // false: the one-square covering reaches a far pixel the others do not
  };
  const Row rows[] = {
      {"larger than the image: everything", {-5, -5, 100, 100}, 0.75f},
      {"past the right and top edges", {30, 10, 50, 50}, 0.75f},
      {"past the left and bottom edges", {-10, -10, 12, 12}, 0.5f},
      {"a row touching the bottom edge: the square moves up, still holds (0, 0)", {0, 0, 20, 1}, 0.5f},
      {"a 1-pixel column at the right edge", {32, 0, 1, 17}, 0.75f},
      {"a row of the top edge", {0, 16, 33, 1}, 0.75f},
      {"the top-right pixel", {32, 16, 1, 1}, 0.75f},
      {"one pixel more than a power of two wide, along the top edge", {0, 16, 17, 1}, 0.25f, false},
  };
  for (const Row& row : rows) {
    for (const CoveringSpec& spec : kAll) {
      if (row.one_square_too || spec.kind != CoveringKind::One) {
        EXPECT_EQ(nb.query(row.r, spec).value, row.value) << row.why << " " << covering_name(spec);
      }
    }
  }
  // A row one pixel above the bottom edge: under top alignment its squares would start below the
  // image and start at y = 0 instead, so they read the far pixel (0, 0) under the row; bottom
  // alignment reads rows 1..8 only.
  EXPECT_EQ(nb.query({0, 1, 17, 1}, kPaper).value, 0.5f) << "paper: squares of 8 from y = 0 hold rows 0..7";
  EXPECT_EQ(nb.query({1, 1, 17, 1}, kPaper).value, 0.25f) << "(0, 0) is left of x = 1";
  EXPECT_EQ(nb.query({0, 1, 17, 1}, kPaperBottom).value, 0.25f);
  DepthImage thin(1, 40, 0.25f);
  thin.at(0, 39) = 1.0f;
  const NBuffer t(thin);
  for (const CoveringSpec& spec : kAll) {
    EXPECT_EQ(t.query({0, 0, 1, 39}, spec).value, 0.25f) << covering_name(spec);
    EXPECT_EQ(t.query({0, 30, 1, 10}, spec).value, 1.0f) << covering_name(spec);
  }
}

// The Fig. 4 measure over every box from 1x1 to 256x256: the paper's covering adds 129.7 % of
// the box on average, the corner covering 284.3 %, one square 921.7 % (brute force above checks
// the areas; this pins the means `nbsim nbuffer coverage` prints).
TEST(CoveringTest, MeanExtraAreaOfFigure4) {
  for (const auto& [spec, mean] : {std::pair{kPaper, 129.7}, std::pair{kCorners, 284.3}, std::pair{CoveringSpec{CoveringKind::One}, 921.7}}) {
    double sum = 0.0;
    for (int h = 1; h <= 256; ++h)
      for (int w = 1; w <= 256; ++w) {
        const Rect r{0, 0, w, h};
        sum += static_cast<double>(covered_area(cover(r, spec, 30)) - r.area()) / static_cast<double>(r.area());
      }
    EXPECT_NEAR(100.0 * sum / (256.0 * 256.0), mean, 0.05) << covering_name(spec);
  }
}

// The top level clamps the corner covering's square size; four squares of the top level still
// cover the image. The paper's covering of the whole image reads the level below the top.
TEST(CoveringTest, ClampsToTopLevel) {
  const Covering c = cover({0, 0, 512, 512}, kCorners, 8);
  EXPECT_EQ(c.level, 8);
  EXPECT_EQ(c.count, 4);
  EXPECT_EQ(covered_area(c), 512 * 512) << "four 256-squares tile the 512 image exactly";
  const Covering p = cover({0, 0, 512, 512}, kPaper, 8);
  EXPECT_EQ(p.level, 8);
  EXPECT_EQ(covered_area(p), 512 * 512);
}

// One-square covering uses the smallest square that contains the rectangle; the sprite covering
// reads a power-of-two square with one lookup at its own level.
TEST(CoveringTest, OneSquareAndSprites) {
  Covering c = cover({10, 20, 5, 9}, {CoveringKind::One, CoveringAlign::Bottom}, 30);
  EXPECT_EQ(c.level, 4);
  EXPECT_EQ(c.count, 1);
  EXPECT_EQ(c.squares[0].y, 20);
  c = cover({10, 20, 5, 9}, {CoveringKind::One, CoveringAlign::Top}, 30);
  EXPECT_EQ(c.squares[0].y, 13) << "flush with the top: 20 + 9 - 16";
  EXPECT_EQ(covered_area(c), 256);
  constexpr CoveringSpec kSprite{CoveringKind::Paper, CoveringAlign::Top, true};
  c = cover({3, 4, 16, 16}, kSprite, 30);
  EXPECT_EQ(c.level, 4);
  EXPECT_EQ(c.count, 1);
  c = cover({3, 4, 17, 17}, kSprite, 30);
  EXPECT_EQ(c.level, 4);
  EXPECT_EQ(c.count, 4);
  c = cover({3, 4, 17, 16}, kSprite, 30);
  EXPECT_EQ(c.kase, CoveringCase::TwoSideBySide);
  EXPECT_EQ(cover({3, 4, 16, 16}, kPaper, 30).count, 4) << "without direct_squares: Fig. 3's four quadrants";
}

}  // namespace
}  // namespace nbsim

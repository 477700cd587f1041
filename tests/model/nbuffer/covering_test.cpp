// CoveringTest: the four-square and one-square coverings of model/nbuffer/covering.h.
#include "model/nbuffer/covering.h"

#include <gtest/gtest.h>

namespace nbsim {
namespace {

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

// Each of the five cases of Fig. 3 is reached by the rectangle that defines it.
TEST(CoveringTest, FiveCases) {
  struct Row { Rect r; CoveringCase kase; int count; const char* why; };
  const Row rows[] = {
      {{3, 5, 8, 8}, CoveringCase::Exact, 1, "a square is one texel"},
      {{3, 5, 12, 8}, CoveringCase::SideBySide, 2, "wider than tall by less than 2x"},
      {{3, 5, 8, 12}, CoveringCase::Stacked, 2, "taller than wide by less than 2x"},
      {{3, 5, 12, 13}, CoveringCase::Four, 4, "both sides between S and 2S"},
      {{3, 5, 12, 3}, CoveringCase::Overhang, 2, "the short side is below S"},
      {{3, 5, 1, 1}, CoveringCase::Exact, 1, "a single pixel"},
  };
  for (const Row& row : rows) {
    const Covering c = cover_four(row.r, 30);
    EXPECT_EQ(c.kase, row.kase) << row.why;
    EXPECT_EQ(c.count, row.count) << row.why;
  }
}

// The top level clamps the square size; four squares of the top level still cover the image.
TEST(CoveringTest, ClampsToTopLevel) {
  const Covering c = cover_four({0, 0, 512, 512}, 8);
  EXPECT_EQ(c.level, 8);
  EXPECT_EQ(c.count, 4);
  EXPECT_EQ(covered_area(c), 512 * 512) << "four 256-squares tile the 512 image exactly";
}

// One-square covering uses the smallest square that contains the rectangle.
TEST(CoveringTest, OneSquareContainsRectangle) {
  const Covering c = cover_one({10, 20, 5, 9}, 30);
  EXPECT_EQ(c.level, 4);
  EXPECT_EQ(c.count, 1);
  EXPECT_EQ(covered_area(c), 256);
}

}  // namespace
}  // namespace nbsim

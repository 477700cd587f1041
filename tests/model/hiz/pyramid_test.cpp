// HiZTest: the Hi-Z pyramid baseline of model/hiz/pyramid.h against brute-force footprints.
#include "model/hiz/pyramid.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "model/common/error.h"
#include "tests/common/reference.h"

namespace nbsim {
namespace {

constexpr FarOp kOps[] = {FarOp::Max, FarOp::Min};

// The level-0 pixels of texel (x, y) of level k (before clipping to the image).
Rect footprint(int k, int x, int y) { return {x << k, y << k, 1 << k, 1 << k}; }

// Checks the answer q of a pyramid over a width x height image with `levels` levels to the
// clipped rectangle c (true farthest `truth`); foot_far(k, x, y) is the brute-force farthest of a
// texel's footprint clipped to the image. "" when every rule holds.
template <class FootFar>
std::string check_hiz_answer(const HiZPyramid& hiz, const Rect& c, const QueryResult& q, float truth, FootFar&& foot_far) {
  std::string err;
  auto fail = [&](const std::string& rule) {
    err += err.empty() ? ref::str(c) + ": " : std::string("; ");
    err += rule;
  };
  const FarOp op = hiz.config().op;
  const int k = std::min(ref::log2_ceil(std::max(c.w, c.h)), hiz.level_count() - 1);
  if (q.level != k) fail("level: read level " + std::to_string(q.level) + ", expected " + std::to_string(k));
  if (q.level < 0 || q.level >= hiz.level_count()) return err;
  // Texels of level k touched by c, per axis.
  const int nx = ((c.x1() - 1) >> q.level) - (c.x >> q.level) + 1, ny = ((c.y1() - 1) >> q.level) - (c.y >> q.level) + 1;
  if (q.texel_count < 1 || q.texel_count > 4) {
    fail("at most four: read " + std::to_string(q.texel_count) + " texels");
    return err;
  }
  if (q.texel_count != nx * ny)
    fail("count: read " + std::to_string(q.texel_count) + " texels, the rectangle touches " + std::to_string(nx * ny));
  std::vector<Texel> feet;
  float over = neutral_depth(op);
  for (const Texel& t : q.read()) {
    if (t.x < 0 || t.y < 0 || t.x >= hiz.level_width(q.level) || t.y >= hiz.level_height(q.level)) {
      fail("texel " + std::to_string(t.x) + "," + std::to_string(t.y) + " outside level " + std::to_string(q.level));
      return err;
    }
    for (const Texel& u : feet)
      if (u.x == t.x << q.level && u.y == t.y << q.level) fail("duplicate: texel read twice");
    feet.push_back({t.x << q.level, t.y << q.level});
    over = farther(op, over, foot_far(q.level, t.x, t.y));
  }
  if (const auto hole = ref::first_uncovered(c, feet, 1 << q.level))
    fail("cover: no texel read covers pixel " + std::to_string(hole->first) + "," + std::to_string(hole->second));
  if (!at_least_as_far(op, q.value, truth))
    fail("conservative: answered " + std::to_string(q.value) + ", nearer than the true farthest " + std::to_string(truth));
  if (q.value != over) fail("union: answered " + std::to_string(q.value) + ", the texels read hold " + std::to_string(over));
  return err;
}

// Level k has ceil(W / 2^k) x ceil(H / 2^k) texels, down to a 1x1 top.
TEST(HiZTest, LevelSizes) {
  const std::pair<int, int> sizes[] = {{1, 1}, {1, 7}, {7, 1}, {5, 3}, {16, 16}, {17, 31}, {641, 479}, {1, 1000}, {1024, 1024}};
  for (const auto& [w, h] : sizes) {
    const HiZPyramid hiz(DepthImage(w, h, 0.5f), {.format = StorageFormat::U16});
    ASSERT_EQ(hiz.level_count(), ref::log2_ceil(std::max(w, h)) + 1) << w << "x" << h << ": halving until 1x1";
    long long texels = 0;
    for (int k = 0; k < hiz.level_count(); ++k) {
      EXPECT_EQ(hiz.level_width(k), (w + (1 << k) - 1) >> k) << w << "x" << h << " level " << k << ": ceil(W / 2^k)";
      EXPECT_EQ(hiz.level_height(k), (h + (1 << k) - 1) >> k) << w << "x" << h << " level " << k << ": ceil(H / 2^k)";
      texels += static_cast<long long>(hiz.level_width(k)) * hiz.level_height(k);
    }
    EXPECT_EQ(hiz.level_width(hiz.level_count() - 1), 1);
    EXPECT_EQ(hiz.level_height(hiz.level_count() - 1), 1);
    EXPECT_EQ(hiz.storage_bytes(), texels * 2) << "U16 texels take 2 bytes";
  }
}

// Every texel is the farthest of its footprint clipped to the image (outside pixels neutral).
TEST(HiZTest, TexelsMatchFootprint) {
  const std::pair<int, int> sizes[] = {{1, 1}, {1, 7}, {7, 1}, {5, 3}, {17, 31}, {33, 64}, {70, 70}};
  for (const FarOp op : kOps)
    for (const auto& [w, h] : sizes) {
      ref::Failures f;
      for (const DepthImage& img : {ref::uniform(w, h, 1), ref::three_values(w, h, 2), ref::ramp(w, h, 1, 1)}) {
        const HiZPyramid hiz(img, {.op = op});
        for (int k = 0; k < hiz.level_count(); ++k)
          for (int y = 0; y < hiz.level_height(k); ++y)
            for (int x = 0; x < hiz.level_width(k); ++x)
              if (hiz.texel(k, x, y) != ref::farthest(img, op, footprint(k, x, y)))
                f.add("level " + std::to_string(k) + " texel " + std::to_string(x) + "," + std::to_string(y) +
                      " is not the farthest of its footprint");
      }
      EXPECT_EQ(f.count(), 0) << to_string(op) << " " << w << "x" << h << ": " << f.summary();
    }
}

// Every rectangle of small odd-sized adversarial images: conservative, at most 2x2 texels.
TEST(HiZTest, EveryRectSmallOdd) {
  const std::pair<int, int> sizes[] = {{1, 1}, {1, 7}, {7, 1}, {5, 3}, {9, 9}, {17, 31}, {33, 29}};
  for (const FarOp op : kOps)
    for (const auto& [w, h] : sizes) {
      ref::Failures f;
      for (const ref::NamedImage& img : ref::adversarial_images(w, h, op, 3, 12)) {
        const HiZPyramid hiz(img.image, {.op = op});
        // Brute-force footprints, scanned once per texel.
        std::vector<DepthImage> feet;
        for (int k = 0; k < hiz.level_count(); ++k) {
          DepthImage l(hiz.level_width(k), hiz.level_height(k), 0.0f);
          for (int y = 0; y < l.height; ++y)
            for (int x = 0; x < l.width; ++x) l.at(x, y) = ref::farthest(img.image, op, footprint(k, x, y));
          feet.push_back(std::move(l));
        }
        auto foot_far = [&](int k, int x, int y) { return feet[static_cast<std::size_t>(k)].at(x, y); };
        ref::for_each_rect(img.image, op, [&](const Rect& r, float truth) {
          const std::string e = check_hiz_answer(hiz, r, hiz.query(r), truth, foot_far);
          if (!e.empty()) f.add(img.name + " " + e);
        });
      }
      EXPECT_EQ(f.count(), 0) << to_string(op) << " " << w << "x" << h << ": " << f.summary();
    }
}

// 20k random rectangles (some partly outside) on 641x479 and on a 1x1000 column.
TEST(HiZTest, RandomRects) {
  const std::pair<int, int> sizes[] = {{641, 479}, {1, 1000}, {1000, 1}};
  for (const FarOp op : kOps)
    for (const auto& [w, h] : sizes) {
      const DepthImage img = ref::uniform(w, h, 4);
      const HiZPyramid hiz(img, {.op = op});
      const ref::RowTable table(img, op);
      auto foot_far = [&](int k, int x, int y) { return table.farthest(footprint(k, x, y)); };
      std::mt19937 rng(5);
      ref::Failures f;
      for (int n = 0; n < 20000; ++n) {
        const Rect r = ref::random_rect(rng, w, h, true);
        const Rect c = clip(r, w, h);
        const QueryResult q = hiz.query(r);
        const std::string e = check_hiz_answer(hiz, c, q, table.farthest(c), foot_far);
        if (!e.empty()) f.add("query " + ref::str(r) + " clipped to " + e);
      }
      EXPECT_EQ(f.count(), 0) << to_string(op) << " " << w << "x" << h << ": " << f.summary();
    }
}

// A pyramid stored in U24/U16 answers the quantized F32 answer, never nearer.
TEST(HiZTest, QuantizedFormatsAreConservative) {
  for (const FarOp op : kOps) {
    const DepthImage img = ref::uniform(97, 61, 6);
    const HiZPyramid exact(img, {.op = op});
    for (const StorageFormat fmt : {StorageFormat::U24, StorageFormat::U16}) {
      const HiZPyramid hiz(img, {.op = op, .format = fmt});
      std::mt19937 rng(7);
      ref::Failures f;
      for (int n = 0; n < 20000; ++n) {
        const Rect r = ref::random_rect(rng, 97, 61, true);
        const float q = hiz.query(r).value, e = exact.query(r).value;
        if (!at_least_as_far(op, q, e)) f.add("conservative: " + ref::str(r) + " nearer than the F32 answer");
        if (q != quantize_toward_far(e, fmt, op)) f.add("commute: " + ref::str(r) + " is not the quantized F32 answer");
      }
      EXPECT_EQ(f.count(), 0) << to_string(fmt) << " " << to_string(op) << ": " << f.summary();
    }
  }
}

// Empty images, empty rectangles and rectangles outside the image are the user's error.
TEST(HiZTest, BadInputThrows) {
  EXPECT_THROW(HiZPyramid(DepthImage(0, 4, 0.0f)), InputError) << "zero width";
  EXPECT_THROW(HiZPyramid(DepthImage(4, 0, 0.0f)), InputError) << "zero height";
  const HiZPyramid hiz(ref::uniform(9, 5, 8));
  for (const Rect r : {Rect{0, 0, 0, 1}, Rect{0, 0, 1, -1}, Rect{9, 0, 2, 2}, Rect{0, 5, 2, 2}, Rect{-2, -2, 2, 2}})
    EXPECT_THROW(hiz.query(r), InputError) << ref::str(r);
  EXPECT_NO_THROW(hiz.query({-2, -2, 3, 3})) << "one pixel inside is enough";
}

// Hand-checked answers; each row says why it is there.
TEST(HiZTest, EdgeCases) {
  struct Row { const char* why; int w, h; FarOp op; int fx, fy; Rect r; float value; int level, count; };
  constexpr auto Max = FarOp::Max;
  const Row rows[] = {
      {"aligned 2x2 is one texel of level 1", 8, 8, Max, 1, 1, {0, 0, 2, 2}, 0.9f, 1, 1},
      {"2 pixels straddling a texel border read two texels", 8, 8, Max, 0, 0, {1, 0, 2, 1}, 0.9f, 1, 2},
      {"straddling: the extra pixel read is the far one", 8, 8, Max, 3, 1, {1, 0, 2, 1}, 0.9f, 1, 2},
      {"aligned 4x4 does not see the pixel just outside", 8, 8, Max, 4, 0, {0, 0, 4, 4}, 0.25f, 2, 1},
      {"odd edge: 5x3 image, last texel column is half outside", 5, 3, Max, 4, 2, {4, 2, 1, 1}, 0.9f, 0, 1},
      {"odd edge: whole 5x3 image at level 3, the 1x1 top", 5, 3, Max, 4, 2, {0, 0, 5, 3}, 0.9f, 3, 1},
      {"reversed Z: the near pixel is the farthest", 8, 8, FarOp::Min, 6, 6, {5, 5, 3, 3}, 0.0f, 2, 1},
      {"reversed Z: 3x3 across a texel corner reads 2x2 texels and their extra pixels", 8, 8, FarOp::Min, 6, 6, {3, 3, 3, 3}, 0.0f, 2, 4},
      {"reversed Z: a near pixel outside every texel read is not seen", 16, 16, FarOp::Min, 8, 8, {3, 3, 3, 3}, 0.75f, 2, 4},
      {"1x1 image", 1, 1, Max, 0, 0, {0, 0, 1, 1}, 0.9f, 0, 1},
  };
  for (const Row& row : rows) {
    const float bg = row.op == Max ? 0.25f : 0.75f;
    DepthImage img(row.w, row.h, bg);
    img.at(row.fx, row.fy) = row.op == Max ? 0.9f : 0.0f;
    const HiZPyramid hiz(img, {.op = row.op});
    const QueryResult q = hiz.query(row.r);
    EXPECT_EQ(q.value, row.value) << row.why;
    EXPECT_EQ(q.level, row.level) << row.why;
    EXPECT_EQ(q.texel_count, row.count) << row.why;
  }
}

}  // namespace
}  // namespace nbsim

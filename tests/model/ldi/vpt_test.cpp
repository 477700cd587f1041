// LdiVptTest: the volumetric parity test (model/ldi/vpt.h): the tie rule, the three readers (full
// LDI, cropped, compressed) against each other and a brute-force count on every texel in and around
// the crop and every depth of interest, their fetch counts against closed forms, and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <utility>
#include <vector>

#include "model/common/error.h"
#include "model/ldi/vpt.h"
#include "tests/model/ldi/random_ldi.h"

namespace {

using namespace nbsim::ldi;

constexpr float kInf = std::numeric_limits<float>::infinity();

// The brute-force answer: the layers of texel (x, y) with depth < z, counted over all stored layers.
int layers_in_front(const Ldi& l, int x, int y, float z) {
  int n = 0;
  for (int k = 0; k < l.layer_count(); ++k) n += l.depth(x, y, k) < z ? 1 : 0;
  return n;
}

// Ranges of the texel (pairs of layers, a lone last layer ending at +inf) whose end is < z.
int ranges_passed(const Ldi& l, int x, int y, float z) {
  int m = 0;
  const int n = l.count(x, y);
  for (int k = 0; k < n; k += 2) m += (k + 1 < n ? l.depth(x, y, k + 1) : kInf) < z ? 1 : 0;
  return m;
}

// Every depth worth testing: the 1/16 grid the random layers sit on (ties), the floats right
// beside each grid value, beyond both ends, both infinities and -0.0.
std::vector<float> test_depths() {
  std::vector<float> z = {-1.0f, 2.0f, -kInf, kInf, -0.0f};
  for (int i = 0; i <= test_support::kGrid; ++i) {
    const float v = static_cast<float>(i) / test_support::kGrid;
    z.insert(z.end(), {v, std::nextafter(v, -kInf), std::nextafter(v, kInf)});
  }
  return z;
}

// The tie rule on a shape touching the cube's faces (layers 0.0 and 1.0) and on a texel with a
// duplicate face and a lone last layer: a layer is in front of z iff depth < z; all readers agree.
TEST(LdiVptTest, TieRuleTable) {
  const Ldi l = Ldi::from_texels(2, 1, {{0.0f, 1.0f}, {0.25f, 0.5f, 0.5f, 0.75f, 0.875f}});
  const CroppedLdi cl = crop(l);
  const CompressedLdi cc = compress(l);
  struct Row {
    int x;
    float z;
    bool inside;
    const char* why;
  };
  const Row rows[] = {
      {0, 0.0f, false, "exactly on the front face at 0: no layer < z, outside"},
      {0, 0.5f, true, "between the faces"},
      {0, 1.0f, true, "exactly on the back face at 1.0 (a valid layer, not the marker): inside"},
      {0, std::nextafter(1.0f, 2.0f), false, "just behind the back face"},
      {0, kInf, false, "at +inf: both layers in front, the marker is not"},
      {1, 0.25f, false, "on the first front face"},
      {1, 0.5f, true, "on the back face 0.5 (the duplicate 0.5 is not in front either)"},
      {1, 0.625f, true, "behind 0.25, 0.5, 0.5: three layers"},
      {1, 0.75f, true, "on 0.75: still three in front"},
      {1, 0.8f, false, "four in front"},
      {1, 0.875f, false, "on the lone last layer"},
      {1, 0.9f, true, "behind the lone last layer (a mesh with a hole): five in front"},
  };
  for (const Row& r : rows) {
    EXPECT_EQ(vpt_layers(l, r.x, 0, r.z).inside, r.inside) << "full LDI: " << r.why;
    EXPECT_EQ(vpt_layers(cl, r.x, 0, r.z).inside, r.inside) << "cropped LDI: " << r.why;
    EXPECT_EQ(vpt_ranges(cc, r.x, 0, r.z).inside, r.inside) << "compressed LDI: " << r.why;
  }
}

// On seeded random LDIs (ties, odd counts, empty texels, trailing layers), every texel in and one
// ring around the crop and every test depth: the three readers give the brute-force parity, and
// their fetches equal the closed forms: min(L, front + 1) layered (L = layers read: all stored for
// the full LDI, d for the cropped), 1 + min(k, passed + 1) compressed, 0 outside the crop; the
// texels they read are the texel's own and its first range at I + the ranges before it.
TEST(LdiVptTest, ReadersAgreeWithBruteForceExhaustively) {
  test_support::RandomLdi gen(7);
  const std::vector<float> depths = test_depths();
  long long points = 0, ties = 0;
  for (int i = 0; i < 200; ++i) {
    const Ldi l = gen.next();
    const CroppedLdi cl = crop(l);
    const CompressedLdi cc = compress(l);
    const nbsim::Rect& r = cl.crop.rect;
    const int d = cl.crop.depth_complexity;
    // Each cropped texel's first range texel, counted independently: I + the ranges before it.
    std::vector<std::uint32_t> first_range;
    std::uint32_t next = static_cast<std::uint32_t>(r.area());
    for (int y = r.y; y < r.y1(); ++y)
      for (int x = r.x; x < r.x1(); ++x) first_range.push_back(next), next += static_cast<std::uint32_t>(l.count(x, y) + 1) / 2;
    for (int y = std::min(r.y, 0) - 1; y <= std::max(r.y1(), l.height()); ++y)
      for (int x = std::min(r.x, 0) - 1; x <= std::max(r.x1(), l.width()); ++x)
        for (float z : depths) {
          const bool in_ldi = x >= 0 && y >= 0 && x < l.width() && y < l.height();
          const bool in_crop = r.contains(x, y);
          const int front = in_ldi ? layers_in_front(l, x, y, z) : 0;
          const bool inside = (front & 1) != 0;
          const VptResult full = vpt_layers(l, x, y, z), cropped = vpt_layers(cl, x, y, z), comp = vpt_ranges(cc, x, y, z),
                          every = vpt_all_layers(cl, x, y, z);
          ASSERT_EQ(full.inside, inside) << "LDI " << i << " texel (" << x << ", " << y << ") z " << z << ": full reader";
          ASSERT_EQ(cropped.inside, inside) << "LDI " << i << " texel (" << x << ", " << y << ") z " << z << ": cropped reader";
          ASSERT_EQ(comp.inside, inside) << "LDI " << i << " texel (" << x << ", " << y << ") z " << z << ": compressed reader";
          ASSERT_EQ(every.inside, inside) << "LDI " << i << " texel (" << x << ", " << y << ") z " << z << ": the paper's reader";
          ASSERT_EQ(every.fetches, in_crop ? d : 0) << "LDI " << i << ": the paper's reader reads every layer";
          ASSERT_EQ(full.fetches, in_ldi ? std::min(l.layer_count(), front + 1) : 0) << "LDI " << i << " full fetches";
          ASSERT_EQ(cropped.fetches, in_crop ? std::min(d, front + 1) : 0) << "LDI " << i << " cropped fetches";
          const int k = in_crop ? (l.count(x, y) + 1) / 2 : 0;
          ASSERT_EQ(comp.fetches, in_crop ? 1 + std::min(k, ranges_passed(l, x, y, z) + 1) : 0)
              << "LDI " << i << " texel (" << x << ", " << y << ") z " << z << ": compressed fetches";
          if (in_ldi) {
            ASSERT_EQ(full.texel, static_cast<std::uint64_t>(y * l.width() + x)) << "full reader's texel";
          }
          if (in_crop) {
            const auto ct = static_cast<std::size_t>((y - r.y) * r.w + (x - r.x));
            ASSERT_EQ(cropped.texel, ct) << "cropped reader's texel";
            ASSERT_EQ(every.texel, ct) << "the paper's reader's texel";
            ASSERT_EQ(comp.texel, ct) << "compressed reader's index texel";
            ASSERT_EQ(comp.first_range, first_range[ct]) << "compressed reader's first range texel";
          }
          ++points;
          if (in_ldi)
            for (int j = 0; j < l.count(x, y); ++j) ties += l.depth(x, y, j) == z ? 1 : 0;
        }
  }
  std::cout << points << " test points, " << ties << " (layer, point) ties\n";
  EXPECT_GT(ties, 5000) << "the test must exercise points exactly on layers";
}

// Fetch counts on one texel of 18 layers (d = 18): behind every layer 18 layered fetches against
// 1 + 9 compressed; in front of all 1 against 1 + 1; between layers 5 and 6 (six in front) 7
// against 1 + 4 (ranges 0-1, 2-3, 4-5 passed, the fourth read).
TEST(LdiVptTest, FetchCountsOnADeepTexel) {
  std::vector<float> t;
  for (int k = 0; k < 18; ++k) t.push_back(static_cast<float>(k + 1) / 20.0f);
  const Ldi l = Ldi::from_texels(1, 1, {t});
  const CompressedLdi c = compress(l);
  struct Row {
    float z;
    int layered, compressed;
    bool inside;
  };
  for (const Row& r : {Row{0.99f, 18, 10, false}, Row{0.01f, 1, 2, false}, Row{0.33f, 7, 5, false}, Row{0.28f, 6, 4, true}}) {
    const VptResult a = vpt_layers(l, 0, 0, r.z), b = vpt_ranges(c, 0, 0, r.z);
    EXPECT_EQ(a.fetches, r.layered) << "z " << r.z;
    EXPECT_EQ(b.fetches, r.compressed) << "z " << r.z;
    EXPECT_EQ(a.inside, r.inside) << "z " << r.z;
    EXPECT_EQ(b.inside, r.inside) << "z " << r.z;
  }
}

// Points outside the crop rectangle (the crop is a uniform) are outside without any fetch; a point
// inside the crop on an empty texel costs one fetch either way (layer 0 is +inf; its index says k = 0).
TEST(LdiVptTest, OutsideTheCropCostsNoFetch) {
  std::vector<std::vector<float>> texels(5 * 4);
  texels[1 * 5 + 1] = {0.2f, 0.8f};
  texels[2 * 5 + 3] = {0.3f, 0.6f};
  const Ldi l = Ldi::from_texels(5, 4, texels);
  const CroppedLdi cl = crop(l);
  const CompressedLdi c = compress(l);
  ASSERT_EQ(cl.crop.rect, (nbsim::Rect{1, 1, 3, 2}));
  for (auto [x, y] : std::vector<std::pair<int, int>>{{0, 1}, {4, 1}, {1, 0}, {1, 3}, {-1, -1}, {100, 2}}) {
    EXPECT_EQ(vpt_layers(cl, x, y, 0.5f).fetches, 0) << "(" << x << ", " << y << ") outside the crop";
    EXPECT_EQ(vpt_ranges(c, x, y, 0.5f).fetches, 0) << "(" << x << ", " << y << ") outside the crop";
    EXPECT_FALSE(vpt_ranges(c, x, y, 0.5f).inside);
  }
  EXPECT_EQ(vpt_layers(cl, 3, 1, 0.5f).fetches, 1) << "empty texel inside the crop: layer 0 read";
  EXPECT_EQ(vpt_ranges(c, 3, 1, 0.5f).fetches, 1) << "empty texel inside the crop: the index read";
  EXPECT_TRUE(vpt_ranges(c, 1, 1, 0.5f).inside);
  EXPECT_TRUE(vpt_ranges(c, 3, 2, 0.5f).inside);
}

// Mean fetches per test on a seeded deep LDI (64x64 texels of 10 to 18 layers on the 1/16 grid,
// odd counts included), 33 depths per texel: the compressed test reads about half as many texels
// (the paper's O(d) -> O(d/2)): per test at most 1 + ceil(d/2), and at most 1.5 + half the layered
// fetches (f front layers cost f + 1 layered, 2 + floor(f/2) compressed).
TEST(LdiVptTest, CompressedHalvesTheFetchesOnADeepLdi) {
  test_support::RandomLdi gen(18);
  std::vector<std::vector<float>> texels(64 * 64);
  for (auto& t : texels) {
    const int n = 10 + gen.below(9);
    for (int k = 0; k < n; ++k) t.push_back(static_cast<float>(gen.below(test_support::kGrid + 1)) / test_support::kGrid);
    std::sort(t.begin(), t.end());
  }
  const Ldi l = Ldi::from_texels(64, 64, texels);
  const CroppedLdi cl = crop(l);
  const CompressedLdi c = compress(l);
  ASSERT_EQ(cl.crop.depth_complexity, 18);
  long long layered = 0, compressed = 0, every = 0, tests = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      for (int s = 0; s <= 32; ++s) {
        const float z = static_cast<float>(s) / 32.0f;
        const VptResult a = vpt_layers(cl, x, y, z), b = vpt_ranges(c, x, y, z), p = vpt_all_layers(cl, x, y, z);
        ASSERT_EQ(a.inside, b.inside);
        ASSERT_EQ(p.inside, b.inside);
        ASSERT_EQ(p.fetches, 18) << "the paper's reader: d fetches, O(d)";
        every += p.fetches;
        ASSERT_LE(b.fetches, 1 + 9);
        ASSERT_LE(2 * b.fetches, 3 + a.fetches) << "texel (" << x << ", " << y << ") z " << z;
        layered += a.fetches, compressed += b.fetches, ++tests;
      }
  const double mean_layered = static_cast<double>(layered) / static_cast<double>(tests),
               mean_compressed = static_cast<double>(compressed) / static_cast<double>(tests),
               mean_every = static_cast<double>(every) / static_cast<double>(tests);
  std::cout << tests << " tests: mean fetches " << mean_every << " every layer (the paper's), " << mean_layered << " layered, "
            << mean_compressed << " compressed\n";
  EXPECT_LT(mean_compressed, mean_layered);
  EXPECT_LE(2 * mean_compressed, mean_every + 2) << "compressed: at most 1 + d/2 against the paper's d";
}

// A NaN test depth is bad input, refused with a message (it would otherwise read every layer).
TEST(LdiVptTest, NaNDepthIsRefused) {
  const Ldi l = Ldi::from_texels(1, 1, {{0.5f}});
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(vpt_layers(l, 0, 0, nan), nbsim::InputError);
  EXPECT_THROW(vpt_layers(crop(l), 0, 0, nan), nbsim::InputError);
  EXPECT_THROW(vpt_ranges(compress(l), 0, 0, nan), nbsim::InputError);
}

// A damaged index texel pointing past the texture is refused, not read out of bounds.
TEST(LdiVptTest, DamagedIndexIsRefused) {
  CompressedLdi c = compress(Ldi::from_texels(1, 1, {{0.25f, 0.5f}}));
  c.texels[0] = 1000;
  EXPECT_THROW(vpt_ranges(c, 0, 0, 0.4f), nbsim::InputError);
}

}  // namespace

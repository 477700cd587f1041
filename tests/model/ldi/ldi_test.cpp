// LdiTest: the LDI core (model/ldi/ldi.h): the invalid marker, counts and depth complexity, the
// validation of bad input, and the crop.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "model/common/error.h"
#include "model/ldi/ldi.h"
#include "tests/model/ldi/random_ldi.h"

namespace {

using namespace nbsim::ldi;
using nbsim::InputError;
using nbsim::Rect;

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// The message of the InputError that `f` throws ("" when it throws none).
template <class F>
std::string input_error(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A shape touching the cube's faces: its front face at 0 and back face at exactly 1.0 are two valid
// layers, never taken for the invalid marker (+inf).
TEST(LdiTest, BackFaceAtOneIsAValidLayer) {
  const Ldi l = Ldi::from_texels(2, 1, {{0.0f, 1.0f}, {}});
  EXPECT_EQ(l.count(0, 0), 2) << "depth 1.0 is a valid layer";
  EXPECT_EQ(l.count(1, 0), 0);
  EXPECT_EQ(l.depth_complexity(), 2);
  EXPECT_EQ(l.depth(0, 0, 1), 1.0f);
  EXPECT_EQ(l.depth(1, 0, 0), kInvalidDepth);
  EXPECT_TRUE(std::isinf(kInvalidDepth) && kInvalidDepth > 0.0f) << "the marker is +inf, outside [0, 1]";
}

// Counts per texel and d = the largest count, independent of the stored layer count.
TEST(LdiTest, CountsAndDepthComplexity) {
  const Ldi l = Ldi::from_texels(3, 2, {{0.1f}, {0.1f, 0.2f, 0.3f}, {}, {0.5f, 0.5f}, {}, {0.0f, 0.25f, 0.5f, 0.75f}});
  EXPECT_EQ(l.layer_count(), 4);
  EXPECT_EQ(l.depth_complexity(), 4);
  const int expected[2][3] = {{1, 3, 0}, {2, 0, 4}};
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) EXPECT_EQ(l.count(x, y), expected[y][x]) << "texel (" << x << ", " << y << ")";
  // Trailing stored layers that no texel uses do not raise d.
  std::vector<float> depths(2 * 1 * 5, kInvalidDepth);
  depths[0] = 0.5f;
  EXPECT_EQ(Ldi(2, 1, 5, depths).depth_complexity(), 1);
}

// Bad input, row by row: an InputError whose message names the problem (and the texel and layer).
TEST(LdiTest, BadInputTable) {
  struct Row {
    int w, h, layers;
    std::vector<float> depths;
    const char* must_say;
    const char* why;
  };
  const Row rows[] = {
      {2, 1, 1, {0.5f, kNaN}, "texel (1, 0) layer 0: depth is NaN", "NaN depth"},
      {1, 1, 2, {0.2f, -kInf}, "texel (0, 0) layer 1: depth -inf is outside [0, 1]", "-inf depth"},
      {1, 1, 1, {-0.5f}, "outside [0, 1]", "negative depth"},
      {1, 1, 1, {1.5f}, "outside [0, 1]", "depth beyond the far face"},
      {1, 2, 2, {0.1f, 0.2f, 0.3f, 0.1f}, "texel (0, 1) layer 1: depth 0.1 is nearer than layer 0's 0.2 (layers out of order)",
       "unordered layers"},
      {1, 1, 3, {0.1f, kInf, 0.3f}, "texel (0, 0) layer 2: valid depth 0.3 behind missing layer 1", "a hole in the layers"},
      {0, 1, 1, {}, "0x1 texels", "width 0"},
      {1, 0, 1, {}, "1x0 texels", "height 0"},
      {16385, 1, 0, {}, "each side must be in [1, 16384]", "wider than GL_MAX_TEXTURE_SIZE"},
      {1, 1, 2049, std::vector<float>(2049, kInf), "2049 layers, the limit is 2048", "more layers than the limit"},
      {1, 1, -1, {}, "-1 layers", "negative layer count"},
      {2, 2, 1, {0.5f}, "1 depths for 2x2 texels x 1 layers (expected 4)", "size mismatch"},
  };
  for (const Row& r : rows) {
    const std::string msg = input_error([&] { Ldi(r.w, r.h, r.layers, r.depths); });
    EXPECT_NE(msg.find(r.must_say), std::string::npos) << r.why << ": got '" << msg << "'";
  }
  EXPECT_NE(input_error([] { Ldi::from_texels(1, 1, {std::vector<float>(2049, 0.5f)}); }).find("limit is 2048"),
            std::string::npos)
      << "from_texels: a texel deeper than the limit";
  EXPECT_NO_THROW(Ldi::from_texels(1, 1, {std::vector<float>(2048, 0.5f)})) << "exactly the limit is fine";
}

// The crop is the bounding rectangle of the texels with a layer, M_crop = w_crop * h_crop * d, and
// uncrop restores the LDI bit for bit (trailing unused layers included).
TEST(LdiTest, CropIsTheBoundingRectangle) {
  std::vector<float> depths(6 * 5 * 4, kInvalidDepth);
  const auto at = [](int x, int y, int k) { return (static_cast<std::size_t>(k) * 5 + y) * 6 + x; };
  depths[at(1, 3, 0)] = 0.1f, depths[at(1, 3, 1)] = 0.9f;
  depths[at(4, 1, 0)] = 0.3f;
  const Ldi l(6, 5, 4, depths);
  const Crop c = find_crop(l);
  EXPECT_EQ(c.rect, (Rect{1, 1, 4, 3}));
  EXPECT_EQ(c.depth_complexity, 2);
  EXPECT_EQ(c.m_crop(), 4u * 3u * 2u);
  const CroppedLdi cl = crop(l);
  EXPECT_EQ(cl.depths.size(), 24u);
  EXPECT_EQ(cl.depth(1, 3, 1), 0.9f);
  EXPECT_EQ(cl.depth(2, 2, 0), kInvalidDepth) << "an empty texel inside the crop";
  EXPECT_TRUE(bit_equal(uncrop(cl), l));
}

// An LDI without any valid layer crops to an empty rectangle (M_crop = 0) and uncrops back.
TEST(LdiTest, AllInvalidCropsToNothing) {
  const Ldi l(3, 2, 2, std::vector<float>(12, kInvalidDepth));
  const CroppedLdi c = crop(l);
  EXPECT_TRUE(c.crop.rect.empty());
  EXPECT_EQ(c.crop.m_crop(), 0u);
  EXPECT_TRUE(c.depths.empty());
  EXPECT_TRUE(bit_equal(uncrop(c), l));
}

// crop/uncrop round trips on seeded random LDIs (ties, -0.0, odd counts, empty texels).
TEST(LdiTest, CropRoundTripsOnRandomLdis) {
  test_support::RandomLdi gen(1401);
  for (int i = 0; i < 300; ++i) {
    const Ldi l = gen.next();
    ASSERT_TRUE(bit_equal(uncrop(crop(l)), l)) << "random LDI " << i;
  }
}

// bit_equal tells -0.0 from +0.0 (operator== on floats would not).
TEST(LdiTest, BitEqualSeesTheSignOfZero) {
  EXPECT_FALSE(bit_equal(Ldi::from_texels(1, 1, {{0.0f}}), Ldi::from_texels(1, 1, {{-0.0f}})));
  EXPECT_TRUE(bit_equal(Ldi::from_texels(1, 1, {{-0.0f}}), Ldi::from_texels(1, 1, {{-0.0f}})));
}

}  // namespace

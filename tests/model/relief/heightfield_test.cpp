// ReliefHeightfieldTest: the heightfield of model/relief (heightfield.h): the generators, the
// checks and their messages, and the bilinear surface with its virtual zero border.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "model/relief/heightfield.h"
#include "tests/common/input_error.h"

namespace {

using namespace nbsim::relief;
using nbsim::testing::input_error;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

Heightfield flat(int n, float h) { return Heightfield{n, std::vector<float>(static_cast<std::size_t>(n) * n, h)}; }

// Every kind at small, odd and large sizes is a valid field, and the same arguments give the same heights.
TEST(ReliefHeightfieldTest, EveryGeneratorIsValidAndDeterministic) {
  ASSERT_EQ(heightfield_kinds().size(), 5u);
  for (std::string_view kind : heightfield_kinds()) {
    for (int n : {2, 3, 16, 33, 128}) {
      const Heightfield a = make_heightfield(kind, n, 0, 7);
      EXPECT_EQ(a.size, n) << kind;
      EXPECT_EQ(heightfield_problem(a), "") << kind << " at size " << n;
      EXPECT_EQ(a.heights, make_heightfield(kind, n, 0, 7).heights) << kind << " at size " << n << " is not deterministic";
    }
  }
}

// fbm and spikes follow the seed; fbm spans exactly [0, 0.9] and is not 0 on the outermost ring.
TEST(ReliefHeightfieldTest, SeededGenerators) {
  EXPECT_NE(make_heightfield("fbm", 32, 0, 1).heights, make_heightfield("fbm", 32, 0, 2).heights) << "fbm ignores its seed";
  EXPECT_NE(make_heightfield("spikes", 32, 0, 1).heights, make_heightfield("spikes", 32, 0, 2).heights) << "spikes ignore their seed";
  EXPECT_NE(make_heightfield("fbm", 32, 1, 1).heights, make_heightfield("fbm", 32, 8, 1).heights) << "fbm ignores its octaves";
  const Heightfield f = make_heightfield("fbm", 64, 0, 3);
  const auto [lo, hi] = std::minmax_element(f.heights.begin(), f.heights.end());
  EXPECT_EQ(*lo, 0.0f);
  EXPECT_NEAR(*hi, 0.9f, 1e-6f);
  float ring = 0.0f;
  for (int k = 0; k < 64; ++k) ring = std::max({ring, f.at(k, 0), f.at(0, k), f.at(k, 63), f.at(63, k)});
  EXPECT_GT(ring, 0.0f) << "the outermost ring need not be 0: the virtual border supplies the 0";
}

// walls, spikes, saddle and step put their features where heightfield.h says.
TEST(ReliefHeightfieldTest, GeneratorLayouts) {
  const Heightfield w = make_heightfield("walls", 16, 4, 0);
  for (int j = 0; j < 16; ++j)
    for (int i = 0; i < 16; ++i)
      EXPECT_EQ(w.at(i, j), (i % 4 == 2 || j % 4 == 2) ? 1.0f : 0.0f) << "walls at texel (" << i << ", " << j << ")";

  const Heightfield s = make_heightfield("spikes", 16, 10, 5);
  EXPECT_EQ(std::count(s.heights.begin(), s.heights.end(), 1.0f), 10) << "param spikes, at distinct texels";
  EXPECT_EQ(std::count(s.heights.begin(), s.heights.end(), 0.1f), 256 - 10) << "the floor is 0.1";
  const Heightfield s0 = make_heightfield("spikes", 16, 0, 5);
  EXPECT_EQ(std::count(s0.heights.begin(), s0.heights.end(), 1.0f), 4) << "param 0 means N / 4";
  const Heightfield all = make_heightfield("spikes", 4, 16, 5);
  EXPECT_EQ(std::count(all.heights.begin(), all.heights.end(), 1.0f), 16) << "every texel can be a spike";

  const Heightfield sd = make_heightfield("saddle", 8, 0, 0);
  EXPECT_EQ(sd.at(3, 3), 0.0f);
  EXPECT_EQ(sd.at(4, 3), 1.0f);
  EXPECT_EQ(sd.at(3, 4), 1.0f);
  EXPECT_EQ(sd.at(4, 4), 0.0f);
  EXPECT_EQ(std::count(sd.heights.begin(), sd.heights.end(), 1.0f), 2) << "0 outside the four saddle texels";

  const Heightfield st = make_heightfield("step", 6, 0, 0);
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 6; ++i) EXPECT_EQ(st.at(i, j), i >= 3 ? 1.0f : 0.0f) << "step at texel (" << i << ", " << j << ")";
}

// Each row: a broken field and the words its problem must contain.
TEST(ReliefHeightfieldTest, ProblemsAreNamed) {
  Heightfield nan_field = flat(4, 0.5f);
  nan_field.heights[2 * 4 + 1] = kNaN;  // texel (1, 2)
  Heightfield high = flat(4, 0.5f);
  high.heights[3 * 4 + 2] = 1.5f;  // texel (2, 3)
  Heightfield low = flat(4, 0.5f);
  low.heights[0] = -0.25f;
  Heightfield infinite = flat(4, 0.5f);
  infinite.heights[5] = kInf;
  Heightfield short_field = flat(4, 0.5f);
  short_field.heights.resize(10);
  const struct {
    const char* why;
    Heightfield field;
    std::string expected;
  } rows[] = {
      {"NaN texel", nan_field, "texel (1, 2) is NaN"},
      {"above 1", high, "texel (2, 3) is 1.5, outside [0, 1]"},
      {"below 0", low, "texel (0, 0) is -0.25, outside [0, 1]"},
      {"infinite", infinite, "texel (1, 1) is inf, outside [0, 1]"},
      {"wrong length", short_field, "has 10 heights, but 4 x 4 needs 16"},
      {"size 1 is too small", flat(1, 0.0f), "size 1 is not supported (2 to 1024)"},
      {"size 2000 is too large", Heightfield{2000, {}}, "size 2000 is not supported (2 to 1024)"},
      {"size 0", Heightfield{}, "size 0 is not supported"},
  };
  for (const auto& row : rows) {
    EXPECT_NE(heightfield_problem(row.field).find(row.expected), std::string::npos)
        << row.why << ": got '" << heightfield_problem(row.field) << "'";
    EXPECT_NE(input_error([&] { check_heightfield(row.field, "the field in f.exr"); }).find("the field in f.exr: " + row.expected),
              std::string::npos)
        << row.why << ": check_heightfield must throw InputError naming the field";
  }
  EXPECT_EQ(heightfield_problem(flat(2, 0.0f)), "");
  EXPECT_EQ(heightfield_problem(flat(1024, 1.0f)), "");
  EXPECT_NO_THROW(check_heightfield(flat(3, 1.0f), "x"));
}

// Unknown kinds, bad params and unsupported sizes are the user's errors.
TEST(ReliefHeightfieldTest, BadGeneratorArgumentsAreInputErrors) {
  const struct {
    const char* why;
    const char* kind;
    int size, param;
    const char* expected;
  } rows[] = {
      {"unknown kind", "mountains", 16, 0, "unknown heightfield kind 'mountains'"},
      {"fbm: 13 octaves", "fbm", 16, 13, "octaves"},
      {"fbm: negative octaves", "fbm", 16, -1, "octaves"},
      {"walls: spacing 1", "walls", 16, 1, "spacing"},
      {"walls: spacing 2000", "walls", 16, 2000, "spacing"},
      {"spikes: negative count", "spikes", 16, -3, "count"},
      {"spikes: more than the texels", "spikes", 4, 17, "count"},
      {"size 1", "step", 1, 0, "size 1 is not supported"},
      {"size 2000", "saddle", 2000, 0, "size 2000 is not supported"},
  };
  for (const auto& row : rows)
    EXPECT_NE(input_error([&] { make_heightfield(row.kind, row.size, row.param, 1); }).find(row.expected), std::string::npos)
        << row.why;
}

// The surface: texel centres carry their heights, cells are bilinear, the border falls to 0.
TEST(ReliefHeightfieldTest, SurfaceIsBilinearWithZeroBorder) {
  Heightfield f = flat(3, 0.0f);
  f.heights = {0.1f, 0.2f, 0.3f,  //
               0.4f, 0.5f, 0.6f,  //
               0.7f, 0.8f, 0.9f};
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(surface_height(f, i + 0.5, j + 0.5), f.at(i, j)) << "texel centre";
  EXPECT_NEAR(surface_height(f, 1.0, 1.0), (0.1 + 0.2 + 0.4 + 0.5) / 4, 1e-7) << "cell middle: the average of its corners";
  EXPECT_NEAR(surface_height(f, 1.25, 0.5), 0.25 * 0.1 + 0.75 * 0.2, 1e-7) << "along a row";
  EXPECT_NEAR(surface_height(f, 0.0, 0.5), 0.05, 1e-7) << "the box's edge: halfway to the virtual 0";
  EXPECT_NEAR(surface_height(f, 3.0, 3.0), 0.9 / 4, 1e-7) << "the box's corner: a quarter of the corner texel";
  EXPECT_EQ(surface_height(f, -0.5, 1.5), 0.0) << "the virtual texels' centres";
  EXPECT_EQ(surface_height(f, 1.5, 3.5), 0.0);
  EXPECT_EQ(surface_height(f, -7.0, 40.0), 0.0) << "far outside";
}

}  // namespace

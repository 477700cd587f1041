// NBufferBuildTest: the optimized NBuffer::build, both paths (bands of rows with row groups, and row
// by row with rings of pairs and streamed planes; SIMD clones; see model/nbuffer/nbuffer.cpp)
// against a straightforward level-by-level build kept here as the reference, bit for bit: every
// format, both ops, partial builds, sizes from 1x1 to past a band, and inputs with ties, signed
// zeros, NaNs and the far and neutral limits.
#include "model/nbuffer/nbuffer.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "tests/common/reference.h"

namespace nbsim {
namespace {

constexpr FarOp kOps[] = {FarOp::Max, FarOp::Min};
constexpr StorageFormat kFormats[] = {StorageFormat::F32, StorageFormat::U24, StorageFormat::U16};

// The build as Fig. 2 states it: level 0 is the quantized depth, and level i at (x, y) is the
// farthest of level i - 1 at (x, y), (x + s, y), (x, y + s), (x + s, y + s), s = 2^(i - 1), in
// that pairing (the pairs along x first), skipping texels outside the image. One plane after the
// other, one texel at a time.
std::vector<std::vector<float>> reference_build(const DepthImage& depth, const NBufferConfig& c, int levels) {
  const int w = depth.width, h = depth.height;
  std::vector<std::vector<float>> out(static_cast<std::size_t>(levels));
  out[0].resize(depth.texels.size());
  for (std::size_t k = 0; k < depth.texels.size(); ++k) out[0][k] = quantize_toward_far(depth.texels[k], c.format, c.op);
  for (int i = 1; i < levels; ++i) {
    const int s = 1 << (i - 1);
    const std::vector<float>& src = out[static_cast<std::size_t>(i - 1)];
    std::vector<float>& dst = out[static_cast<std::size_t>(i)];
    dst.resize(src.size());
    auto at = [&](int x, int y) { return src[static_cast<std::size_t>(y) * w + x]; };
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        float row = x + s < w ? farther(c.op, at(x, y), at(x + s, y)) : at(x, y);
        if (y + s < h) {
          const float above = x + s < w ? farther(c.op, at(x, y + s), at(x + s, y + s)) : at(x, y + s);
          row = farther(c.op, row, above);
        }
        dst[static_cast<std::size_t>(y) * w + x] = row;
      }
  }
  return out;
}

// Depths that stress bit-exactness: mostly a few tied values, some random, signed zeros, NaNs,
// the far and neutral limits, and values between storage codes.
DepthImage stress_image(int w, int h, std::mt19937& rng) {
  DepthImage img(w, h, 0.0f);
  for (float& t : img.texels) {
    switch (ref::uniform_int(rng, 0, 11)) {
      case 0: t = 0.0f; break;
      case 1: t = -0.0f; break;
      case 2: t = 1.0f; break;
      case 3: t = std::numeric_limits<float>::quiet_NaN(); break;
      case 4: case 5: case 6: t = 0.25f * static_cast<float>(ref::uniform_int(rng, 1, 3)); break;
      default: t = ref::unit_float(rng); break;
    }
  }
  return img;
}

// Texels whose bits differ (NaN equals NaN of the same bits, +0 differs from -0).
long long bit_differences(std::span<const float> a, const std::vector<float>& b) {
  long long n = 0;
  for (std::size_t k = 0; k < a.size(); ++k) n += std::bit_cast<std::uint32_t>(a[k]) != std::bit_cast<std::uint32_t>(b[k]);
  return n;
}

// Builds `img` with config c from the constructor (the path build() picks), then again into the
// same buffer on each path (banded, then rows, then rows over rows), and compares every level with
// the reference after each; failures go to f.
void check_against_reference(const DepthImage& img, const NBufferConfig& c, const std::string& what, ref::Failures& f) {
  NBuffer nb(img, c);
  const auto want = reference_build(img, c, nb.level_count());
  const struct {
    NBuffer::BuildPath path;
    const char* name;
  } passes[] = {{NBuffer::BuildPath::Auto, "built"},
                {NBuffer::BuildPath::Banded, "rebuilt banded"},
                {NBuffer::BuildPath::Rows, "rebuilt by rows"},
                {NBuffer::BuildPath::Rows, "rebuilt by rows again"}};
  for (const auto& pass : passes) {
    if (pass.path != NBuffer::BuildPath::Auto) nb.build(img, pass.path);  // over the previous pass's levels
    for (int i = 0; i < nb.level_count(); ++i)
      if (const long long d = bit_differences(nb.level(i), want[static_cast<std::size_t>(i)]))
        f.add(what + " (" + pass.name + "): level " + std::to_string(i) + ": " + std::to_string(d) +
              " texels differ from the level-by-level build");
  }
}

std::string name_of(int w, int h, const NBufferConfig& c) {
  return std::to_string(w) + "x" + std::to_string(h) + " " + std::string(to_string(c.op)) + " " +
         std::string(to_string(c.format)) + " max_level " + std::to_string(c.max_level);
}

// ---------------------------------------------------------------------------------------------

// The reference itself: equals the definition (farthest of the clipped square) on finite inputs.
TEST(NBufferBuildTest, ReferenceMatchesDefinition) {
  for (const FarOp op : kOps) {
    const DepthImage img = ref::uniform(23, 37, 5);
    const auto levels = reference_build(img, {.op = op}, 6);
    ref::Failures f;
    for (int i = 0; i < 6; ++i)
      for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
          if (levels[static_cast<std::size_t>(i)][static_cast<std::size_t>(y) * img.width + x] !=
              ref::level_texel(img, op, i, x, y))
            f.add("level " + std::to_string(i) + " texel " + std::to_string(x) + "," + std::to_string(y));
    EXPECT_EQ(f.count(), 0) << to_string(op) << ": the reference build is not the definition: " << f.summary();
  }
}

// Sizes chosen for the build's seams, each row with its reason, every format and op.
TEST(NBufferBuildTest, EdgeSizesMatchReference) {
  struct Row { int w, h; const char* why; };
  const Row rows[] = {
      {1, 1, "one texel, one level"},          {2, 1, "one row, one level"},
      {1, 2, "one column, one level"},         {1, 300, "a column taller than several bands"},
      {300, 1, "a row: every level is its top row"}, {3, 5, "odd and tiny"},
      {16, 16, "two vectors wide"},            {17, 9, "one texel past two vectors"},
      {63, 65, "one row past a band of 64"},   {64, 64, "exactly one band"},
      {129, 128, "two bands, odd width"},      {130, 257, "steps past the banded ones, odd height"},
      {1024, 3, "wide and short: groups never fit"}, {5, 1030, "tall and thin: top level past 512"},
  };
  std::mt19937 rng(2005);
  for (const Row& row : rows) {
    const DepthImage img = stress_image(row.w, row.h, rng);
    ref::Failures f;
    for (const FarOp op : kOps)
      for (const StorageFormat format : kFormats) {
        const NBufferConfig c{op, format, -1};
        check_against_reference(img, c, name_of(row.w, row.h, c), f);
      }
    EXPECT_EQ(f.count(), 0) << row.w << "x" << row.h << " (" << row.why << "): " << f.summary();
  }
}

// Random sizes (log-uniform sides up to 700, some 1-wide), formats, ops and level caps.
TEST(NBufferBuildTest, RandomSizesMatchReference) {
  std::mt19937 rng(16);
  ref::Failures f;
  for (int n = 0; n < 120; ++n) {
    auto side = [&] { return ref::uniform_int(rng, 0, 5) == 0 ? 1 : static_cast<int>(std::lround(std::exp2(ref::unit_float(rng) * 9.5f))); };
    const int w = side(), h = side();
    const int full = nbuffer_level_count(w, h);
    const int max_level = ref::uniform_int(rng, 0, 2) == 0 ? ref::uniform_int(rng, 0, full) : -1;
    const NBufferConfig c{kOps[ref::uniform_int(rng, 0, 1)], kFormats[ref::uniform_int(rng, 0, 2)], max_level};
    check_against_reference(stress_image(w, h, rng), c, name_of(w, h, c), f);
  }
  EXPECT_EQ(f.count(), 0) << f.summary();
}

// Table 1's sizes, which the benchmark times, on the city-like images of the other tests.
TEST(NBufferBuildTest, Table1SizesMatchReference) {
  const std::pair<int, int> sizes[] = {{256, 256}, {512, 512}, {640, 480}, {1024, 1024}};
  ref::Failures f;
  std::mt19937 rng(31);
  for (const auto& [w, h] : sizes)
    for (const FarOp op : kOps) {
      const NBufferConfig c{op, StorageFormat::F32, -1};
      check_against_reference(w == 1024 ? ref::three_values(w, h, 7) : stress_image(w, h, rng), c, name_of(w, h, c), f);
    }
  EXPECT_EQ(f.count(), 0) << f.summary();
}

}  // namespace
}  // namespace nbsim

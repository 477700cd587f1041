// DepthTestTest: the early depth test (model/raster/depth_test.h): the depth functions, the depth
// plane's interpolation and clamp, a disabled test, the 24-bit depth format, fragment shaders'
// discards (pixel by pixel and block by block), whole blocks against one pixel at a time.
#include "model/raster/depth_test.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include "model/common/depth.h"
#include "model/raster/setup.h"
#include "tests/model/raster/coverage.h"
#include "tests/model/raster/compare_funcs.h"

namespace nbsim::raster {
namespace {

using namespace nbsim::raster::testing;

// Each depth function against a stored 0.5 (and NaN-free equality), a table.
TEST(DepthTestTest, DepthFunctions) {
  for (const CompareRow& r : kCompareFuncs) {
    EXPECT_EQ(depth_passes(r.f, 0.25f, 0.5f), r.below) << "func " << static_cast<int>(r.f) << ", fragment nearer";
    EXPECT_EQ(depth_passes(r.f, 0.5f, 0.5f), r.equal) << "func " << static_cast<int>(r.f) << ", equal depth";
    EXPECT_EQ(depth_passes(r.f, 0.75f, 0.5f), r.above) << "func " << static_cast<int>(r.f) << ", fragment farther";
  }
  EXPECT_TRUE(depth_passes(DepthFunc::NotEqual, NAN, 0.5f)) << "NOTEQUAL is unordered";
  EXPECT_FALSE(depth_passes(DepthFunc::Less, NAN, 0.5f)) << "LESS is ordered";
}

// A constant-depth triangle gives exactly its depth; a sloped one stays within 1e-6 of the plane
// through its vertices at pixel centres; depth is clamped to [0, 1].
TEST(DepthTestTest, DepthPlaneInterpolation) {
  SetupTriangle s;
  SetupCounters k;
  const TriangleSetup setup({64, 64});
  ASSERT_EQ(setup.setup(tri(1, 1, 60, 3, 5, 58, 0.3f), kNoCull, s, k), SetupResult::Accepted);
  for (int y = 5; y < 40; y += 7)
    for (int x = 5; x < 40; x += 7) EXPECT_EQ(s.depth.at(x, y), 0.3f) << "constant depth is exact";
  WindowTriangle t = tri(1, 1, 60, 3, 5, 58);
  t.v[0].z = 0.1f;
  t.v[1].z = 0.9f;
  t.v[2].z = 0.4f;
  ASSERT_EQ(setup.setup(t, kNoCull, s, k), SetupResult::Accepted);
  const double det = (60.0 - 1.0) * (58.0 - 1.0) - (5.0 - 1.0) * (3.0 - 1.0);
  for (int y = 2; y < 30; y += 3)
    for (int x = 2; x < 30; x += 3) {
      const double px = x + 0.5, py = y + 0.5;
      const double b1 = ((px - 1.0) * (58.0 - 1.0) - (py - 1.0) * (5.0 - 1.0)) / det;
      const double b2 = ((60.0 - 1.0) * (py - 1.0) - (3.0 - 1.0) * (px - 1.0)) / det;
      const double z = 0.1 + b1 * (0.9 - 0.1) + b2 * (0.4 - 0.1);
      EXPECT_NEAR(s.depth.at(x, y), z, 1e-6) << "pixel (" << x << "," << y << ")";
    }
  DepthPlane p{1.5f, 0.0f, 0.0f};
  EXPECT_EQ(p.at(0, 0), 1.0f) << "clamped to the far value";
  p.a0 = -0.5f;
  EXPECT_EQ(p.at(0, 0), 0.0f) << "clamped to the near value";
}

// With the depth test disabled every fragment passes and the buffer is left alone.
TEST(DepthTestTest, DisabledTestPassesWithoutWriting) {
  DepthImage img(8, 8, 0.25f);
  EarlyDepthTest unit(img);
  DepthCounters k;
  unit.test_block(DepthPlane{0.75f, 0, 0}, 0, 0, 0x0f0f, DepthState{DepthFunc::Less, false, true}, k);
  EXPECT_EQ(k.fragments, 8u);
  EXPECT_EQ(k.passed, 8u);
  EXPECT_EQ(k.depth_tests, 0u) << "no comparison when the test is off";
  EXPECT_EQ(k.written, 0u);
  EXPECT_EQ(img.at(0, 0), 0.25f);
}

// A fragment shader's discard runs before the depth test: a discarded fragment is rasterized
// (counted) but never tested or written, and the shader sees the depth before the [0, 1] clamp.
TEST(DepthTestTest, FragmentShaderDiscardsBeforeTheTest) {
  struct OddColumns final : FragmentShader {
    mutable float last_z = 0.0f;
    bool discards(int x, int, float z) const override {
      last_z = z;
      return x % 2 == 1;
    }
  } shader;
  DepthImage img(8, 8, 1.0f);
  EarlyDepthTest unit(img);
  DepthCounters k;
  DepthState state{DepthFunc::Less, true, true};
  state.shader = &shader;
  unit.test_block(DepthPlane{-0.25f, 0, 0}, 0, 0, 0x000f, state, k);  // pixels (0..3, 0)
  EXPECT_EQ(k.fragments, 4u);
  EXPECT_EQ(k.shader_discarded, 2u);
  EXPECT_EQ(k.depth_tests, 2u);
  EXPECT_EQ(k.written, 2u);
  EXPECT_EQ(img.at(0, 0), 0.0f) << "the kept fragment's depth, clamped";
  EXPECT_EQ(img.at(1, 0), 1.0f) << "a discarded fragment writes nothing";
  EXPECT_EQ(shader.last_z, -0.25f) << "gl_FragCoord.z is not clamped";
}

// A shader that keeps whole blocks (keep_block) tests as the same shader asked pixel by pixel: the
// same buffer and counts, with the depth test on and off, writes on and off, sloped planes, both
// formats and blocks on the ragged edges.
TEST(DepthTestTest, ShaderKeepingBlocksTestsAsPixelByPixel) {
  struct Pattern : FragmentShader {
    std::vector<std::uint8_t> keep;
    int width = 0;
    bool discards(int x, int y, float) const override { return keep[static_cast<std::size_t>(y * width + x)] == 0; }
  };
  struct Blocks final : Pattern {
    std::optional<std::uint16_t> keep_block(int x, int y, std::uint16_t mask) const override {
      unsigned kept = 0;
      for (int i = 0; i < 16; ++i)
        if ((mask >> i & 1) && !discards(x + (i & 3), y + (i >> 2), 0.0f)) kept |= 1u << i;
      return static_cast<std::uint16_t>(kept);
    }
  };
  std::mt19937 random(3);
  std::uniform_real_distribution<float> unit(-0.25f, 1.25f), slope(-0.05f, 0.05f);
  constexpr int kW = 14, kH = 10;
  Pattern pixels;
  Blocks blocks;
  for (Pattern* p : {static_cast<Pattern*>(&pixels), static_cast<Pattern*>(&blocks)}) p->width = kW;
  for (const DepthFormat format : {DepthFormat::Float32, DepthFormat::Unorm24}) {
    DepthImage a(kW, kH, 0.5f);
    for (float& t : a.texels) t = stored_depth(format, std::clamp(unit(random), 0.0f, 1.0f));
    DepthImage b = a;
    EarlyDepthTest by_pixel(a, true, format), by_block(b, true, format);
    DepthCounters ka, kb;
    for (int trial = 0; trial < 300; ++trial) {
      pixels.keep.resize(static_cast<std::size_t>(kW * kH));
      for (std::uint8_t& k : pixels.keep) k = random() % 3 != 0 ? 1 : 0;
      blocks.keep = pixels.keep;
      const DepthPlane plane{unit(random), slope(random), slope(random)};
      DepthState state{static_cast<DepthFunc>(random() % 8), random() % 4 != 0, random() % 2 == 0};
      const int x = 4 * static_cast<int>(random() % 4), y = 4 * static_cast<int>(random() % 3);
      auto mask = static_cast<std::uint16_t>(random());
      for (int i = 0; i < 16; ++i)
        if (x + (i & 3) >= kW || y + (i >> 2) >= kH) mask = static_cast<std::uint16_t>(mask & ~(1u << i));
      state.shader = &pixels;
      by_pixel.test_block(plane, x, y, mask, state, ka);
      state.shader = &blocks;
      by_block.test_block(plane, x, y, mask, state, kb);
      ASSERT_TRUE(a.texels == b.texels) << "trial " << trial;
    }
    const auto counts = [](const DepthCounters& k) {
      return std::array{k.fragments, k.blocks, k.depth_tests, k.passed, k.written, k.shader_discarded};
    };
    EXPECT_EQ(counts(ka), counts(kb));
    EXPECT_GT(ka.shader_discarded, 500u);
    EXPECT_GT(ka.written, 100u);
  }
}

// llvmpipe's 24-bit depth: the product rounded to float, then ties to even; ends and NaN fixed.
TEST(DepthTestTest, Unorm24Conversion) {
  struct Row {
    float z;
    std::uint32_t q;
    const char* why;
  };
  const Row rows[] = {
      {0.0f, 0u, "zero"},
      {1.0f, 16777215u, "one"},
      {0.5f, 8388608u, "0.5 * (2^24 - 1) = 8388607.5, a tie: to even"},
      {1.5f / 16777215.0f, 2u, "1.5 rounds to even 2"},
      {2.5f / 16777215.0f, 2u, "2.5 rounds to even 2"},
      {-0.25f, 0u, "negative clamps to 0"},
      {2.0f, 16777215u, "above one clamps"},
      {NAN, 0u, "NaN is 0"},
  };
  for (const Row& r : rows) EXPECT_EQ(to_unorm24(r.z), r.q) << r.why;
}

// The float image of every 24-bit value is strictly increasing (so float comparisons are the
// integer ones) and converts back to the same value.
TEST(DepthTestTest, Unorm24FloatsAreOneToOne) {
  float last = -1.0f;
  std::uint32_t bad_order = 0, bad_back = 0, bad_quotient = 0, bad_round = 0;
  for (std::uint32_t q = 0; q <= 16777215u; ++q) {
    const float f = from_unorm24(q);
    bad_order += f > last ? 0 : 1;
    bad_back += to_unorm24(f) == q ? 0 : 1;
    bad_quotient += f == static_cast<float>(static_cast<double>(q) / 16777215.0) ? 0 : 1;
    // to_unorm24's rounding against the library's nearbyint, at q and halfway to q + 1.
    for (const float z : {static_cast<float>(q) / 16777215.0f, (static_cast<float>(q) + 0.5f) / 16777215.0f}) {
      const float p = z * 16777215.0f;
      const std::uint32_t want = p >= 16777215.0f ? 16777215u : static_cast<std::uint32_t>(std::nearbyint(p));
      bad_round += to_unorm24(z) == want ? 0 : 1;
    }
    last = f;
  }
  EXPECT_EQ(bad_order, 0u) << "from_unorm24 must be strictly increasing";
  EXPECT_EQ(bad_back, 0u) << "to_unorm24(from_unorm24(q)) must be q";
  EXPECT_EQ(bad_quotient, 0u) << "the reciprocal product rounds to the quotient's float";
  EXPECT_EQ(bad_round, 0u) << "to_unorm24 rounds as std::nearbyint";
  EXPECT_EQ(from_unorm24(16777215u), 1.0f);
  EXPECT_EQ(stored_depth(DepthFormat::Float32, 0.3f), 0.3f) << "Float32 stores the fragment depth";
}

// The trace header's depth_format names.
TEST(DepthTestTest, DepthFormatNames) {
  EXPECT_EQ(parse_depth_format("DEPTH_COMPONENT32F"), DepthFormat::Float32);
  EXPECT_EQ(parse_depth_format("DEPTH32F_STENCIL8"), DepthFormat::Float32);
  EXPECT_EQ(parse_depth_format("DEPTH24_STENCIL8"), DepthFormat::Unorm24);
  EXPECT_EQ(parse_depth_format("DEPTH_COMPONENT24"), DepthFormat::Unorm24);
  EXPECT_FALSE(parse_depth_format("DEPTH_COMPONENT16").has_value());
}

// Whole 4x4 blocks test each pixel as the per-pixel definition does (plane.at, the stored format,
// depth_passes, the write), bit for bit: every function, fused and unfused planes, both formats,
// writes on and off, random masks, the passing pixels marked or not, blocks inside the buffer and
// on its ragged right and top edges, and depths that tie, fall outside [0, 1], are -0 or NaN (planes
// and stored values).
TEST(DepthTestTest, BlocksTestEveryPixelAsOneByOne) {
  std::mt19937 random(5);
  std::uniform_real_distribution<float> unit(-0.25f, 1.25f), slope(-0.05f, 0.05f);
  const auto bits = [](float v) { return std::bit_cast<std::uint32_t>(v); };
  constexpr int kW = 14, kH = 10;  // not multiples of 4: the last column and row of blocks are ragged
  for (int trial = 0; trial < 400; ++trial) {
    DepthPlane plane{unit(random), slope(random), slope(random)};
    if (trial % 17 == 0) plane = DepthPlane{NAN, 0.0f, 0.0f};
    if (trial % 19 == 0) plane = DepthPlane{-0.0f, 0.0f, 0.0f};
    if (trial % 23 == 0) plane = DepthPlane{0.5f, 0.0f, 0.0f};  // ties with the stored 0.5s below
    for (const DepthFormat format : {DepthFormat::Float32, DepthFormat::Unorm24})
      for (const bool fused : {true, false}) {
        DepthImage start(kW, kH, 0.5f);
        for (float& t : start.texels) {
          const int pick = static_cast<int>(random() % 8);
          t = pick == 0 ? NAN : pick == 1 ? 0.5f : pick == 2 ? 1.0f : stored_depth(format, std::clamp(unit(random), 0.0f, 1.0f));
        }
        for (const CompareRow& row : kCompareFuncs)
          for (const bool write : {true, false}) {
            DepthImage got = start, want = start;
            EarlyDepthTest unit_under_test(got, fused, format);
            DepthCounters k;
            std::uint64_t passed = 0, written = 0, tests = 0;
            // Every other trial marks the passing pixels (DepthState::passed_mask).
            std::vector<std::uint8_t> marks(got.texels.size(), 0), want_marks(got.texels.size(), 0);
            DepthState state{row.f, true, write};
            if (trial % 2 == 1) state.passed_mask = &marks;
            for (int y = 0; y < kH; y += 4)
              for (int x = 0; x < kW; x += 4) {
                std::uint16_t mask = static_cast<std::uint16_t>(random());
                for (int i = 0; i < 16; ++i)  // pixels outside the buffer are never covered
                  if (x + (i & 3) >= kW || y + (i >> 2) >= kH) mask = static_cast<std::uint16_t>(mask & ~(1u << i));
                unit_under_test.test_block(plane, x, y, mask, state, k);
                for (int i = 0; i < 16; ++i) {
                  if (!(mask & (1u << i))) continue;
                  const int px = x + (i & 3), py = y + (i >> 2);
                  ++tests;
                  const float z = stored_depth(format, plane.at(px, py, fused));
                  float& stored = want.texels[static_cast<std::size_t>(py * kW + px)];
                  if (!depth_passes(row.f, z, stored)) continue;
                  ++passed;
                  if (state.passed_mask) want_marks[static_cast<std::size_t>(py * kW + px)] = 1;
                  if (write) stored = z, ++written;
                }
              }
            EXPECT_EQ(k.depth_tests, tests);
            EXPECT_EQ(k.passed, passed) << "func " << static_cast<int>(row.f) << " trial " << trial << (fused ? " fused" : " unfused");
            EXPECT_EQ(k.written, written);
            ASSERT_EQ(marks, want_marks) << "passed pixels, func " << static_cast<int>(row.f) << " trial " << trial;
            for (std::size_t t = 0; t < got.texels.size(); ++t)
              ASSERT_EQ(bits(got.texels[t]), bits(want.texels[t])) << "texel " << t << ", func " << static_cast<int>(row.f) << ", trial " << trial;
          }
      }
  }
}

}  // namespace
}  // namespace nbsim::raster

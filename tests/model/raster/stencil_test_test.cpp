// StencilTestTest: the stencil test in front of the early depth test (model/raster/stencil_test.h):
// every func, every op with its clamp or wrap, the masks, GL's order with the depth test, two-sided
// selection through RasterPath (triangle winding, points), a random comparison with a per-pixel
// reference written from the GL specification's wording, and the blocks tested in lanes against
// the same blocks one fragment at a time.
#include "model/raster/stencil_test.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "model/common/error.h"
#include "model/raster/raster_path.h"
#include "tests/model/raster/compare_funcs.h"

namespace nbsim::raster {
namespace {

using geometry::ClipPosition;

// Every func with ref < stored, ref == stored and ref > stored (GL: "LESS passes if ref < stored").
TEST(StencilTestTest, EveryFunc) {
  for (const testing::CompareRow& r : testing::kCompareFuncs) {
    EXPECT_EQ(stencil_passes(r.f, 3, 7, 0xFF), r.below) << "func " << static_cast<int>(r.f) << ", ref 3 stored 7";
    EXPECT_EQ(stencil_passes(r.f, 7, 7, 0xFF), r.equal) << "func " << static_cast<int>(r.f) << ", ref 7 stored 7";
    EXPECT_EQ(stencil_passes(r.f, 200, 7, 0xFF), r.above) << "func " << static_cast<int>(r.f) << ", ref 200 stored 7";
  }
}

// The value mask applies to both ref and stored value before the comparison.
TEST(StencilTestTest, ValueMaskAppliesToBothSides) {
  EXPECT_TRUE(stencil_passes(DepthFunc::Equal, 0x13, 0xF3, 0x0F)) << "only the low nibble is compared";
  EXPECT_FALSE(stencil_passes(DepthFunc::Equal, 0x13, 0xF3, 0xFF));
  EXPECT_TRUE(stencil_passes(DepthFunc::Less, 0x81, 0x02, 0x0F)) << "ref's high bit is masked away: 1 < 2";
  EXPECT_FALSE(stencil_passes(DepthFunc::Less, 0x81, 0x02, 0xFF));
  EXPECT_TRUE(stencil_passes(DepthFunc::Equal, 0xAB, 0x12, 0x00)) << "mask 0: 0 == 0";
}

// Every op, with INCR/DECR clamping at 255/0 and the _WRAP ops wrapping modulo 256.
TEST(StencilTestTest, EveryOpWithClampAndWrap) {
  struct Row {
    StencilOp op;
    std::uint8_t stored, expect;
    const char* why;
  };
  const std::uint8_t ref = 0x5A;
  const Row rows[] = {
      {StencilOp::Keep, 17, 17, "keep"},
      {StencilOp::Zero, 17, 0, "zero"},
      {StencilOp::Replace, 17, ref, "replace with ref"},
      {StencilOp::Incr, 17, 18, "incr"},
      {StencilOp::Incr, 255, 255, "incr clamps at 255"},
      {StencilOp::IncrWrap, 17, 18, "incr_wrap"},
      {StencilOp::IncrWrap, 255, 0, "incr_wrap wraps 255 -> 0"},
      {StencilOp::Decr, 17, 16, "decr"},
      {StencilOp::Decr, 0, 0, "decr clamps at 0"},
      {StencilOp::DecrWrap, 17, 16, "decr_wrap"},
      {StencilOp::DecrWrap, 0, 255, "decr_wrap wraps 0 -> 255"},
      {StencilOp::Invert, 0x0F, 0xF0, "invert"},
      {StencilOp::Invert, 0, 255, "invert 0"},
  };
  for (const Row& r : rows) EXPECT_EQ(stencil_update(r.op, r.stored, ref, 0xFF), r.expect) << r.why;
}

// The write mask keeps the unmasked bits of the old value: new = (old & ~wm) | (op & wm).
TEST(StencilTestTest, WriteMaskKeepsUnmaskedBits) {
  EXPECT_EQ(stencil_update(StencilOp::Replace, 0xF0, 0x0F, 0x03), 0xF3) << "replace through mask 0x03";
  EXPECT_EQ(stencil_update(StencilOp::Zero, 0xFF, 0, 0x0F), 0xF0) << "zero through mask 0x0F";
  EXPECT_EQ(stencil_update(StencilOp::IncrWrap, 0x0F, 0, 0x0F), 0x00) << "incr_wrap 0x0F -> 0x10, low nibble 0";
  EXPECT_EQ(stencil_update(StencilOp::Incr, 0xFF, 0, 0x0F), 0xFF) << "incr clamps on the whole 8 bits, then the mask";
  EXPECT_EQ(stencil_update(StencilOp::DecrWrap, 0x10, 0, 0xF0), 0x00) << "0x10 - 1 = 0x0F, high nibble 0";
  EXPECT_EQ(stencil_update(StencilOp::Invert, 0xAA, 0, 0x00), 0xAA) << "mask 0 writes nothing";
}

// GL's 32-bit state is reduced as Mesa does: ref clamped to [0, 255], masks' low 8 bits.
TEST(StencilTestTest, StateFromTraceClampsRefAndMasks) {
  scene::StencilFace f;
  f.ref = -5;
  f.value_mask = 0x1234F0F0u;
  f.write_mask = 0xFFFFFF0Fu;
  f.func = scene::DepthFunc::Gequal;
  f.fail = scene::StencilOp::Invert;
  StencilFace s = stencil_face(f);
  EXPECT_EQ(s.ref, 0) << "negative ref clamps to 0";
  EXPECT_EQ(s.value_mask, 0xF0);
  EXPECT_EQ(s.write_mask, 0x0F);
  EXPECT_EQ(s.func, DepthFunc::Gequal);
  EXPECT_EQ(s.fail, StencilOp::Invert);
  f.ref = 300;
  EXPECT_EQ(stencil_face(f).ref, 255) << "ref above 255 clamps to 255";
}

// A func or op outside GL's eight is the user's error (InputError), never undefined behaviour.
TEST(StencilTestTest, OutOfRangeEnumsAreRefused) {
  scene::StencilState st;
  st.test = true;
  st.back.depth_fail = static_cast<scene::StencilOp>(8);
  EXPECT_THROW(stencil_state(st), InputError);
  st.back.depth_fail = scene::StencilOp::Keep;
  st.front.func = static_cast<scene::DepthFunc>(9);
  EXPECT_THROW(stencil_state(st), InputError);
}

// One pixel through DepthStencilTest (stored stencil 5, stored depth 0.5, fragment depth 0.25).
struct Pixel {
  std::uint8_t stencil;
  float depth;
  DepthCounters dk;
  StencilCounters sk;
};
Pixel one_pixel(const StencilState& ss, const DepthState& ds, bool front = true, float z = 0.25f) {
  DepthImage depth(4, 4, 0.5f);
  StencilImage stencil(4, 4, 5);
  DepthStencilTest t(depth, stencil);
  Pixel p{};
  t.test_block(DepthPlane{z, 0, 0}, front, 0, 0, 0x0001, ds, ss, p.dk, p.sk);
  p.stencil = stencil.texels[0];
  p.depth = depth.texels[0];
  return p;
}

StencilState ops_state(DepthFunc func, std::uint8_t ref) {
  StencilState s;
  s.test = true;
  s.front.func = func;
  s.front.ref = ref;
  s.front.fail = StencilOp::Replace;     // -> ref
  s.front.depth_fail = StencilOp::Zero;  // -> 0
  s.front.pass = StencilOp::Incr;        // -> 6
  return s;
}

// GL's order: stencil fail -> fail op, no depth test or write, not passed.
TEST(StencilTestTest, StencilFailRunsFailOpOnly) {
  const Pixel p = one_pixel(ops_state(DepthFunc::Never, 9), DepthState{DepthFunc::Less, true, true});
  EXPECT_EQ(p.stencil, 9) << "fail op (replace)";
  EXPECT_EQ(p.depth, 0.5f) << "no depth write after a stencil fail";
  EXPECT_EQ(p.dk.passed, 0u);
  EXPECT_EQ(p.dk.depth_tests, 0u) << "a fragment failing the stencil test reaches no depth test";
  EXPECT_EQ(p.sk.tests, 1u);
  EXPECT_EQ(p.sk.passed, 0u);
  EXPECT_EQ(p.dk.fragments, 1u);
}

// Stencil pass, depth fail -> depth_fail op, no depth write, not passed.
TEST(StencilTestTest, DepthFailRunsDepthFailOp) {
  const Pixel p = one_pixel(ops_state(DepthFunc::Always, 9), DepthState{DepthFunc::Greater, true, true});
  EXPECT_EQ(p.stencil, 0) << "depth_fail op (zero)";
  EXPECT_EQ(p.depth, 0.5f);
  EXPECT_EQ(p.dk.passed, 0u);
  EXPECT_EQ(p.dk.depth_tests, 1u);
  EXPECT_EQ(p.sk.depth_failed, 1u);
}

// Both pass -> pass op and the depth write.
TEST(StencilTestTest, BothPassRunsPassOpAndWritesDepth) {
  const Pixel p = one_pixel(ops_state(DepthFunc::Always, 9), DepthState{DepthFunc::Less, true, true});
  EXPECT_EQ(p.stencil, 6) << "pass op (incr)";
  EXPECT_EQ(p.depth, 0.25f) << "depth written";
  EXPECT_EQ(p.dk.passed, 1u);
  EXPECT_EQ(p.dk.written, 1u);
  EXPECT_EQ(p.sk.written, 1u);
  EXPECT_EQ(p.sk.changed, 1u);
}

// The depth test disabled counts as passed (pass op), and writes no depth.
TEST(StencilTestTest, DepthTestOffCountsAsPass) {
  const Pixel p = one_pixel(ops_state(DepthFunc::Always, 9), DepthState{DepthFunc::Never, false, false});
  EXPECT_EQ(p.stencil, 6) << "pass op although the depth func is NEVER: the test is off";
  EXPECT_EQ(p.depth, 0.5f);
  EXPECT_EQ(p.dk.passed, 1u);
  EXPECT_EQ(p.dk.depth_tests, 0u);
}

// Depth writes off: the pass op still runs, the depth stays.
TEST(StencilTestTest, DepthMaskOffKeepsDepth) {
  const Pixel p = one_pixel(ops_state(DepthFunc::Always, 9), DepthState{DepthFunc::Less, true, false});
  EXPECT_EQ(p.stencil, 6);
  EXPECT_EQ(p.depth, 0.5f);
  EXPECT_EQ(p.dk.written, 0u);
}

// Back-facing fragments use the back state, front-facing ones the front state.
TEST(StencilTestTest, TwoSidedSelectsTheFace) {
  StencilState s = ops_state(DepthFunc::Always, 9);
  s.back.func = DepthFunc::Always;
  s.back.pass = StencilOp::DecrWrap;
  s.back.ref = 0;
  const DepthState ds{DepthFunc::Less, true, true};
  EXPECT_EQ(one_pixel(s, ds, true).stencil, 6) << "front: incr";
  const Pixel back = one_pixel(s, ds, false);
  EXPECT_EQ(back.stencil, 4) << "back: decr_wrap";
  EXPECT_EQ(back.sk.back_facing, 1u);
}

// The stencil test off is the depth test alone, bit for bit, and leaves the stencil buffer alone.
TEST(StencilTestTest, DisabledIsTheDepthTestAlone) {
  std::mt19937 rng(7);
  DepthImage a(8, 8, 0.5f), b(8, 8, 0.5f);
  for (std::size_t i = 0; i < a.texels.size(); ++i) a.texels[i] = b.texels[i] = static_cast<float>(rng() % 9) / 8.0f;
  StencilImage stencil(8, 8, 77);
  EarlyDepthTest alone(a);
  DepthStencilTest both(b, stencil);
  StencilState off = ops_state(DepthFunc::Never, 1);
  off.test = false;
  DepthCounters ka, kb;
  StencilCounters ks;
  for (int k = 0; k < 200; ++k) {
    const DepthPlane plane{static_cast<float>(rng() % 9) / 8.0f, 0.01f * static_cast<float>(rng() % 5), -0.02f};
    const int x = 4 * static_cast<int>(rng() % 2), y = 4 * static_cast<int>(rng() % 2);
    const auto mask = static_cast<std::uint16_t>(rng());
    const DepthState ds{static_cast<DepthFunc>(rng() % 8), rng() % 2 == 0, rng() % 4 != 0};
    alone.test_block(plane, x, y, mask, ds, ka);
    both.test_block(plane, rng() % 2 == 0, x, y, mask, ds, off, kb, ks);
  }
  EXPECT_TRUE(a.texels == b.texels) << "same depth buffer";
  EXPECT_EQ(ka.fragments, kb.fragments);
  EXPECT_EQ(ka.depth_tests, kb.depth_tests);
  EXPECT_EQ(ka.passed, kb.passed);
  EXPECT_EQ(ka.written, kb.written);
  EXPECT_EQ(ks.tests, 0u);
  EXPECT_EQ(stencil.texels, std::vector<std::uint8_t>(64, 77)) << "stencil buffer untouched";
}

// The GL specification's rules, written out per pixel with plain integers, as a reference.
int reference_op(StencilOp op, int s, int ref) {
  switch (op) {
    case StencilOp::Keep: return s;
    case StencilOp::Zero: return 0;
    case StencilOp::Replace: return ref;
    case StencilOp::Incr: return s < 255 ? s + 1 : 255;
    case StencilOp::IncrWrap: return (s + 1) % 256;
    case StencilOp::Decr: return s > 0 ? s - 1 : 0;
    case StencilOp::DecrWrap: return (s + 255) % 256;
    case StencilOp::Invert: return 255 - s;
  }
  return -1;
}
bool reference_compare(DepthFunc f, int a, int b) {
  switch (f) {
    case DepthFunc::Never: return false;
    case DepthFunc::Less: return a < b;
    case DepthFunc::Equal: return a == b;
    case DepthFunc::Lequal: return a <= b;
    case DepthFunc::Greater: return a > b;
    case DepthFunc::NotEqual: return a != b;
    case DepthFunc::Gequal: return a >= b;
    case DepthFunc::Always: return true;
  }
  return false;
}

// Random states and blocks against the per-pixel reference: stencil and depth buffers equal.
TEST(StencilTestTest, RandomBlocksMatchReference) {
  std::mt19937 rng(2024);
  const auto small = [&] { return static_cast<std::uint8_t>(rng() % 4 == 0 ? rng() : rng() % 4); };  // ties often
  const auto face = [&] {
    StencilFace f;
    f.func = static_cast<DepthFunc>(rng() % 8);
    f.ref = small();
    f.value_mask = rng() % 3 == 0 ? static_cast<std::uint8_t>(rng()) : 0xFF;
    f.write_mask = rng() % 3 == 0 ? static_cast<std::uint8_t>(rng()) : 0xFF;
    f.fail = static_cast<StencilOp>(rng() % 8);
    f.depth_fail = static_cast<StencilOp>(rng() % 8);
    f.pass = static_cast<StencilOp>(rng() % 8);
    return f;
  };
  DepthImage depth(8, 8, 0.5f);
  StencilImage stencil(8, 8, 0);
  for (std::size_t i = 0; i < depth.texels.size(); ++i) {
    depth.texels[i] = static_cast<float>(rng() % 5) / 4.0f;
    stencil.texels[i] = small();
  }
  std::vector<float> ref_depth = depth.texels;
  std::vector<int> ref_stencil(stencil.texels.begin(), stencil.texels.end());
  DepthStencilTest t(depth, stencil);
  std::uint64_t ref_passed = 0;
  DepthCounters dk;
  StencilCounters sk;
  for (int k = 0; k < 2000; ++k) {
    StencilState ss;
    ss.test = true;
    ss.front = face();
    ss.back = face();
    const DepthState ds{static_cast<DepthFunc>(rng() % 8), rng() % 2 == 0, rng() % 4 != 0};
    const DepthPlane plane{static_cast<float>(rng() % 5) / 4.0f, 0, 0};  // constant depth: exact
    const bool front = rng() % 2 == 0;
    const int x = 4 * static_cast<int>(rng() % 2), y = 4 * static_cast<int>(rng() % 2);
    const auto mask = static_cast<std::uint16_t>(rng());
    t.test_block(plane, front, x, y, mask, ds, ss, dk, sk);
    const StencilFace& f = front ? ss.front : ss.back;
    for (int i = 0; i < 16; ++i) {
      if (!(mask >> i & 1)) continue;
      const std::size_t at = static_cast<std::size_t>((y + i / 4) * 8 + x + i % 4);
      int& s = ref_stencil[at];
      StencilOp op;
      if (!reference_compare(f.func, f.ref & f.value_mask, s & f.value_mask)) {
        op = f.fail;
      } else if (ds.test && !depth_passes(ds.func, plane.a0, ref_depth[at])) {
        op = f.depth_fail;
      } else {
        op = f.pass;
        ++ref_passed;
        if (ds.test && ds.write) ref_depth[at] = plane.a0;
      }
      s = (s & ~f.write_mask & 0xFF) | (reference_op(op, s, f.ref) & f.write_mask);
    }
  }
  EXPECT_EQ(std::vector<int>(stencil.texels.begin(), stencil.texels.end()), ref_stencil) << "stencil buffer";
  EXPECT_TRUE(depth.texels == ref_depth) << "depth buffer";
  EXPECT_EQ(dk.passed, ref_passed) << "samples passed";
  EXPECT_GT(sk.changed, 0u);
  EXPECT_GT(sk.depth_failed, 0u);
}

// Blocks wholly inside the buffers are tested in lanes (block_lanes.h): the same buffers, bit for
// bit, and the same counts as one fragment at a time, for random states (every func and op, masks),
// sloped planes (fused and not, both depth formats, NaN, -0, ties), the depth test on and off,
// writes on and off, and blocks on the ragged right and top edges (one fragment at a time there).
TEST(StencilTestTest, LanesTestAsOneByOne) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> unit(-0.25f, 1.25f), slope(-0.05f, 0.05f);
  const auto small = [&] { return static_cast<std::uint8_t>(rng() % 4 == 0 ? rng() : rng() % 4); };
  const auto face = [&] {
    StencilFace f;
    f.func = static_cast<DepthFunc>(rng() % 8);
    f.ref = small();
    f.value_mask = rng() % 3 == 0 ? static_cast<std::uint8_t>(rng()) : 0xFF;
    f.write_mask = rng() % 4 == 0 ? static_cast<std::uint8_t>(rng() % 2 == 0 ? 0 : rng()) : 0xFF;
    f.fail = static_cast<StencilOp>(rng() % 8);
    f.depth_fail = static_cast<StencilOp>(rng() % 8);
    f.pass = static_cast<StencilOp>(rng() % 8);
    return f;
  };
  const auto bits = [](float v) { return std::bit_cast<std::uint32_t>(v); };
  constexpr int kW = 14, kH = 10;  // not multiples of 4: the last column and row of blocks are ragged
  std::uint64_t changed = 0, depth_failed = 0, written = 0;
  for (const DepthFormat format : {DepthFormat::Float32, DepthFormat::Unorm24})
    for (const bool fused : {true, false}) {
      DepthImage depth_a(kW, kH, 0.5f);
      StencilImage stencil_a(kW, kH, 0);
      for (std::size_t i = 0; i < depth_a.texels.size(); ++i) {
        const int pick = static_cast<int>(rng() % 8);
        depth_a.texels[i] = pick == 0 ? NAN : pick == 1 ? 0.5f : stored_depth(format, std::clamp(unit(rng), 0.0f, 1.0f));
        stencil_a.texels[i] = small();
      }
      DepthImage depth_b = depth_a;
      StencilImage stencil_b = stencil_a;
      DepthStencilTest lanes(depth_a, stencil_a, fused, format), one_by_one(depth_b, stencil_b, fused, format);
      one_by_one.set_lanes(false);
      DepthCounters dka, dkb;
      StencilCounters ska, skb;
      for (int trial = 0; trial < 600; ++trial) {
        StencilState ss;
        ss.test = true;
        ss.front = face();
        ss.back = face();
        const DepthState ds{static_cast<DepthFunc>(rng() % 8), rng() % 4 != 0, rng() % 3 != 0};
        DepthPlane plane{unit(rng), slope(rng), slope(rng)};
        if (trial % 17 == 0) plane = DepthPlane{NAN, 0.0f, 0.0f};
        if (trial % 19 == 0) plane = DepthPlane{-0.0f, 0.0f, 0.0f};
        if (trial % 23 == 0) plane = DepthPlane{0.5f, 0.0f, 0.0f};  // ties with the stored 0.5s
        const bool front = rng() % 2 == 0;
        const int x = 4 * static_cast<int>(rng() % 4), y = 4 * static_cast<int>(rng() % 3);
        auto mask = static_cast<std::uint16_t>(rng());
        for (int i = 0; i < 16; ++i)  // pixels outside the buffers are never covered
          if (x + (i & 3) >= kW || y + (i >> 2) >= kH) mask = static_cast<std::uint16_t>(mask & ~(1u << i));
        lanes.test_block(plane, front, x, y, mask, ds, ss, dka, ska);
        one_by_one.test_block(plane, front, x, y, mask, ds, ss, dkb, skb);
        ASSERT_EQ(stencil_a.texels, stencil_b.texels) << "trial " << trial << (fused ? " fused" : " unfused");
        for (std::size_t t = 0; t < depth_a.texels.size(); ++t)
          ASSERT_EQ(bits(depth_a.texels[t]), bits(depth_b.texels[t])) << "texel " << t << ", trial " << trial;
      }
      // fragments, blocks, depth tests, passed, depth written; stencil tests, passed, depth failed,
      // back facing, written, changed
      const auto counts = [](const DepthCounters& d, const StencilCounters& k) {
        return std::array{d.fragments, d.blocks, d.depth_tests, d.passed, d.written, k.tests, k.passed, k.depth_failed, k.back_facing, k.written, k.changed};
      };
      EXPECT_EQ(counts(dka, ska), counts(dkb, skb)) << (fused ? "fused" : "unfused");
      changed += ska.changed, depth_failed += ska.depth_failed, written += dka.written;
    }
  EXPECT_GT(changed, 1000u);
  EXPECT_GT(depth_failed, 1000u);
  EXPECT_GT(written, 1000u);
}

// Through RasterPath: a triangle counter-clockwise in window space (y up) is front-facing under
// glFrontFace(GL_CCW), a clockwise one back-facing, and GL_CW swaps them; points are front-facing.
TEST(StencilTestTest, RasterPathFacingFromWindingAndPoints) {
  RasterPathConfig cfg;
  cfg.width_px = 16;
  cfg.height_px = 16;
  StencilState ss;
  ss.test = true;
  ss.front.pass = StencilOp::Replace;
  ss.front.ref = 1;
  ss.back.pass = StencilOp::Replace;
  ss.back.ref = 2;
  const std::vector<ClipPosition> ccw = {{-1, -1, 0, 1}, {1, -1, 0, 1}, {-1, 1, 0, 1}};  // lower-left half, CCW
  const std::vector<ClipPosition> cw = {{1, -1, 0, 1}, {-1, 1, 0, 1}, {1, 1, 0, 1}};     // upper-right half, CW
  for (const bool front_ccw : {true, false}) {
    DepthImage depth(16, 16, 1.0f);
    StencilImage stencil(16, 16, 0);
    RasterPath path(cfg, depth, stencil);
    DrawState st;
    st.geometry.face.cull = geometry::CullFace::None;
    st.geometry.face.front_ccw = front_ccw;
    st.depth = DepthState{DepthFunc::Always, false, true};
    st.stencil = ss;
    const DrawCounters a = path.draw(ccw, st);
    const DrawCounters b = path.draw(cw, st);
    EXPECT_EQ(a.stencil.back_facing, front_ccw ? 0u : a.stencil.tests);
    EXPECT_EQ(b.stencil.back_facing, front_ccw ? b.stencil.tests : 0u);
    EXPECT_EQ(stencil.at(1, 1), front_ccw ? 1 : 2) << "CCW triangle, front_ccw " << front_ccw;
    EXPECT_EQ(stencil.at(14, 14), front_ccw ? 2 : 1) << "CW triangle, front_ccw " << front_ccw;
    const std::vector<ClipPosition> point = {{0.0625f, 0.0625f, 0, 1}};  // window (8.5, 8.5): pixel (8, 8)'s centre
    const std::vector<float> size = {1.0f};
    st.geometry.face.front_ccw = front_ccw;
    ss.front.ref = 3;
    st.stencil = ss;
    path.draw_points(point, size, st);
    EXPECT_EQ(stencil.at(8, 8), 3) << "a point uses the front state, front_ccw " << front_ccw;
    ss.front.ref = 1;
  }
}

}  // namespace
}  // namespace nbsim::raster

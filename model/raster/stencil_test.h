// Stencil test: GL's stencil test and stencil operations on an 8-bit stencil buffer (StencilImage,
// y up like DepthImage), combined with the early depth test (depth_test.h) in GL's order, on the
// 4x4 blocks of the rasterizer. The face a fragment uses comes from triangle setup (SetupTriangle::
// front_facing: the sign of the snapped window-space area and glFrontFace, as llvmpipe decides it
// for culling); point sprites are always front-facing (lp_setup_point.c).
//
// Per fragment, as GL specifies and lp_bld_depth.c builds it (Mesa 22.3):
//   stencil test fails                  -> face.fail op; no depth test, no depth write, not passed
//   stencil passes, depth test fails    -> face.depth_fail op; no depth write, not passed
//   stencil passes, depth passes (or the depth test is disabled)
//                                       -> face.pass op; depth written when enabled; passed
// The test compares (ref & value_mask) with (stored & value_mask) (LESS passes when ref < stored);
// an op's result is written through write_mask: new = (old & ~write_mask) | (op & write_mask).
// INCR and DECR clamp at 255 and 0, INCR_WRAP and DECR_WRAP wrap modulo 256, INVERT is ~old.
// GL clamps ref to [0, 255] and uses the low 8 bits of both masks (st_atom_depth.c,
// _mesa_get_stencil_ref); stencil_face() does the same. With the stencil test disabled the
// stencil buffer is neither read nor written and the depth test runs alone (EarlyDepthTest,
// bit for bit the depth-only path).
//
// Early tests, discard and gl_FragDepth (lp_state_fs.c generate_fs_loop, Mesa 22.3): llvmpipe runs
// depth and stencil together, early (before the shader) unless the shader writes depth, has
// early_fragment_tests off and side effects, or may discard while the stencil buffer can be
// written (a nonzero write mask on an enabled face): then both run late, after the shader, on
// the fragments it kept and with the depth it wrote. A discarding shader with no stencil write
// keeps the early test and defers only the depth write. In every case the stored result is GL's:
// a discarded fragment updates neither buffer and is not counted by GL_SAMPLES_PASSED. The model
// has no fragment shader: it tests every rasterized fragment at its interpolated depth, so a draw
// with DrawRecord::discards or writes_depth can only be matched when the shader kept every
// fragment and wrote the interpolated depth. The depth unit counts such draws under the stencil
// test (stencil_draws_unmodelled) instead of pretending they are exact.
#pragma once

#include <cstdint>
#include <vector>

#include "model/common/depth.h"
#include "model/raster/depth_test.h"
#include "model/raster/setup.h"
#include "model/scene/frame.h"

namespace nbsim::raster {

// Fixed by the design being matched: GL's stencil buffer on llvmpipe (S8 of DEPTH24_STENCIL8 and
// DEPTH32F_STENCIL8) has 8 bits.
constexpr int kStencilBits = 8;
constexpr std::uint8_t kStencilMax = 0xFF;

// GL's stencil operations in GL's order. Fixed values, equal to scene::StencilOp.
enum class StencilOp : std::uint8_t { Keep = 0, Zero = 1, Replace = 2, Incr = 3, IncrWrap = 4, Decr = 5, DecrWrap = 6, Invert = 7 };

// One face's stencil state as the hardware sees it: ref and masks already reduced to 8 bits.
struct StencilFace {
  DepthFunc func = DepthFunc::Always;
  std::uint8_t ref = 0;
  std::uint8_t value_mask = kStencilMax;
  std::uint8_t write_mask = kStencilMax;
  StencilOp fail = StencilOp::Keep;
  StencilOp depth_fail = StencilOp::Keep;
  StencilOp pass = StencilOp::Keep;
};

struct StencilState {
  bool test = false;  // GL_STENCIL_TEST
  StencilFace front, back;
  const StencilFace& face(bool front_facing) const noexcept { return front_facing ? front : back; }
};

// GL's state of a draw reduced to what the unit uses: ref clamped to [0, 255], masks' low 8 bits.
// Throws InputError for a func or op outside GL's eight (a record that did not come from a
// checked trace).
StencilFace stencil_face(const scene::StencilFace& face);
StencilState stencil_state(const scene::StencilState& state);

// True when a fragment passes the stencil test against the stored value.
constexpr bool stencil_passes(DepthFunc func, std::uint8_t ref, std::uint8_t stored, std::uint8_t value_mask) noexcept {
  const unsigned r = ref & value_mask, s = stored & value_mask;
  switch (func) {
    case DepthFunc::Never: return false;
    case DepthFunc::Less: return r < s;
    case DepthFunc::Equal: return r == s;
    case DepthFunc::Lequal: return r <= s;
    case DepthFunc::Greater: return r > s;
    case DepthFunc::NotEqual: return r != s;
    case DepthFunc::Gequal: return r >= s;
    case DepthFunc::Always: return true;
  }
  return false;
}

// The value `op` produces from `stored`, before the write mask.
constexpr std::uint8_t stencil_op_result(StencilOp op, std::uint8_t stored, std::uint8_t ref) noexcept {
  switch (op) {
    case StencilOp::Keep: return stored;
    case StencilOp::Zero: return 0;
    case StencilOp::Replace: return ref;
    case StencilOp::Incr: return stored == kStencilMax ? kStencilMax : static_cast<std::uint8_t>(stored + 1);
    case StencilOp::IncrWrap: return static_cast<std::uint8_t>(stored + 1);
    case StencilOp::Decr: return stored == 0 ? 0 : static_cast<std::uint8_t>(stored - 1);
    case StencilOp::DecrWrap: return static_cast<std::uint8_t>(stored - 1);
    case StencilOp::Invert: return static_cast<std::uint8_t>(~stored);
  }
  return stored;
}

// The stored value after `op` through the write mask.
constexpr std::uint8_t stencil_update(StencilOp op, std::uint8_t stored, std::uint8_t ref, std::uint8_t write_mask) noexcept {
  return static_cast<std::uint8_t>((stored & ~write_mask) | (stencil_op_result(op, stored, ref) & write_mask));
}

// An 8-bit stencil image, y up, row-major (index = y * width + x), like DepthImage.
struct StencilImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> texels;

  StencilImage() = default;
  StencilImage(int w, int h, std::uint8_t fill);
  std::uint8_t at(int x, int y) const { return texels[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)]; }
};

// Per-draw counters of the stencil test (added to, never reset, by the unit). Zero for draws
// without the stencil test.
struct StencilCounters {
  std::uint64_t tests = 0;        // stencil comparisons: one per rasterized fragment of a draw with the test on
  std::uint64_t passed = 0;       // fragments passing the stencil test (they go on to the depth test)
  std::uint64_t depth_failed = 0; // passed the stencil test, failed the depth test (depth_fail op)
  std::uint64_t back_facing = 0;  // fragments tested with the back face's state
  std::uint64_t written = 0;      // stencil values stored: an op other than KEEP with a nonzero write mask
  std::uint64_t changed = 0;      // of those, values that differ from the one read
  StencilCounters& operator+=(const StencilCounters& o);
};

// The early depth test with the stencil test in front of it, on one depth and one stencil buffer.
class DepthStencilTest {
 public:
  // Tests against and writes to `depth` and `stencil`, which must have the same size and outlive
  // the unit. Throws InputError when the sizes differ.
  DepthStencilTest(DepthImage& depth, StencilImage& stencil, bool fused_interpolation = true,
                   DepthFormat format = DepthFormat::Float32);

  // Tests the pixels of `mask` in the 4x4 block at (x, y) (bit i + 4 j is pixel (x + i, y + j),
  // inside the buffers) of a primitive facing `front_facing`. With stencil.test false this is
  // EarlyDepthTest::test_block and the stencil buffer is not touched.
  void test_block(const DepthPlane& plane, bool front_facing, int x, int y, std::uint16_t mask, const DepthState& depth,
                  const StencilState& stencil, DepthCounters& depth_counters, StencilCounters& stencil_counters);

  DepthImage& depth() noexcept { return depth_test_.buffer(); }
  StencilImage& stencil() noexcept { return *stencil_; }
  bool fused_interpolation() const noexcept { return depth_test_.fused_interpolation(); }
  DepthFormat depth_format() const noexcept { return depth_test_.format(); }
  void set_depth_format(DepthFormat format) noexcept { depth_test_.set_format(format); }
  // Whether blocks wholly inside the buffers are tested in SSE lanes where the host has them (the
  // default; the same results as one fragment at a time, which false forces, for the tests that
  // compare the two).
  void set_lanes(bool lanes) noexcept { lanes_ = lanes; }

 private:
  EarlyDepthTest depth_test_;
  StencilImage* stencil_;
  bool lanes_ = true;
};

}  // namespace nbsim::raster

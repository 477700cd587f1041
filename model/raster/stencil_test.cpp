// Stencil test in front of the early depth test, on 4x4 blocks; see stencil_test.h.
#include "model/raster/stencil_test.h"

#include <algorithm>
#include <bit>
#include <string>

#include "model/common/error.h"

namespace nbsim::raster {

namespace {

StencilOp checked_op(scene::StencilOp op, const char* which) {
  if (static_cast<unsigned>(op) > static_cast<unsigned>(scene::StencilOp::Invert))
    throw InputError(std::string("stencil state: ") + which + " op " + std::to_string(static_cast<unsigned>(op)) +
                     " is not one of GL's eight (0..7: keep, zero, replace, incr, incr_wrap, decr, decr_wrap, invert)");
  return static_cast<StencilOp>(op);
}

}  // namespace

StencilFace stencil_face(const scene::StencilFace& f) {
  if (static_cast<unsigned>(f.func) > static_cast<unsigned>(scene::DepthFunc::Always))
    throw InputError("stencil state: func " + std::to_string(static_cast<unsigned>(f.func)) +
                     " is not one of GL's eight (0..7: never, less, equal, lequal, greater, notequal, gequal, always)");
  StencilFace out;
  out.func = static_cast<DepthFunc>(f.func);
  out.ref = static_cast<std::uint8_t>(std::clamp<std::int32_t>(f.ref, 0, kStencilMax));
  out.value_mask = static_cast<std::uint8_t>(f.value_mask & kStencilMax);
  out.write_mask = static_cast<std::uint8_t>(f.write_mask & kStencilMax);
  out.fail = checked_op(f.fail, "fail");
  out.depth_fail = checked_op(f.depth_fail, "depth_fail");
  out.pass = checked_op(f.pass, "pass");
  return out;
}

StencilState stencil_state(const scene::StencilState& s) {
  StencilState out;
  out.test = s.test;
  out.front = stencil_face(s.front);
  out.back = stencil_face(s.back);
  return out;
}

StencilImage::StencilImage(int w, int h, std::uint8_t fill)
    : width(w), height(h), texels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), fill) {}

StencilCounters& StencilCounters::operator+=(const StencilCounters& o) {
  tests += o.tests;
  passed += o.passed;
  depth_failed += o.depth_failed;
  back_facing += o.back_facing;
  written += o.written;
  changed += o.changed;
  return *this;
}

DepthStencilTest::DepthStencilTest(DepthImage& depth, StencilImage& stencil, bool fused_interpolation, DepthFormat format)
    : depth_test_(depth, fused_interpolation, format), stencil_(&stencil) {
  if (stencil.width != depth.width || stencil.height != depth.height ||
      stencil.texels.size() != static_cast<std::size_t>(depth.width) * static_cast<std::size_t>(depth.height))
    throw InputError("stencil test: stencil buffer " + std::to_string(stencil.width) + "x" + std::to_string(stencil.height) +
                     " does not match the depth buffer " + std::to_string(depth.width) + "x" + std::to_string(depth.height));
}

// An FMA clone on x86-64, as the plain depth test's (depth_test.cpp): the depth plane's std::fma
// becomes one instruction instead of a call to libm's fmaf, with the same bits.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
[[gnu::target_clones("fma", "default")]]
#endif
void DepthStencilTest::test_block(const DepthPlane& plane, bool front_facing, int x, int y, std::uint16_t mask,
                                  const DepthState& ds, const StencilState& ss, DepthCounters& dk, StencilCounters& sk) {
  if (!ss.test) {
    depth_test_.test_block(plane, x, y, mask, ds, dk);
    return;
  }
  if (mask == 0) return;
  NBSIM_CHECK(!ds.peel_layer && !ds.passed_mask, "the peel compare is not modelled with the stencil test on");
  const auto n = static_cast<std::uint64_t>(std::popcount(static_cast<unsigned>(mask)));
  dk.fragments += n;
  dk.blocks += 1;
  sk.tests += n;
  if (!front_facing) sk.back_facing += n;
  const StencilFace& f = ss.face(front_facing);
  DepthImage& depth = depth_test_.buffer();
  const bool fused = depth_test_.fused_interpolation();
  const bool depth_write = ds.test && ds.write;
  const auto store = [&](std::uint8_t& s, StencilOp op) {
    if (op == StencilOp::Keep || f.write_mask == 0) return;
    const std::uint8_t v = stencil_update(op, s, f.ref, f.write_mask);
    ++sk.written;
    if (v != s) ++sk.changed;
    s = v;
  };
  for (unsigned m = mask; m != 0; m &= m - 1) {
    const int i = std::countr_zero(m);
    const int px = x + (i & 3), py = y + (i >> 2);
    const std::size_t at = static_cast<std::size_t>(py) * static_cast<std::size_t>(depth.width) + static_cast<std::size_t>(px);
    std::uint8_t& s = stencil_->texels[at];
    if (!stencil_passes(f.func, f.ref, s, f.value_mask)) {
      store(s, f.fail);
      continue;
    }
    ++sk.passed;
    if (ds.test) {
      ++dk.depth_tests;
      const float z = stored_depth(depth_test_.format(), plane.at(px, py, fused));
      if (!depth_passes(ds.func, z, depth.texels[at])) {
        ++sk.depth_failed;
        store(s, f.depth_fail);
        continue;
      }
      if (depth_write) {
        depth.texels[at] = z;
        ++dk.written;
      }
    }
    ++dk.passed;
    store(s, f.pass);
  }
}

}  // namespace nbsim::raster

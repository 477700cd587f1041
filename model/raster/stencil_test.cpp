// Stencil test in front of the early depth test, on 4x4 blocks; see stencil_test.h.
#include "model/raster/stencil_test.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <string>

#include "model/common/error.h"
#include "model/raster/block_lanes.h"

namespace nbsim::raster {

namespace {

StencilOp checked_op(scene::StencilOp op, const char* which) {
  if (static_cast<unsigned>(op) > static_cast<unsigned>(scene::StencilOp::Invert))
    throw InputError(std::string("stencil state: ") + which + " op " + std::to_string(static_cast<unsigned>(op)) +
                     " is not one of GL's eight (0..7: keep, zero, replace, incr, incr_wrap, decr, decr_wrap, invert)");
  return static_cast<StencilOp>(op);
}

// A block's counts, kept in locals and added to the draw's once: a stencil value is a byte, and a
// store through a byte may alias anything, so counters in memory would be reloaded and stored again
// at every fragment.
struct BlockCounts {
  std::uint64_t passed = 0, depth_failed = 0, written = 0, changed = 0, depth_tests = 0, depth_written = 0, depth_passed = 0;
  void add_to(DepthCounters& dk, StencilCounters& sk) const {
    sk.passed += passed, sk.depth_failed += depth_failed, sk.written += written, sk.changed += changed;
    dk.depth_tests += depth_tests, dk.written += depth_written, dk.passed += depth_passed;
  }
};

#ifdef NBSIM_BLOCK_LANES
// A 4x4 block wholly inside the buffers in SSE lanes: the stencil values as 16 bytes (byte i is pixel
// i of the block's mask, rows of four), the depths as four rows of four floats (block_lanes.h).
// Every fragment of the block is a pixel of its own, so the per-fragment order of test_block's loop
// does not matter: the same tests, ops, writes and counts.

// The stencil test of 16 bytes: (ref & value_mask) against (stored & value_mask), unsigned.
inline __m128i stencil_lanes_pass(DepthFunc func, __m128i ref, __m128i stored) {
  const __m128i eq = _mm_cmpeq_epi8(ref, stored);
  const __m128i ref_le = _mm_cmpeq_epi8(_mm_min_epu8(ref, stored), ref);  // ref <= stored
  const __m128i ref_ge = _mm_cmpeq_epi8(_mm_max_epu8(ref, stored), ref);  // ref >= stored
  const __m128i all = _mm_set1_epi8(-1);
  switch (func) {
    case DepthFunc::Never: return _mm_setzero_si128();
    case DepthFunc::Less: return _mm_andnot_si128(eq, ref_le);
    case DepthFunc::Equal: return eq;
    case DepthFunc::Lequal: return ref_le;
    case DepthFunc::Greater: return _mm_andnot_si128(eq, ref_ge);
    case DepthFunc::NotEqual: return _mm_xor_si128(eq, all);
    case DepthFunc::Gequal: return ref_ge;
    case DepthFunc::Always: return all;
  }
  return _mm_setzero_si128();
}

// stencil_op_result of 16 bytes.
inline __m128i stencil_lanes_op(StencilOp op, __m128i stored, std::uint8_t ref) {
  const __m128i one = _mm_set1_epi8(1);
  switch (op) {
    case StencilOp::Keep: return stored;
    case StencilOp::Zero: return _mm_setzero_si128();
    case StencilOp::Replace: return _mm_set1_epi8(static_cast<char>(ref));
    case StencilOp::Incr: return _mm_adds_epu8(stored, one);
    case StencilOp::IncrWrap: return _mm_add_epi8(stored, one);
    case StencilOp::Decr: return _mm_subs_epu8(stored, one);
    case StencilOp::DecrWrap: return _mm_sub_epi8(stored, one);
    case StencilOp::Invert: return _mm_xor_si128(stored, _mm_set1_epi8(-1));
  }
  return stored;
}

inline std::uint64_t count_bytes(__m128i mask) { return static_cast<std::uint64_t>(std::popcount(static_cast<unsigned>(_mm_movemask_epi8(mask)))); }

template <DepthFunc F>
void stencil_lanes_block(DepthImage& depth, StencilImage& stencil, const __m128 (&raw)[4], int x, int y, std::uint16_t mask,
                         const DepthState& ds, const StencilFace& f, DepthFormat format, BlockCounts& c) {
  const auto width = static_cast<std::size_t>(depth.width);
  std::uint8_t* const s_at = stencil.texels.data() + static_cast<std::size_t>(y) * width + static_cast<std::size_t>(x);
  float* const d_at = depth.texels.data() + static_cast<std::size_t>(y) * width + static_cast<std::size_t>(x);
  std::int32_t rows[4];
  for (std::size_t r = 0; r < 4; ++r) std::memcpy(&rows[r], s_at + r * width, sizeof rows[r]);
  const __m128i stored = _mm_setr_epi32(rows[0], rows[1], rows[2], rows[3]);
  // The pixels of the mask as bytes: bit i of the mask in byte i.
  const __m128i spread = _mm_shuffle_epi8(_mm_cvtsi32_si128(mask), _mm_setr_epi8(0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1));
  const __m128i bit = _mm_setr_epi8(1, 2, 4, 8, 16, 32, 64, -128, 1, 2, 4, 8, 16, 32, 64, -128);
  const __m128i live = _mm_cmpeq_epi8(_mm_and_si128(spread, bit), bit);
  const __m128i value_mask = _mm_set1_epi8(static_cast<char>(f.value_mask));
  const __m128i spass = _mm_and_si128(live, stencil_lanes_pass(f.func, _mm_set1_epi8(static_cast<char>(f.ref & f.value_mask)),
                                                               _mm_and_si128(stored, value_mask)));
  // The depth test of the fragments past the stencil test (all of them pass when it is off).
  __m128i dpass = _mm_set1_epi8(-1);
  __m128 z[4];
  if (ds.test) {
    __m128i rows_pass[4];
    for (int r = 0; r < 4; ++r) {
      z[r] = lanes::stored_lanes(raw[r], format);
      rows_pass[r] = _mm_castps_si128(lanes::passes<F>(z[r], _mm_loadu_ps(d_at + static_cast<std::size_t>(r) * width)));
    }
    dpass = _mm_packs_epi16(_mm_packs_epi32(rows_pass[0], rows_pass[1]), _mm_packs_epi32(rows_pass[2], rows_pass[3]));
  }
  const __m128i sfail = _mm_andnot_si128(spass, live), dfail = _mm_andnot_si128(dpass, spass), pass = _mm_and_si128(spass, dpass);
  // The ops through the write mask, where they write (an op other than KEEP, a nonzero mask).
  __m128i value = stored, written = _mm_setzero_si128();
  if (f.write_mask != 0) {
    const auto apply = [&](StencilOp op, __m128i where) {
      if (op == StencilOp::Keep) return;
      value = _mm_blendv_epi8(value, stencil_lanes_op(op, stored, f.ref), where);
      written = _mm_or_si128(written, where);
    };
    apply(f.fail, sfail);
    apply(f.depth_fail, dfail);
    apply(f.pass, pass);
    const __m128i write_mask = _mm_set1_epi8(static_cast<char>(f.write_mask));
    value = _mm_or_si128(_mm_andnot_si128(write_mask, stored), _mm_and_si128(value, write_mask));
  }
  const std::uint64_t stencil_passed = count_bytes(spass), depth_passed = count_bytes(pass);
  c.passed += stencil_passed;
  c.depth_failed += count_bytes(dfail);
  c.depth_passed += depth_passed;
  if (ds.test) c.depth_tests += stencil_passed;
  const std::uint64_t stencil_written = count_bytes(written);
  if (stencil_written != 0) {
    c.written += stencil_written;
    c.changed += count_bytes(_mm_andnot_si128(_mm_cmpeq_epi8(value, stored), written));
    alignas(16) std::int32_t out[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(out), value);
    for (std::size_t r = 0; r < 4; ++r) std::memcpy(s_at + r * width, &out[r], sizeof out[r]);
  }
  if (ds.test && ds.write && depth_passed != 0) {
    c.depth_written += depth_passed;
    const __m128i rows_pass[4] = {_mm_cvtepi8_epi32(pass), _mm_cvtepi8_epi32(_mm_srli_si128(pass, 4)), _mm_cvtepi8_epi32(_mm_srli_si128(pass, 8)),
                                  _mm_cvtepi8_epi32(_mm_srli_si128(pass, 12))};
    for (int r = 0; r < 4; ++r) {
      const __m128 row_pass = _mm_castsi128_ps(rows_pass[r]);
      float* row = d_at + static_cast<std::size_t>(r) * width;
      _mm_storeu_ps(row, _mm_or_ps(_mm_and_ps(row_pass, z[r]), _mm_andnot_ps(row_pass, _mm_loadu_ps(row))));
    }
  }
}
#endif

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
  BlockCounts c;
#ifdef NBSIM_BLOCK_LANES
  if (lanes_ && lanes::block_fits(depth, x, y, fused)) {
    __m128 raw[4];
    if (fused) lanes::plane_rows_fused(plane, x, y, raw);  // (called here: inlined into the FMA clone)
    else lanes::plane_rows_unfused(plane, x, y, raw);
    const DepthFormat format = depth_test_.format();
    switch (ds.test ? ds.func : DepthFunc::Always) {
      case DepthFunc::Never: stencil_lanes_block<DepthFunc::Never>(depth, *stencil_, raw, x, y, mask, ds, f, format, c); break;
      case DepthFunc::Less: stencil_lanes_block<DepthFunc::Less>(depth, *stencil_, raw, x, y, mask, ds, f, format, c); break;
      case DepthFunc::Equal: stencil_lanes_block<DepthFunc::Equal>(depth, *stencil_, raw, x, y, mask, ds, f, format, c); break;
      case DepthFunc::Lequal: stencil_lanes_block<DepthFunc::Lequal>(depth, *stencil_, raw, x, y, mask, ds, f, format, c); break;
      case DepthFunc::Greater: stencil_lanes_block<DepthFunc::Greater>(depth, *stencil_, raw, x, y, mask, ds, f, format, c); break;
      case DepthFunc::NotEqual: stencil_lanes_block<DepthFunc::NotEqual>(depth, *stencil_, raw, x, y, mask, ds, f, format, c); break;
      case DepthFunc::Gequal: stencil_lanes_block<DepthFunc::Gequal>(depth, *stencil_, raw, x, y, mask, ds, f, format, c); break;
      case DepthFunc::Always: stencil_lanes_block<DepthFunc::Always>(depth, *stencil_, raw, x, y, mask, ds, f, format, c); break;
    }
    c.add_to(dk, sk);
    return;
  }
#endif
  const auto store = [&](std::uint8_t& s, StencilOp op) {
    if (op == StencilOp::Keep || f.write_mask == 0) return;
    const std::uint8_t v = stencil_update(op, s, f.ref, f.write_mask);
    ++c.written;
    if (v != s) ++c.changed;
    s = v;
  };
  std::uint8_t* const stencil = stencil_->texels.data();
  float* const depths = depth.texels.data();
  const auto width = static_cast<std::size_t>(depth.width);
  for (unsigned m = mask; m != 0; m &= m - 1) {
    const int i = std::countr_zero(m);
    const int px = x + (i & 3), py = y + (i >> 2);
    const std::size_t at = static_cast<std::size_t>(py) * width + static_cast<std::size_t>(px);
    std::uint8_t& s = stencil[at];
    if (!stencil_passes(f.func, f.ref, s, f.value_mask)) {
      store(s, f.fail);
      continue;
    }
    ++c.passed;
    if (ds.test) {
      ++c.depth_tests;
      const float z = stored_depth(depth_test_.format(), plane.at(px, py, fused));
      if (!depth_passes(ds.func, z, depths[at])) {
        ++c.depth_failed;
        store(s, f.depth_fail);
        continue;
      }
      if (depth_write) {
        depths[at] = z;
        ++c.depth_written;
      }
    }
    ++c.depth_passed;
    store(s, f.pass);
  }
  c.add_to(dk, sk);
}

}  // namespace nbsim::raster

// Early depth test on 4x4 blocks against a float DepthImage; see depth_test.h.
#include "model/raster/depth_test.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "model/common/error.h"
#include "model/raster/block_lanes.h"

// The plain depth-test loop gets an FMA clone next to the baseline one on x86-64 (picked when the
// program loads): the depth plane's fused evaluation (DepthPlane::raw_at, std::fma) is then one
// instruction instead of a call to libm's fmaf per fragment (a fifth of the loop's time). Both give
// the same bits: fmaf is the correctly rounded fused operation either way.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define NBSIM_FMA_CLONES [[gnu::target_clones("fma", "default")]]
#else
#define NBSIM_FMA_CLONES
#endif

namespace nbsim::raster {

namespace {

template <DepthFunc F>
[[gnu::always_inline]] inline void run_block(DepthImage& img, const DepthPlane& plane, int x, int y, std::uint16_t mask, bool write, bool fused,
               DepthFormat format, std::uint8_t* passed_mask, DepthCounters& k) {
  std::uint64_t passed = 0, written = 0;
  for (unsigned m = mask; m != 0; m &= m - 1) {
    const int i = std::countr_zero(m);
    const int px = x + (i & 3), py = y + (i >> 2);
    const float z = stored_depth(format, plane.at(px, py, fused));
    const std::size_t at = static_cast<std::size_t>(py) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(px);
    float& stored = img.texels[at];
    if (depth_passes(F, z, stored)) {
      ++passed;
      if (passed_mask) passed_mask[at] = 1;
      if (write) {
        stored = z;
        ++written;
      }
    }
  }
  k.passed += passed;
  k.written += written;
}

#ifdef NBSIM_BLOCK_LANES
// A 4x4 block wholly inside the buffer, four pixels a row in SSE lanes (block_lanes.h): the same
// passes and writes as run_block.
template <DepthFunc F>
void lanes_block(DepthImage& img, const __m128 (&raw)[4], int x, int y, std::uint16_t mask, bool write, DepthFormat format,
                 std::uint8_t* passed_mask, DepthCounters& k) {
  std::uint64_t passed = 0;
  for (int r = 0; r < 4; ++r) {
    if (((mask >> (4 * r)) & 0xFu) == 0) continue;
    const __m128 z = lanes::stored_lanes(raw[r], format);
    float* row = img.texels.data() + static_cast<std::size_t>(y + r) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(x);
    const __m128 stored = _mm_loadu_ps(row);
    const __m128 pass = _mm_and_ps(lanes::passes<F>(z, stored), lanes::row_lanes(mask, r));
    const int pass_bits = _mm_movemask_ps(pass);
    passed += static_cast<std::uint64_t>(std::popcount(static_cast<unsigned>(pass_bits)));
    if (write && pass_bits != 0) _mm_storeu_ps(row, _mm_or_ps(_mm_and_ps(pass, z), _mm_andnot_ps(pass, stored)));
    if (passed_mask && pass_bits != 0) {  // a byte 1 for each passing pixel of the row
      std::uint8_t* marks = passed_mask + static_cast<std::size_t>(y + r) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(x);
      for (unsigned b = static_cast<unsigned>(pass_bits); b != 0; b &= b - 1) marks[std::countr_zero(b)] = 1;
    }
  }
  k.passed += passed;
  if (write) k.written += passed;
}
#endif

NBSIM_FMA_CLONES void test_plain_block(DepthImage& img, const DepthPlane& plane, int x, int y, std::uint16_t mask, DepthFunc func,
                                       bool w, bool fused, DepthFormat format, std::uint8_t* passed, DepthCounters& k) {
#ifdef NBSIM_BLOCK_LANES
  if (lanes::block_fits(img, x, y, fused)) {
    __m128 raw[4];
    if (fused) lanes::plane_rows_fused(plane, x, y, raw);  // (called here: inlined into the FMA clone)
    else lanes::plane_rows_unfused(plane, x, y, raw);
    switch (func) {
      case DepthFunc::Never: break;
      case DepthFunc::Less: lanes_block<DepthFunc::Less>(img, raw, x, y, mask, w, format, passed, k); break;
      case DepthFunc::Equal: lanes_block<DepthFunc::Equal>(img, raw, x, y, mask, w, format, passed, k); break;
      case DepthFunc::Lequal: lanes_block<DepthFunc::Lequal>(img, raw, x, y, mask, w, format, passed, k); break;
      case DepthFunc::Greater: lanes_block<DepthFunc::Greater>(img, raw, x, y, mask, w, format, passed, k); break;
      case DepthFunc::NotEqual: lanes_block<DepthFunc::NotEqual>(img, raw, x, y, mask, w, format, passed, k); break;
      case DepthFunc::Gequal: lanes_block<DepthFunc::Gequal>(img, raw, x, y, mask, w, format, passed, k); break;
      case DepthFunc::Always: lanes_block<DepthFunc::Always>(img, raw, x, y, mask, w, format, passed, k); break;
    }
    return;
  }
#endif
  switch (func) {
    case DepthFunc::Never: run_block<DepthFunc::Never>(img, plane, x, y, mask, w, fused, format, passed, k); break;
    case DepthFunc::Less: run_block<DepthFunc::Less>(img, plane, x, y, mask, w, fused, format, passed, k); break;
    case DepthFunc::Equal: run_block<DepthFunc::Equal>(img, plane, x, y, mask, w, fused, format, passed, k); break;
    case DepthFunc::Lequal: run_block<DepthFunc::Lequal>(img, plane, x, y, mask, w, fused, format, passed, k); break;
    case DepthFunc::Greater: run_block<DepthFunc::Greater>(img, plane, x, y, mask, w, fused, format, passed, k); break;
    case DepthFunc::NotEqual: run_block<DepthFunc::NotEqual>(img, plane, x, y, mask, w, fused, format, passed, k); break;
    case DepthFunc::Gequal: run_block<DepthFunc::Gequal>(img, plane, x, y, mask, w, fused, format, passed, k); break;
    case DepthFunc::Always: run_block<DepthFunc::Always>(img, plane, x, y, mask, w, fused, format, passed, k); break;
  }
}

// The path of a fragment stage (DepthState::peel_layer, passed_mask or shader set): the strict
// compare against the previous layer, the shader's discard, then the depth test; one pixel at a
// time (not the hot path).
void run_peel_block(DepthImage& img, const DepthPlane& plane, int x, int y, std::uint16_t mask, const DepthState& state,
                    bool fused, DepthFormat format, DepthCounters& k) {
  for (unsigned m = mask; m != 0; m &= m - 1) {
    const int i = std::countr_zero(m);
    const int px = x + (i & 3), py = y + (i >> 2);
    const std::size_t at = static_cast<std::size_t>(py) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(px);
    float interpolated = plane.at(px, py, fused);
    if (state.peel_layer) {
      ++k.peel_reads;
      if (!(interpolated > state.peel_layer->texels[at])) {  // strict; NaN and +inf layers drop the fragment
        ++k.peel_discarded;
        continue;
      }
    }
    if (state.shader && state.shader->discards(px, py, plane.raw_at(px, py, fused))) {
      ++k.shader_discarded;
      continue;
    }
    if (state.shader)
      if (const std::optional<float> written = state.shader->frag_depth(px, py)) interpolated = std::clamp(*written, 0.0f, 1.0f);
    if (!state.test) {
      ++k.passed;
      if (state.passed_mask) (*state.passed_mask)[at] = 1;
      continue;
    }
    ++k.depth_tests;
    const float z = stored_depth(format, interpolated);
    float& stored = img.texels[at];
    if (!depth_passes(state.func, z, stored)) continue;
    ++k.passed;
    if (state.passed_mask) (*state.passed_mask)[at] = 1;
    if (state.write) {
      stored = z;
      ++k.written;
    }
  }
}

}  // namespace

std::optional<DepthFormat> parse_depth_format(std::string_view n) noexcept {
  if (n == "DEPTH_COMPONENT32F" || n == "DEPTH32F_STENCIL8") return DepthFormat::Float32;
  if (n == "DEPTH24_STENCIL8" || n == "DEPTH_COMPONENT24") return DepthFormat::Unorm24;
  return std::nullopt;
}


// q / (2^24 - 1) rounded to float. The double product with the reciprocal is within a few double
// ulps of the quotient, and the quotient (odd denominator) is never within 2^-49 relative of a
// float rounding boundary, so rounding either to float gives the same float (checked for every q,
// DepthTestTest.Unorm24FloatsAreOneToOne), without a division per fragment.

DepthCounters& DepthCounters::operator+=(const DepthCounters& o) {
  fragments += o.fragments;
  depth_tests += o.depth_tests;
  passed += o.passed;
  written += o.written;
  blocks += o.blocks;
  peel_reads += o.peel_reads;
  peel_discarded += o.peel_discarded;
  shader_discarded += o.shader_discarded;
  return *this;
}

EarlyDepthTest::EarlyDepthTest(DepthImage& buffer, bool fused_interpolation, DepthFormat format)
    : buffer_(&buffer), fused_(fused_interpolation), format_(format) {}

void EarlyDepthTest::test_block(const DepthPlane& plane, int x, int y, std::uint16_t mask, const DepthState& state,
                                DepthCounters& k) {
  if (mask == 0) return;
  const auto n = static_cast<std::uint64_t>(std::popcount(static_cast<unsigned>(mask)));
  k.fragments += n;
  k.blocks += 1;
  NBSIM_CHECK(!state.peel_layer || state.peel_layer->texels.size() == buffer_->texels.size(), "peel layer of another size");
  NBSIM_CHECK(!state.passed_mask || state.passed_mask->size() == buffer_->texels.size(), "passed mask of another size");
  // A whole block goes to the plain test (in lanes where it can): a shader that keeps whole blocks
  // first drops its discards; marked passes are set from the test's. Else one pixel at a time.
  std::uint64_t tested = n;
  std::uint8_t* marks = nullptr;
  bool whole = !state.peel_layer && !state.passed_mask && !state.shader;
  if (state.shader && !state.peel_layer && !state.passed_mask)
    if (const std::optional<std::uint16_t> kept = state.shader->keep_block(x, y, mask)) {
      mask = static_cast<std::uint16_t>(*kept & mask);
      tested = static_cast<std::uint64_t>(std::popcount(static_cast<unsigned>(mask)));
      k.shader_discarded += n - tested;
      if (mask == 0) return;
      whole = true;
    }
  if (state.passed_mask && !state.peel_layer && !state.shader && state.test) {
    marks = state.passed_mask->data();
    whole = true;
  }
  if (!whole) {
    run_peel_block(*buffer_, plane, x, y, mask, state, fused_, format_, k);
    return;
  }
  if (!state.test) {
    k.passed += tested;
    return;
  }
  k.depth_tests += tested;
  test_plain_block(*buffer_, plane, x, y, mask, state.func, state.write, fused_, format_, marks, k);
}

}  // namespace nbsim::raster

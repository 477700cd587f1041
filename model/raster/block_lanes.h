// The 4x4 blocks of the depth and stencil tests in SSE lanes (x86-64): the pieces depth_test.cpp
// and stencil_test.cpp share. Each computes, lane by lane, what the one-fragment-at-a-time code
// computes (DepthPlane::at, stored_depth, depth_passes), with the same operations in the same
// order, so the same bits: the fused plane with FMA instructions (std::fma's one rounding), the
// unfused one as a product and a sum each rounded; the clamp as std::max then std::min; the 24-bit
// depth as to_unorm24 and from_unorm24 build it.
#pragma once

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define NBSIM_BLOCK_LANES 1

#include <immintrin.h>

#include "model/raster/depth_test.h"
#include "model/raster/setup.h"

namespace nbsim::raster::lanes {

// The block's depths before the clamp (DepthPlane::raw_at), row by row.
[[gnu::target("fma")]] inline void plane_rows_fused(const DepthPlane& p, int x, int y, __m128 (&z)[4]) {
  const __m128 fx = _mm_cvtepi32_ps(_mm_setr_epi32(x, x + 1, x + 2, x + 3));
  const __m128 row = _mm_fmadd_ps(_mm_set1_ps(p.dzdx), fx, _mm_set1_ps(p.a0));
  for (int r = 0; r < 4; ++r) z[r] = _mm_fmadd_ps(_mm_set1_ps(p.dzdy), _mm_set1_ps(static_cast<float>(y + r)), row);
}
inline void plane_rows_unfused(const DepthPlane& p, int x, int y, __m128 (&z)[4]) {
  const __m128 fx = _mm_cvtepi32_ps(_mm_setr_epi32(x, x + 1, x + 2, x + 3));
  const __m128 a = _mm_add_ps(_mm_set1_ps(p.a0), _mm_mul_ps(_mm_set1_ps(p.dzdx), fx));
  for (int r = 0; r < 4; ++r) z[r] = _mm_add_ps(a, _mm_mul_ps(_mm_set1_ps(p.dzdy), _mm_set1_ps(static_cast<float>(y + r))));
}

inline bool host_fma() noexcept {
  static const bool fma = __builtin_cpu_supports("fma");
  return fma;
}

// Whether the block at (x, y) can be tested in lanes: wholly inside the buffer, and the fused plane
// only where the CPU has FMA.
inline bool block_fits(const DepthImage& img, int x, int y, bool fused) noexcept {
  return x >= 0 && y >= 0 && x + 4 <= img.width && y + 4 <= img.height && (!fused || host_fma());
}

// stored_depth(format, DepthPlane::at's clamp of `raw`): std::min(std::max(z + 0, 0), 1) (max(0, v)
// keeps v when v is not below 0, NaN too; min(1, v) keeps v when 1 is not below it), then for a
// 24-bit buffer to_unorm24 (the product rounded to float, 0 unless above 0, at most 2^24 - 1, else
// rounded to the nearest integer, ties to even: cvtps2dq in the default rounding mode) and
// from_unorm24 (the double product with 1 / (2^24 - 1), rounded to float).
inline __m128 stored_lanes(__m128 raw, DepthFormat format) {
  const __m128 zero = _mm_setzero_ps();
  const __m128 z = _mm_min_ps(_mm_set1_ps(1.0f), _mm_max_ps(zero, _mm_add_ps(raw, zero)));
  if (format != DepthFormat::Unorm24) return z;
  const __m128 top = _mm_set1_ps(16777215.0f);
  const __m128 p = _mm_mul_ps(z, top);
  const __m128i nearest = _mm_cvtps_epi32(p);
  const __m128i q = _mm_and_si128(_mm_castps_si128(_mm_cmpgt_ps(p, zero)),
                                  _mm_blendv_epi8(nearest, _mm_set1_epi32(16777215), _mm_castps_si128(_mm_cmpge_ps(p, top))));
  const __m128d scale = _mm_set1_pd(1.0 / 16777215.0);
  const __m128 lo = _mm_cvtpd_ps(_mm_mul_pd(_mm_cvtepi32_pd(q), scale));
  const __m128 hi = _mm_cvtpd_ps(_mm_mul_pd(_mm_cvtepi32_pd(_mm_srli_si128(q, 8)), scale));
  return _mm_movelh_ps(lo, hi);
}

// depth_passes(F, z, stored) in four lanes.
template <DepthFunc F>
[[gnu::always_inline]] inline __m128 passes(__m128 z, __m128 stored) {
  if constexpr (F == DepthFunc::Less) return _mm_cmplt_ps(z, stored);
  else if constexpr (F == DepthFunc::Equal) return _mm_cmpeq_ps(z, stored);
  else if constexpr (F == DepthFunc::Lequal) return _mm_cmple_ps(z, stored);
  else if constexpr (F == DepthFunc::Greater) return _mm_cmpgt_ps(z, stored);
  else if constexpr (F == DepthFunc::NotEqual) return _mm_cmpneq_ps(z, stored);  // true for a NaN, as !(==)
  else if constexpr (F == DepthFunc::Gequal) return _mm_cmpge_ps(z, stored);
  else if constexpr (F == DepthFunc::Always) return _mm_castsi128_ps(_mm_set1_epi32(-1));
  else return _mm_setzero_ps();
}

// The 4-bit mask of row r of a block's 16-bit pixel mask as four lanes (all ones where set).
inline __m128 row_lanes(std::uint16_t mask, int r) {
  const __m128i bits = _mm_setr_epi32(1, 2, 4, 8);
  return _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(static_cast<int>((mask >> (4 * r)) & 0xFu)), bits), bits));
}

}  // namespace nbsim::raster::lanes

#endif

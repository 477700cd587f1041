// Early depth test: the 4x4 blocks of covered pixels from the rasterizer (model/raster/
// rasterizer.h) tested against, and written to, a float depth buffer (DepthImage, y up, see
// model/common/depth.h), with the fragment depth interpolated from the triangle's depth plane as
// llvmpipe does it (model/raster/setup.h DepthPlane).
//
// Comparisons are IEEE float comparisons of fragment against stored depth, ordered except
// NotEqual (which passes NaN), as lp_bld_depth.c builds them. With the test disabled every
// fragment passes and nothing is written (GL: depth writes need the test enabled).
// A 24-bit unorm buffer (DEPTH24_STENCIL8, DEPTH_COMPONENT24) is kept as floats too: a fragment's
// depth becomes llvmpipe's 24-bit value first, and the buffer holds that value's float image
// (from_unorm24), which is one-to-one and monotonic, so float comparisons are GL's integer ones.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "model/common/depth.h"
#include "model/raster/setup.h"

namespace nbsim::raster {

// GL's depth functions in GL's order. Fixed values, equal to scene::DepthFunc.
enum class DepthFunc : std::uint8_t {
  Never = 0,
  Less = 1,
  Equal = 2,
  Lequal = 3,
  Greater = 4,
  NotEqual = 5,
  Gequal = 6,
  Always = 7
};

// True when a fragment at depth `fragment` passes against `stored` under `func`.
constexpr bool depth_passes(DepthFunc func, float fragment, float stored) noexcept {
  switch (func) {
    case DepthFunc::Never: return false;
    case DepthFunc::Less: return fragment < stored;
    case DepthFunc::Equal: return fragment == stored;
    case DepthFunc::Lequal: return fragment <= stored;
    case DepthFunc::Greater: return fragment > stored;
    case DepthFunc::NotEqual: return !(fragment == stored);
    case DepthFunc::Gequal: return fragment >= stored;
    case DepthFunc::Always: return true;
  }
  return false;
}

// The depth buffer's format, from the trace header's depth_format. Fixed values.
enum class DepthFormat : std::uint8_t { Float32 = 0, Unorm24 = 1 };

// "DEPTH_COMPONENT32F" and "DEPTH32F_STENCIL8" are Float32, "DEPTH24_STENCIL8" and
// "DEPTH_COMPONENT24" Unorm24; anything else nullopt.
std::optional<DepthFormat> parse_depth_format(std::string_view gl_name) noexcept;

// llvmpipe's 24-bit value of a fragment depth in [0, 1] (lp_bld_conv.c
// lp_build_clamped_float_to_unsigned_norm, width 24 = float mantissa + 1): the product
// z * 16777215 rounded to float, then to the nearest integer, ties to even. NaN gives 0.
inline std::uint32_t to_unorm24(float z) noexcept {
  const float p = z * 16777215.0f;  // one float rounding, as the JIT's fmul
  if (!(p > 0.0f)) return 0;        // 0, negative zero and NaN
  if (p >= 16777215.0f) return 16777215u;
  // Round to nearest, ties to even (cvtps2dq): below 2^23 the sum with 2^23 rounds p to an integer
  // in float arithmetic (its ulp is 1 there); from 2^23 on every float is an integer already.
  // Bit-identical to std::nearbyint in the default rounding mode, without a library call.
  constexpr float k2p23 = 8388608.0f;
  const float r = p < k2p23 ? (p + k2p23) - k2p23 : p;
  return static_cast<std::uint32_t>(r);
}
// The float the buffer holds for a 24-bit value: q / (2^24 - 1) rounded to float (adjacent values
// stay apart: their distance is above one float ulp in [0, 1]).
inline float from_unorm24(std::uint32_t q) noexcept { return static_cast<float>(static_cast<double>(q) * (1.0 / 16777215.0)); }
// A fragment depth as a buffer of `format` stores it.
inline float stored_depth(DepthFormat format, float z) noexcept {
  return format == DepthFormat::Unorm24 ? from_unorm24(to_unorm24(z)) : z;
}

// A fragment shader's discard before the depth test (the fragment counted as rasterized, never
// depth tested): `discards` gets the pixel and the fragment's gl_FragCoord.z, the depth plane's
// value before the [0, 1] clamp (DepthPlane::raw_at), as llvmpipe's shader sees it.
// A shader that writes gl_FragDepth (frag_depth returns it) has it clamped to [0, 1], then tested and
// stored instead of the interpolated depth (llvmpipe clamps a written depth even in a float buffer
// without depth clamp: ReliefGlWalkTest.FragDepthOutsideTheUnitRange).
// A shader that decides without the depth and writes none may keep_block: the pixels of `mask` in
// the 4x4 block at (x, y) it keeps (bit i + 4 j is pixel (x + i, y + j), as the tests' masks), the
// same as discards() pixel by pixel; the block is then depth tested whole (in lanes where it can
// be). nullopt (the default): pixel by pixel.
class FragmentShader {
 public:
  virtual ~FragmentShader() = default;
  virtual bool discards(int x, int y, float frag_z) const = 0;
  virtual std::optional<float> frag_depth(int /*x*/, int /*y*/) const { return std::nullopt; }
  virtual std::optional<std::uint16_t> keep_block(int /*x*/, int /*y*/, std::uint16_t /*mask*/) const { return std::nullopt; }
};

struct DepthState {
  DepthFunc func = DepthFunc::Less;
  bool test = true;   // GL_DEPTH_TEST
  bool write = true;  // glDepthMask
  // Depth peeling (layered depth images, model/ldi): when set, a second compare before the depth
  // test, as a peel's fragment shader makes it: a fragment whose interpolated depth is not strictly
  // greater than `peel_layer` at its pixel (same size as the buffer; +inf where there is no
  // previous layer, which drops every fragment there) is discarded: counted in `fragments` and
  // `peel_reads`, never depth tested, never in `passed`. Null (the default): no peel compare.
  const DepthImage* peel_layer = nullptr;
  // When set (a vector of buffer-size bytes), the pixels where a sample passed the depth test are
  // set to 1 (never cleared here): which texels a peel pass wrote, even at the clear value 1.0.
  std::vector<std::uint8_t>* passed_mask = nullptr;
  // When set, every fragment runs it after the peel compare and before the depth test; a discarded
  // fragment is counted in `fragments` and `shader_discarded`.
  const FragmentShader* shader = nullptr;
};

// Per-draw counters of the depth test (added to, never reset, by the unit).
struct DepthCounters {
  std::uint64_t fragments = 0;    // rasterized fragments (GL's fragment-shader atomic counter)
  std::uint64_t depth_tests = 0;  // comparisons against the buffer (docs/architecture.md: "depth test")
  std::uint64_t passed = 0;       // GL_SAMPLES_PASSED
  std::uint64_t written = 0;      // depth values stored
  std::uint64_t blocks = 0;       // 4x4 blocks with at least one fragment
  std::uint64_t peel_reads = 0;      // previous-layer reads of the peel compare (DepthState::peel_layer)
  std::uint64_t peel_discarded = 0;  // fragments the peel compare discarded (not strictly behind the layer)
  std::uint64_t shader_discarded = 0;  // fragments DepthState::shader discarded
  DepthCounters& operator+=(const DepthCounters& o);
};

class EarlyDepthTest {
 public:
  // The unit tests against and writes to `buffer`, which must outlive it. `fused_interpolation`
  // evaluates the depth plane with FMA as llvmpipe does on FMA hosts (setup.h).
  // `format` Unorm24 stores and compares llvmpipe's 24-bit depths (stored_depth).
  explicit EarlyDepthTest(DepthImage& buffer, bool fused_interpolation = true, DepthFormat format = DepthFormat::Float32);

  // Tests the pixels of `mask` in the 4x4 block at (x, y) (bit i + 4 j is pixel (x + i, y + j);
  // they must lie inside the buffer).
  void test_block(const DepthPlane& plane, int x, int y, std::uint16_t mask, const DepthState& state,
                  DepthCounters& counters);

  DepthImage& buffer() noexcept { return *buffer_; }
  bool fused_interpolation() const noexcept { return fused_; }
  DepthFormat format() const noexcept { return format_; }
  void set_format(DepthFormat format) noexcept { format_ = format; }

 private:
  DepthImage* buffer_;
  bool fused_;
  DepthFormat format_;
};

}  // namespace nbsim::raster

// StorageTest: the storage formats of model/common/storage.h and their conservative quantization,
// alone and inside an N-buffer.
#include "model/common/storage.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "model/nbuffer/nbuffer.h"
#include "tests/common/reference.h"

namespace nbsim {
namespace {

constexpr FarOp kOps[] = {FarOp::Max, FarOp::Min};
constexpr StorageFormat kQuantized[] = {StorageFormat::U24, StorageFormat::U16};

double code_scale(StorageFormat f) { return f == StorageFormat::U24 ? 16777215.0 : 65535.0; }

std::string hex(float v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.9g (0x%08x)", static_cast<double>(v), std::bit_cast<std::uint32_t>(v));
  return buf;
}

std::string what(StorageFormat f, FarOp op, float d) {
  return std::string(to_string(f)) + " " + std::string(to_string(op)) + " d=" + hex(d);
}

// Depths that stress quantization: the ends of [0, 1], denormals, the neighbours of every
// 256th U16 code and of U24 codes near 0, 0.5 and 1, and random floats spread both uniformly and
// over every exponent (random bit patterns below 1.0f).
std::vector<float> hard_depths() {
  std::vector<float> v{0.0f,
                       1.0f,
                       std::nextafter(1.0f, 0.0f),
                       std::nextafter(std::nextafter(1.0f, 0.0f), 0.0f),
                       std::numeric_limits<float>::denorm_min(),
                       2.0f * std::numeric_limits<float>::denorm_min(),
                       FLT_MIN,
                       std::nextafter(FLT_MIN, 0.0f),
                       FLT_MIN * 0.5f,
                       0.5f,
                       1.0f / 3.0f,
                       0.1f};
  auto around = [&](double code, double scale) {
    const auto d = static_cast<float>(code / scale);
    v.insert(v.end(), {d, std::nextafter(d, 0.0f), std::nextafter(d, 2.0f)});
  };
  for (int c = 0; c <= 65535; c += 257) around(c, 65535.0);
  for (int c : {0, 1, 2, 3, 8388607, 8388608, 8388609, 16777213, 16777214, 16777215}) around(c, 16777215.0);
  std::mt19937 rng(5);
  for (int i = 0; i < 200000; ++i) v.push_back(ref::unit_float(rng));
  for (int i = 0; i < 200000; ++i) v.push_back(std::bit_cast<float>(static_cast<std::uint32_t>(rng() % 0x3F800001u)));  // [0, 1], every exponent
  for (float& d : v) d = std::clamp(d, 0.0f, 1.0f);
  return v;
}

// Format sizes and names are fixed by the design (they end up in configs and traces).
TEST(StorageTest, FormatTable) {
  struct Row { StorageFormat f; int bits, bytes; const char* name; };
  const Row rows[] = {{StorageFormat::F32, 32, 4, "f32"}, {StorageFormat::U24, 24, 4, "u24"}, {StorageFormat::U16, 16, 2, "u16"}};
  for (const Row& row : rows) {
    EXPECT_EQ(storage_bits(row.f), row.bits) << row.name;
    EXPECT_EQ(storage_bytes(row.f), row.bytes) << row.name << (row.f == StorageFormat::U24 ? ": stored as D24X8" : "");
    EXPECT_EQ(to_string(row.f), row.name);
    EXPECT_EQ(parse_storage_format(row.name), row.f) << "names round-trip";
  }
  EXPECT_FALSE(parse_storage_format("u32")) << "unknown names are rejected";
  EXPECT_FALSE(parse_storage_format("F32")) << "names are lower case";
}

// F32 stores every depth unchanged.
TEST(StorageTest, F32IsExact) {
  for (const float d : hard_depths())
    for (const FarOp op : kOps) ASSERT_EQ(quantize_toward_far(d, StorageFormat::F32, op), d) << what(StorageFormat::F32, op, d);
}

// U24/U16 never store a depth nearer than the truth, stay in [0, 1], and store a code of the
// format (the float nearest code / (2^bits - 1)) within one code step of the depth.
TEST(StorageTest, QuantizedNeverNearer) {
  const std::vector<float> depths = hard_depths();
  for (const StorageFormat f : kQuantized)
    for (const FarOp op : kOps) {
      ref::Failures fails;
      const double scale = code_scale(f);
      for (const float d : depths) {
        const float q = quantize_toward_far(d, f, op);
        if (!at_least_as_far(op, q, d)) fails.add("conservative: " + what(f, op, d) + " stored as nearer " + hex(q));
        if (!(q >= 0.0f && q <= 1.0f)) fails.add("range: " + what(f, op, d) + " stored outside [0, 1] as " + hex(q));
        // The stored float is only the nearest float to its code (U24 codes are not all floats),
        // so tightness is measured in codes: within one code of d * scale.
        const double code = std::round(static_cast<double>(q) * scale);
        if (std::abs(code - static_cast<double>(d) * scale) > 1.0)
          fails.add("tight: " + what(f, op, d) + " stored as code " + std::to_string(code) + ", more than one code step away");
        if (static_cast<float>(code / scale) != q) fails.add("code: " + what(f, op, d) + " stored " + hex(q) + ", not a code");
      }
      EXPECT_EQ(fails.count(), 0) << to_string(f) << " " << to_string(op) << ": " << fails.summary();
    }
}

// Exact codes and the ends of the range are stored as they are; the edge cases with reasons.
TEST(StorageTest, QuantizedEdgeCases) {
  struct Row { float d; StorageFormat f; FarOp op; float want; const char* why; };
  const float denorm = std::numeric_limits<float>::denorm_min();
  const Row rows[] = {
      {0.0f, StorageFormat::U16, FarOp::Max, 0.0f, "0 is code 0"},
      {1.0f, StorageFormat::U16, FarOp::Max, 1.0f, "the far plane is the top code"},
      {1.0f, StorageFormat::U24, FarOp::Min, 1.0f, "reversed Z: 1 is the top code"},
      {0.0f, StorageFormat::U24, FarOp::Min, 0.0f, "reversed Z: the far plane 0 is code 0"},
      {denorm, StorageFormat::U16, FarOp::Max, static_cast<float>(1.0 / 65535.0), "a denormal rounds up to code 1"},
      {denorm, StorageFormat::U16, FarOp::Min, 0.0f, "reversed Z: a denormal rounds down to 0"},
      {denorm, StorageFormat::U24, FarOp::Max, static_cast<float>(1.0 / 16777215.0), "a denormal rounds up to code 1 (U24)"},
      {std::nextafter(1.0f, 0.0f), StorageFormat::U16, FarOp::Max, 1.0f, "just below 1 rounds up to the far plane"},
      {std::nextafter(1.0f, 0.0f), StorageFormat::U16, FarOp::Min, static_cast<float>(65534.0 / 65535.0), "reversed Z: just below 1 rounds down"},
      {0.5f, StorageFormat::U16, FarOp::Max, static_cast<float>(32768.0 / 65535.0), "0.5 lies between codes 32767 and 32768"},
      {0.5f, StorageFormat::U16, FarOp::Min, static_cast<float>(32767.0 / 65535.0), "reversed Z: 0.5 rounds down to 32767"},
  };
  for (const Row& row : rows)
    EXPECT_EQ(quantize_toward_far(row.d, row.f, row.op), row.want) << row.why << " (" << what(row.f, row.op, row.d) << ")";
}

// Quantization is monotone: a farther depth is never stored nearer (it commutes with max/min).
TEST(StorageTest, QuantizeIsMonotone) {
  // Positive floats are ordered like their bit patterns: walk [0, 1] in bit order with a stride
  // (every exponent), then densely through the top of the range where the codes are.
  std::vector<float> walk;
  for (std::uint32_t b = 0; b <= 0x3F800000u; b += 1009u) walk.push_back(std::bit_cast<float>(b));
  for (std::uint32_t b = 0x3F7F0000u; b <= 0x3F800000u; ++b) walk.push_back(std::bit_cast<float>(b));
  std::sort(walk.begin(), walk.end());
  for (const StorageFormat f : kQuantized)
    for (const FarOp op : kOps) {
      ref::Failures fails;
      float prev_d = walk.front(), prev_q = quantize_toward_far(prev_d, f, op);
      for (const float d : walk) {
        const float q = quantize_toward_far(d, f, op);
        if (q < prev_q) fails.add("monotone: " + what(f, op, d) + " -> " + hex(q) + " but the smaller " + hex(prev_d) + " -> " + hex(prev_q));
        prev_d = d, prev_q = q;
      }
      EXPECT_EQ(fails.count(), 0) << to_string(f) << " " << to_string(op) << ": " << fails.summary();
    }
}

// Quantizing a stored value again keeps it (a stored level re-stored, or level 0 written back,
// must not creep toward far).
TEST(StorageTest, QuantizeIsIdempotent) {
  const std::vector<float> depths = hard_depths();
  for (const StorageFormat f : {StorageFormat::F32, StorageFormat::U24, StorageFormat::U16})
    for (const FarOp op : kOps) {
      ref::Failures fails;
      for (const float d : depths) {
        const float q = quantize_toward_far(d, f, op), qq = quantize_toward_far(q, f, op);
        if (qq != q) fails.add("idempotent: " + what(f, op, d) + " stored as " + hex(q) + ", re-stored as " + hex(qq));
      }
      EXPECT_EQ(fails.count(), 0) << to_string(f) << " " << to_string(op) << ": " << fails.summary();
    }
}

// An N-buffer fed its own stored depth keeps it: rebuilding from level 0, or writing level 0 back
// as a dirty rectangle, changes nothing (the user-visible side of idempotent quantization).
TEST(StorageTest, StoredDepthRoundTripsThroughNBuffer) {
  const DepthImage img = ref::uniform(31, 17, 9);
  for (const StorageFormat f : {StorageFormat::F32, StorageFormat::U24, StorageFormat::U16})
    for (const FarOp op : kOps) {
      NBuffer nb(img, {.op = op, .format = f});
      const DepthImage stored = nb.level_image(0);
      const NBuffer rebuilt(stored, nb.config());
      long long differ = 0;
      for (int i = 0; i < nb.level_count(); ++i)
        for (std::size_t k = 0; k < nb.level(i).size(); ++k) differ += nb.level(i)[k] != rebuilt.level(i)[k];
      EXPECT_EQ(differ, 0) << to_string(f) << " " << to_string(op) << ": texels moved when rebuilt from the stored level 0";
      const UpdateStats st = nb.update(stored, {0, 0, 31, 17});
      EXPECT_EQ(st.total_changed(), 0) << to_string(f) << " " << to_string(op) << ": writing the stored level 0 back changed texels";
    }
}

// An N-buffer in U24/U16 holds the quantized F32 levels and answers every random rectangle with
// the quantized F32 answer, so never nearer than the F32 answer.
TEST(StorageTest, QuantizedNBufferIsConservative) {
  for (const FarOp op : kOps) {
    const DepthImage img = ref::uniform(97, 61, 7);
    const NBuffer exact(img, {.op = op});
    for (const StorageFormat f : kQuantized) {
      const NBuffer nb(img, {.op = op, .format = f});
      ref::Failures fails;
      for (int i = 0; i < nb.level_count(); ++i)
        for (int y = 0; y < img.height; ++y)
          for (int x = 0; x < img.width; ++x)
            if (nb.texel(i, x, y) != quantize_toward_far(exact.texel(i, x, y), f, op))
              fails.add("levels: level " + std::to_string(i) + " texel " + std::to_string(x) + "," + std::to_string(y) +
                        " is not the quantized F32 texel");
      std::mt19937 rng(8);
      for (int n = 0; n < 20000; ++n) {
        const Rect r = ref::random_rect(rng, img.width, img.height, true);
        for (const CoveringSpec kind : {CoveringSpec{CoveringKind::Paper, CoveringAlign::Top}, CoveringSpec{CoveringKind::Corners, CoveringAlign::Bottom}, CoveringSpec{CoveringKind::One, CoveringAlign::Top}}) {
          const QueryResult q = nb.query(r, kind), e = exact.query(r, kind);
          if (!at_least_as_far(op, q.value, e.value))
            fails.add("conservative: " + ref::str(r) + " answered " + hex(q.value) + ", nearer than F32's " + hex(e.value));
          if (q.value != quantize_toward_far(e.value, f, op))
            fails.add("commute: " + ref::str(r) + " answered " + hex(q.value) + ", not the quantized F32 answer");
        }
      }
      EXPECT_EQ(fails.count(), 0) << to_string(f) << " " << to_string(op) << ": " << fails.summary();
    }
  }
}

}  // namespace
}  // namespace nbsim

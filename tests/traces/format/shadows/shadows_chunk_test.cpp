// ShadowsChunkTest: the shadows technique's SHDC record (traces/format/shadows/shadows_chunk.h) read back by every
// reader, and every damage to it refused naming the chunk.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "tests/traces/format/chunk_builder.h"
#include "traces/format/shadows/shadows_chunk.h"

namespace {

using namespace nbsim::trace;
using namespace nbsim::trace::testing;

// The shadows technique's SHDC record (traces/format/shadows/shadows_chunk.h) is decoded by every reader;
// each flipped byte, a payload one byte short or long, a vector count past the payload and broken
// rules (lengths, decisions, rectangles outside the litmap, draws below -1) are refused naming it.
TEST(ShadowsChunkTest, DecodedAndDamageRefused) {
  struct Fields {
    std::vector<std::int32_t> x{0, 10, 0}, w{0, 6, 64};
    std::vector<std::uint32_t> decision{2, 0, 3};
    std::vector<std::int32_t> draw{-1, 7, 8};
    std::vector<std::uint32_t> cls{0, 1, 1}, kept{0, 1, 4};
  };
  auto payload = [](const Fields& f) {
    bytes::Out o;
    o.u32(3);
    o.u32(64);                                              // litmap_size
    o.counted_words(std::vector<std::uint32_t>{1, 2, 5});  // object
    o.counted_words(f.x);
    o.counted_words(std::vector<std::int32_t>{0, 20, 0});  // y
    o.counted_words(f.w);
    o.counted_words(std::vector<std::int32_t>{0, 5, 64});  // h
    for (int k = 0; k < 4; ++k) o.counted_words(std::vector<float>{0.5f, 0.25f, 1.0f});  // caster_near/far, z_min/max
    o.counted_words(std::vector<std::uint32_t>{0, 8, 0});  // lookups
    o.counted_words(f.decision);
    o.counted_words(std::vector<float>{0.0f, 0.3f, 0.0f});  // clamp_near
    o.counted_words(std::vector<float>{INFINITY, 0.9f, INFINITY});  // clamp_far
    o.counted_words(f.draw);
    o.u64(1234567);  // reference_fill
    o.u64(0);        // mask_diff_pixels
    o.str("tower,bird");  // class_names
    o.counted_words(f.cls);
    o.counted_words(f.kept);
    o.counted_words(std::vector<std::uint32_t>{500, 70, 9000});  // fill_infinite
    for (double v : {10.0, 90.0, 12.5, 50.0, 0.0, 50.0, 60.0, 0.5, 400.0}) o.f64(v);  // the light camera
    return o.take();
  };
  TechniqueRecord raw;
  raw.type = kShadowsChunk;
  raw.payload = payload(Fields{});
  const TechniqueRecord r = decode_technique(kShadowsChunk, raw.payload);
  ASSERT_TRUE(r.decoded) << "the format library registers SHDC";
  EXPECT_EQ(encode(r), raw.payload) << "SHDC encodes back to the same bytes";
  expect_reads_back_and_flips_refused(r, "SHDC");
  std::vector<std::uint8_t> shorter = raw.payload;
  shorter.pop_back();
  std::string e = record_error(kShadowsChunk, shorter);
  EXPECT_TRUE(has(e, "chunk 2 (SHDC)") && has(e, "decodes short")) << e;
  std::vector<std::uint8_t> longer = raw.payload;
  longer.push_back(0);
  e = record_error(kShadowsChunk, longer);
  EXPECT_TRUE(has(e, "chunk 2 (SHDC)") && has(e, "decodes long")) << e;
  // The layout before the per-caster breakdown (class_names, class, kept, fill_infinite) and the
  // light camera: refused
  // naming the type, the missing field and where this nbsim's fields are listed.
  const std::ptrdiff_t breakdown_bytes = (4 + 10) + 3 * (4 + 3 * 4) + 9 * 8;
  e = record_error(kShadowsChunk, std::vector<std::uint8_t>(raw.payload.begin(), raw.payload.end() - breakdown_bytes));
  EXPECT_TRUE(has(e, "chunk 2 (SHDC)") && has(e, "technique chunk SHDC (ShadowCasters, technique shadows) does not have this nbsim's layout") &&
              has(e, "'class_names'") && has(e, "18 fields of 31 read") && has(e, "`nbsim trace format SHDC`"))
      << e;
  std::vector<std::uint8_t> hostile = raw.payload;
  put_le32(hostile, 8, 0xFFFFFFFFu);  // the object vector's count
  e = record_error(kShadowsChunk, hostile);
  EXPECT_TRUE(has(e, "chunk 2 (SHDC)") && has(e, "4294967295")) << e;
  struct Broken {
    Fields f;
    std::string message;
  };
  Broken rows[] = {{Fields{}, "field 'x' has 2 elements, but count is 3"},
                   {Fields{}, "field 'decision' of caster 1 is 4, above 3"},
                   {Fields{}, "caster 2's rectangle (0, 0, 65x64) is not inside the 64x64 litmap"},
                   {Fields{}, "caster 1's rectangle (-1, 20, 6x5) is not inside"},
                   {Fields{}, "field 'draw' of caster 0 is -2, below -1"},
                   {Fields{}, "field 'kept' of caster 2 is 5, above 4"}};
  rows[0].f.x = {0, 10};
  rows[1].f.decision = {2, 4, 3};
  rows[2].f.w = {0, 6, 65};
  rows[3].f.x = {0, -1, 0};
  rows[4].f.draw = {-2, 7, 8};
  rows[5].f.kept = {0, 1, 5};
  for (const Broken& b : rows) {
    e = record_error(kShadowsChunk, payload(b.f));
    EXPECT_TRUE(has(e, "chunk 2 (SHDC)") && has(e, b.message)) << b.message << ": " << e;
  }
}

// SHDG, the casters' meshes: decoded, encoded back to the same bytes; ranges and vertex indices
// outside their arrays refused naming the caster or the index.
TEST(ShadowsChunkTest, CasterMeshesDecodedAndDamageRefused) {
  auto payload = [](std::vector<std::uint32_t> first, std::vector<std::uint32_t> triangles) {
    bytes::Out o;
    o.u32(1);
    o.counted_words(std::vector<std::uint32_t>{4});  // object
    o.counted_words(std::vector<float>{0, 0, 0, 1, 1, 1});  // bounds
    o.counted_words(first);
    o.counted_words(std::vector<std::uint32_t>{4});  // triangle_count
    o.counted_words(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1});  // vertices
    o.counted_words(triangles);
    return o.take();
  };
  const std::vector<std::uint32_t> tetra = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  const auto raw = payload({0}, tetra);
  const TechniqueRecord r = decode_technique(kCasterMeshesChunk, raw);
  ASSERT_TRUE(r.decoded) << "the format library registers SHDG";
  EXPECT_EQ(encode(r), raw);
  std::string e = record_error(kCasterMeshesChunk, payload({1}, tetra));
  EXPECT_TRUE(has(e, "(SHDG)") && has(e, "caster 0 (object 4): triangles 1 + 4 run past the 4 triangles")) << e;
  std::vector<std::uint32_t> bad = tetra;
  bad[11] = 9;
  e = record_error(kCasterMeshesChunk, payload({0}, bad));
  EXPECT_TRUE(has(e, "triangle index 11 is vertex 9, but there are 4 vertices")) << e;
}

// SHDM, every object's mesh: decoded, encoded back to the same bytes; an object listed twice and a
// range outside the triangles refused, naming them.
TEST(ShadowsChunkTest, LitmapMeshesDecodedAndDamageRefused) {
  auto payload = [](std::vector<std::uint32_t> object, std::vector<std::uint32_t> first) {
    bytes::Out o;
    o.u32(static_cast<std::uint32_t>(object.size()));
    o.counted_words(object);
    o.counted_words(first);
    o.counted_words(std::vector<std::uint32_t>(object.size(), 1));  // triangle_count
    o.counted_words(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});  // vertices
    o.counted_words(std::vector<std::uint32_t>{0, 1, 2, 2, 1, 0});  // triangles
    return o.take();
  };
  const auto raw = payload({3, 7}, {0, 1});
  const TechniqueRecord r = decode_technique(kLitmapMeshesChunk, raw);
  ASSERT_TRUE(r.decoded) << "the format library registers SHDM";
  EXPECT_EQ(encode(r), raw);
  std::string e = record_error(kLitmapMeshesChunk, payload({3, 3}, {0, 1}));
  EXPECT_TRUE(has(e, "(SHDM)") && has(e, "object 3 is listed twice")) << e;
  e = record_error(kLitmapMeshesChunk, payload({3, 7}, {0, 2}));
  EXPECT_TRUE(has(e, "mesh 1 (object 7): triangles 2 + 1 run past the 2 triangles")) << e;
}

}  // namespace

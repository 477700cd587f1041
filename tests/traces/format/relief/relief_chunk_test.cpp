// ReliefChunkTest: the relief technique's RLFH and RLFF records (traces/format/relief/relief_chunk.h) read back by every
// reader, and every damage to it refused naming the chunk.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "model/nbuffer/nbuffer.h"
#include "model/relief/records.h"
#include "tests/traces/format/chunk_builder.h"
#include "traces/format/relief/relief_chunk.h"
#include "model/relief/roles.h"

namespace {

using namespace nbsim::trace;
using namespace nbsim::trace::testing;

// The relief technique's RLFH and RLFF records (traces/format/relief/relief_chunk.h) are decoded by every
// reader, and what the reader accepts the model's readers accept too (model/relief/records.h, the
// same fourccs); each flipped byte, a payload one byte short or long and each broken rule (sizes,
// levels and tunables out of range, vectors of other lengths, NaN, heights outside [0, 1], radii
// that are not whole or above max_radius, methods and hits out of range, unsorted pixels) are
// refused naming the chunk.
TEST(ReliefChunkTest, DecodedAndDamageRefused) {
  constexpr std::uint32_t kN = 4;
  struct Field {
    std::uint32_t size = kN, levels = 2, max_radius = 3, linear_steps = 16, binary_steps = 8, root_steps = 4;
    std::vector<float> heights = std::vector<float>{0.0f, 0.25f, 0.5f, 0.0f,  0.125f, 1.0f, 0.75f, 0.5f,
                                                    0.0f, 0.0f,  0.5f, 0.25f, 0.375f, 0.0f, 0.0f,  0.0f};
    std::vector<float> radius = std::vector<float>{1, 0, 0, 1, 2, 0, 0, 1, 3, 2, 0, 1, 3, 3, 2, 2};
    std::vector<float> nbuffer;  // the max N-buffer of the default heights, filled in below
    std::vector<float> origin{2.0f, -3.0f, 5.5f}, ray_a{0.125f, 0.0f, 0.0f}, ray_c{-0.5f, 1.0f, -1.0f};
    double frustum_apex = 0.0;
    std::vector<float> eye_h, ray_q;  // a box: none
  };
  Field good_field;
  {
    nbsim::DepthImage image(kN, kN, 0.0f);
    image.texels = good_field.heights;
    const nbsim::NBuffer nb(image, nbsim::NBufferConfig{nbsim::FarOp::Max, nbsim::StorageFormat::F32, -1});
    for (int l = 0; l < nb.level_count(); ++l) good_field.nbuffer.insert(good_field.nbuffer.end(), nb.level(l).begin(), nb.level(l).end());
  }
  auto field_payload = [](const Field& f) {
    bytes::Out o;
    o.u32(f.size), o.u32(f.levels), o.u32(f.max_radius);
    o.str("hand-made 4x4");
    o.counted_words(f.heights);
    o.counted_words(f.radius);
    o.counted_words(f.nbuffer);
    o.u32(f.linear_steps), o.u32(f.binary_steps), o.u32(f.root_steps);
    o.counted_words(f.origin);
    o.counted_words(f.ray_a);
    o.counted_words(std::vector<float>{0.0f, 0.125f, 0.0f});  // ray_b
    o.counted_words(f.ray_c);
    o.f64(30.0);  // view_angle
    o.f64(f.frustum_apex);
    o.counted_words(f.eye_h);
    o.counted_words(f.ray_q);
    return o.take();
  };
  struct Fragments {
    std::uint32_t method = 4, count = 2;
    std::vector<std::uint32_t> pixel{5, 9}, hit{1, 2};
    std::vector<float> t{0.75f, 0.0f};
  };
  auto fragments_payload = [](const Fragments& f) {
    bytes::Out o;
    o.u32(0);  // draw: the frame's relief_box draw
    o.u32(f.method), o.u32(f.count);
    o.counted_words(f.pixel);
    o.counted_words(f.hit);
    o.counted_words(f.t);
    o.counted_words(std::vector<std::uint32_t>{24, 400});  // lookups
    o.counted_words(std::vector<std::uint32_t>{5, 100});   // steps
    o.counted_words(std::vector<std::uint32_t>{16, 0});    // bisections
    return o.take();
  };
  EXPECT_EQ(kReliefFieldChunk, nbsim::relief::kReliefFieldRecordType) << "model/relief/records.h names RLFH by its fourcc";
  EXPECT_EQ(kReliefFragmentsChunk, nbsim::relief::kReliefFragmentsRecordType) << "model/relief/records.h names RLFF by its fourcc";
  const Properties P;
  DrawRecord box = sample_draw(0, 6);
  box.role = nbsim::relief::kReliefBoxRole;
  box.state.write = false;
  box.discards = true;
  // HEAD, FRAM, DRAW (the relief box), RLFH, RLFF, FEND, END: a relief frame as the capture writes it.
  auto trace = [&](const TechniqueRecord& field, const TechniqueRecord& fragments) {
    return Builder().add(P).add(sample_frame_begin(0)).add(box).technique(field).technique(fragments).add(FrameEnd{0, 1, 0}).end(1).b;
  };
  TechniqueRecord raw_field, raw_fragments;
  raw_field.type = kReliefFieldChunk;
  raw_field.payload = field_payload(good_field);
  raw_fragments.type = kReliefFragmentsChunk;
  raw_fragments.payload = fragments_payload(Fragments{});
  const TechniqueRecord field = decode_technique(kReliefFieldChunk, raw_field.payload);
  const TechniqueRecord fragments = decode_technique(kReliefFragmentsChunk, raw_fragments.payload);
  ASSERT_TRUE(field.decoded && fragments.decoded) << "the format library registers RLFH and RLFF";
  EXPECT_EQ(encode(field), raw_field.payload) << "RLFH encodes back to the same bytes";
  EXPECT_EQ(encode(fragments), raw_fragments.payload) << "RLFF encodes back to the same bytes";
  const Bytes good = trace(field, fragments);
  {
    FrameReader frames(TraceReader(good, "t.nbtrace"));
    const auto f = frames.next();
    ASSERT_TRUE(f);
    ASSERT_EQ(f->technique_records.size(), 2u);
    expect_same(field, f->technique_records[0]);
    expect_same(fragments, f->technique_records[1]);
    EXPECT_EQ(nbsim::relief::read_relief_field(*f).nbuffer, good_field.nbuffer);
    EXPECT_EQ(nbsim::relief::read_relief_fragments(*f, 16).size(), 1u);
  }
  const std::vector<std::size_t> offsets = chunk_offsets(good);
  for (const std::size_t chunk : {3u, 4u})
    for (std::size_t i = offsets[chunk]; i < offsets[chunk + 1]; ++i) {
      Bytes b = good;
      b[i] ^= 0x01;
      const std::string e = read_error(b);
      ASSERT_TRUE(has(e, "chunk " + std::to_string(chunk) + " ")) << "byte " << i << " of " << (chunk == 3 ? "RLFH" : "RLFF") << " flipped: " << e;
    }
  auto error_of = [&](std::uint32_t type, std::vector<std::uint8_t> bytes_in) {
    TechniqueRecord x;
    x.type = type;
    x.payload = std::move(bytes_in);
    return type == kReliefFieldChunk ? read_error(trace(x, fragments)) : read_error(trace(field, x));
  };
  std::vector<std::uint8_t> shorter = field_payload(good_field);
  shorter.pop_back();
  EXPECT_TRUE(has(error_of(kReliefFieldChunk, shorter), "chunk 3 (RLFH)") && has(error_of(kReliefFieldChunk, shorter), "decodes short"));
  std::vector<std::uint8_t> longer = field_payload(good_field);
  longer.push_back(0);
  EXPECT_TRUE(has(error_of(kReliefFieldChunk, longer), "decodes long"));
  shorter = fragments_payload(Fragments{});
  shorter.pop_back();
  EXPECT_TRUE(has(error_of(kReliefFragmentsChunk, shorter), "chunk 4 (RLFF)") && has(error_of(kReliefFragmentsChunk, shorter), "decodes short"));
  longer = fragments_payload(Fragments{});
  longer.push_back(0);
  EXPECT_TRUE(has(error_of(kReliefFragmentsChunk, longer), "decodes long"));

  struct BrokenField {
    std::function<void(Field&)> damage;
    std::string message;
  };
  const BrokenField fields[] = {
      {[](Field& f) { f.size = 1; }, "size is 1, not 2 to 1024"},
      {[](Field& f) { f.size = 1025; }, "size is 1025, not 2 to 1024"},
      {[](Field& f) { f.levels = 3; }, "levels is 3, but a 4x4 N-buffer has 2"},
      {[](Field& f) { f.max_radius = 0; }, "max_radius is 0, not 1 to 255"},
      {[](Field& f) { f.max_radius = 256; }, "max_radius is 256, not 1 to 255"},
      {[](Field& f) { f.linear_steps = 0; }, "linear_steps is 0, not 1 to 1024"},
      {[](Field& f) { f.linear_steps = 1025; }, "linear_steps is 1025, not 1 to 1024"},
      {[](Field& f) { f.binary_steps = 33; }, "binary_steps is 33, not 0 to 32"},
      {[](Field& f) { f.root_steps = 33; }, "root_steps is 33, not 0 to 32"},
      {[](Field& f) { f.heights.pop_back(); }, "field 'heights' has 15 values, but size x size (4x4) is 16"},
      {[](Field& f) { f.radius.push_back(0); }, "field 'radius' has 17 values, but size x size (4x4) is 16"},
      {[](Field& f) { f.nbuffer.resize(16); }, "field 'nbuffer' has 16 values, but levels x size x size (2x4x4) is 32"},
      {[](Field& f) { f.origin.pop_back(); }, "field 'origin' has 2 values, but a vector's length is 3"},
      {[](Field& f) { f.frustum_apex = -1.0; }, "frustum_apex is -1"},
      {[](Field& f) { f.frustum_apex = 2.0; }, "field 'eye_h' has 0 values, but a frustum's homogeneous eye is 4"},
      {[](Field& f) { f.eye_h = {0, 0, 0, 1}; }, "field 'eye_h' has 4 values, but a box's is 0"},
      {[](Field& f) { f.frustum_apex = 2.0, f.eye_h = {0, 0, 0, 1}, f.ray_q = {1, 2, 3}; }, "field 'ray_q' has 3 values"},
      {[](Field& f) { f.ray_a.push_back(1); }, "field 'ray_a' has 4 values"},
      {[](Field& f) { f.heights[5] = std::nanf(""); }, "field 'heights' has NaN at index 5"},
      {[](Field& f) { f.nbuffer[20] = std::nanf(""); }, "field 'nbuffer' has NaN at index 20"},
      {[](Field& f) { f.ray_c[2] = std::nanf(""); }, "field 'ray_c' has NaN at index 2"},
      {[](Field& f) { f.heights[9] = 1.5f; }, "height of texel (1, 2) is 1.5, outside [0, 1]"},
      {[](Field& f) { f.heights[0] = -0.5f; }, "height of texel (0, 0) is -0.5, outside [0, 1]"},
      {[](Field& f) { f.radius[7] = 2.5f; }, "radius of texel (3, 1) is 2.5, not a whole number in [0, 3]"},
      {[](Field& f) { f.radius[12] = 4.0f; }, "radius of texel (0, 3) is 4, not a whole number in [0, 3]"},
      {[](Field& f) { f.radius[1] = -1.0f; }, "radius of texel (1, 0) is -1"},
  };
  for (const BrokenField& b : fields) {
    Field f = good_field;
    b.damage(f);
    const std::string e = error_of(kReliefFieldChunk, field_payload(f));
    EXPECT_TRUE(has(e, "chunk 3 (RLFH)") && has(e, b.message)) << b.message << ": " << e;
  }
  struct BrokenFragments {
    std::function<void(Fragments&)> damage;
    std::string message;
  };
  const BrokenFragments rows[] = {
      {[](Fragments& f) { f.hit.pop_back(); }, "field 'hit' has 1 elements, but count is 2 (one a fragment)"},
      {[](Fragments& f) { f.count = 3; }, "field 'pixel' has 2 elements, but count is 3 (one a fragment)"},
      {[](Fragments& f) { f.method = 5; }, "method is 5, above 4"},
      {[](Fragments& f) { f.hit[1] = 3; }, "field 'hit' of fragment 1 is 3, above 2"},
      {[](Fragments& f) { f.t[0] = std::nanf(""); }, "field 't' of fragment 0 is NaN"},
      {[](Fragments& f) { f.pixel = {9, 5}; }, "field 'pixel' is not strictly increasing: fragment 1 is pixel 5, after 9"},
      {[](Fragments& f) { f.pixel = {9, 9}; }, "field 'pixel' is not strictly increasing: fragment 1 is pixel 9, after 9"},
  };
  for (const BrokenFragments& b : rows) {
    Fragments f;
    b.damage(f);
    const std::string e = error_of(kReliefFragmentsChunk, fragments_payload(f));
    EXPECT_TRUE(has(e, "chunk 4 (RLFF)") && has(e, b.message)) << b.message << ": " << e;
  }
}

// RLFD (the depth the boxes left) decodes, encodes back to its bytes, and its rule refuses a matrix
// of other than 16 values or with NaN, a CRC count unlike the draw count and unsorted draws.
TEST(ReliefChunkTest, DepthRecordRule) {
  const auto payload = [](std::vector<float> m, std::vector<std::uint32_t> draws, std::vector<std::uint32_t> crcs) {
    bytes::Out o;
    o.counted_words(m);
    o.counted_words(draws);
    o.counted_words(crcs);
    return o.take();
  };
  const std::vector<float> identity{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  const std::vector<std::uint8_t> good = payload(identity, {3, 5}, {0xDEADBEEFu, 7});
  const TechniqueRecord r = decode_technique(kReliefDepthChunk, good);
  ASSERT_TRUE(r.decoded);
  EXPECT_EQ(encode(r), good);
  EXPECT_EQ(kReliefDepthChunk, nbsim::relief::kReliefDepthRecordType) << "model/relief/records.h names RLFD by its fourcc";
  std::vector<float> with_nan = identity;
  with_nan[5] = std::nanf("");
  const std::pair<std::vector<std::uint8_t>, const char*> bad[] = {
      {payload(std::vector<float>(15, 0.0f), {3}, {1}), "field 'texel_to_clip' has 15 values"},
      {payload(with_nan, {3}, {1}), "field 'texel_to_clip' has NaN at index 5"},
      {payload(identity, {3, 5}, {1}), "field 'depth_crc' has 1 values, but there are 2 draws"},
      {payload(identity, {5, 3}, {1, 2}), "field 'draws' is not strictly increasing: 3 after 5"},
  };
  for (const auto& [bytes_in, message] : bad) {
    try {
      decode_technique(kReliefDepthChunk, bytes_in);
      ADD_FAILURE() << message << ": accepted";
    } catch (const nbsim::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("ReliefDepth"), std::string::npos) << e.what();
    }
  }
}

}  // namespace

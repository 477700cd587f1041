// ParticlesChunkTest: the particles technique's PRTC record (traces/format/particles/particles_chunk.h) read back by every
// reader, and every damage to it refused naming the chunk.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "tests/traces/format/chunk_builder.h"
#include "traces/format/particles/particles_chunk.h"

namespace {

using namespace nbsim::trace;
using namespace nbsim::trace::testing;

// The particles technique's PRTC record (traces/format/particles/particles_chunk.h) is decoded by every
// reader; each flipped byte, a payload one byte short or long and a vector count past the payload
// are refused naming the chunk.
TEST(ParticlesChunkTest, DecodedAndDamageRefused) {
  TechniqueRecord r;
  r.type = kParticlesChunk;
  r.decoded = true;
  r.fields = {{"count", std::uint64_t{3}},
              {"draw", std::vector<std::uint32_t>{0, 0, 1}},
              {"x", std::vector<float>{0.5f, -3.0f, 100.25f}},
              {"y", std::vector<float>{1.5f, 2.0f, 95.0f}},
              {"depth", std::vector<float>{0.25f, 1.0f, 0.999f}},
              {"size", std::vector<float>{16.0f, 24.0f, 64.0f}},
              {"culled", std::vector<std::uint32_t>{1, 0, 0}},
              {"lookups", std::vector<std::uint32_t>{1, 4, 0}},
              {"reference_samples", std::vector<std::uint32_t>{0, 17, 4096}}};
  r.payload = encode(r);
  expect_reads_back_and_flips_refused(r, "PRTC");
  Bytes shorter = r.payload;
  shorter.pop_back();
  std::string e = record_error(kParticlesChunk, shorter);
  EXPECT_TRUE(has(e, "chunk 2 (PRTC)") && has(e, "decodes short")) << e;
  Bytes longer = r.payload;
  longer.push_back(0);
  e = record_error(kParticlesChunk, longer);
  EXPECT_TRUE(has(e, "chunk 2 (PRTC)") && has(e, "decodes long")) << e;
  Bytes hostile = r.payload;
  put_le32(hostile, 4, 0xFFFFFFFFu);  // the draw vector's count
  e = record_error(kParticlesChunk, hostile);
  EXPECT_TRUE(has(e, "chunk 2 (PRTC)") && has(e, "4294967295")) << e;
  // Intact framing, broken rule: a vector of another length than count, a flag or a lookup count
  // out of range (payloads built by hand: the writer's encode() aborts on such records).
  struct Broken {
    std::vector<float> x;
    std::vector<std::uint32_t> culled, lookups;
    std::string message;
  };
  for (const Broken& b : {Broken{{1.0f, 2.0f}, {1, 0, 0}, {1, 4, 0}, "field 'x' has 2 elements, but count is 3"},
                          Broken{{1.0f, 2.0f, 3.0f}, {0, 2, 0}, {1, 4, 0}, "field 'culled' of particle 1 is 2, above 1"},
                          Broken{{1.0f, 2.0f, 3.0f}, {1, 0, 0}, {1, 5, 0}, "field 'lookups' of particle 1 is 5, above 4"}}) {
    bytes::Out o;
    o.u32(3);
    o.counted_words(std::vector<std::uint32_t>{0, 0, 1});  // draw
    o.counted_words(b.x);
    for (int k = 0; k < 3; ++k) o.counted_words(std::vector<float>{1.0f, 2.0f, 3.0f});  // y, depth, size
    o.counted_words(b.culled);
    o.counted_words(b.lookups);
    o.counted_words(std::vector<std::uint32_t>{0, 0, 0});  // reference_samples
    e = record_error(kParticlesChunk, o.take());
    EXPECT_TRUE(has(e, "chunk 2 (PRTC)") && has(e, b.message)) << e;
  }
}

}  // namespace

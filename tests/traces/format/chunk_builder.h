// Helpers for the trace format's damage tests (TraceCorruptionTest and each technique's chunk
// test): a trace built chunk by chunk without the writer's checks, so that a rule can be broken on
// purpose, and the reader's refusal message.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "tests/traces/format/sample_trace.h"
#include "traces/format/bytes.h"

namespace nbsim::trace::testing {

inline bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Reads the whole trace from memory; returns the InputError's message, or "" when it reads.
inline std::string read_error(const Bytes& b) {
  try {
    read_all(TraceReader(b, "t.nbtrace"));
  } catch (const nbsim::InputError& e) {
    return e.what();
  }
  return "";
}

inline std::uint64_t le64_at(const Bytes& b, std::size_t at) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(b[at + i]) << (8 * i);
  return v;
}
inline void put_le32(Bytes& b, std::size_t at, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i) b[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline void put_le64(Bytes& b, std::size_t at, std::uint64_t v) {
  for (std::size_t i = 0; i < 8; ++i) b[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

// Recomputes the CRC of the chunk at `at` after its header or payload was edited on purpose.
inline void refit_crc(Bytes& b, std::size_t at) {
  const std::size_t stored = static_cast<std::size_t>(le64_at(b, at + 8));
  put_le32(b, at + kChunkHeaderBytes + stored, crc32(std::span(b).subspan(at, kChunkHeaderBytes + stored)));
}

// The chunk containing byte `at` (the last chunk starting at or before it).
inline std::size_t chunk_of(const std::vector<std::size_t>& offsets, std::size_t at) {
  std::size_t k = 0;
  while (k + 1 < offsets.size() && offsets[k + 1] <= at) ++k;
  return k;
}

// A hand-built trace: chunks framed by encode_chunk without the writer's checks, so that rules
// can be broken on purpose.
struct Builder {
  Bytes b;
  std::uint64_t chunks = 0;
  explicit Builder(std::uint32_t version = kFormatVersion) {
    const auto p = encode_preamble(version);
    b.assign(p.begin(), p.end());
  }
  Builder& chunk(ChunkType t, const Bytes& payload, bool compress = false, std::uint32_t flags = 0) {
    const Bytes c = encode_chunk(t, payload, compress, flags);
    b.insert(b.end(), c.begin(), c.end());
    ++chunks;
    return *this;
  }
  template <class R>
  Builder& add(const R& r) {
    return chunk(RecordChunk<R>::type, encode(r));
  }
  Builder& technique(const TechniqueRecord& r) { return chunk(static_cast<ChunkType>(r.type), encode(r), false, kFlagTechnique); }
  Builder& end(std::uint32_t frames) { return add(EndMarker{chunks, frames}); }
};

// A one-frame trace holding `r` as its only technique chunk (chunk 2, after HEAD and FRAM).
inline Bytes one_record_trace(const TechniqueRecord& r) {
  return Builder().add(Properties{}).add(sample_frame_begin(0)).technique(r).add(FrameEnd{0, 0, 0}).end(1).b;
}

// The reader's message for one_record_trace of a record of `type` with this payload ("" when it reads).
inline std::string record_error(std::uint32_t type, Bytes payload) {
  TechniqueRecord x;
  x.type = type;
  x.payload = std::move(payload);
  return read_error(one_record_trace(x));
}

// `r` reads back field for field from one_record_trace, and every byte of its chunk flipped is
// refused naming chunk 2 (`name` is the record's name in the failure messages).
inline void expect_reads_back_and_flips_refused(const TechniqueRecord& r, const std::string& name) {
  const Bytes trace = one_record_trace(r);
  {
    FrameReader frames(TraceReader(trace, "t.nbtrace"));
    const auto f = frames.next();
    ASSERT_TRUE(f);
    ASSERT_EQ(f->technique_records.size(), 1u);
    expect_same(r, f->technique_records[0]);
  }
  const std::vector<std::size_t> offsets = chunk_offsets(trace);
  for (std::size_t i = offsets[2]; i < offsets[3]; ++i) {  // HEAD, FRAM, the record
    Bytes b = trace;
    b[i] ^= 0x01;
    const std::string e = read_error(b);
    ASSERT_TRUE(has(e, "chunk 2 ")) << "byte " << i << " of " << name << " flipped: " << e;
  }
}

}  // namespace nbsim::trace::testing

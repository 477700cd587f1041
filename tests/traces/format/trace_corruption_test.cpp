// TraceCorruptionTest: every damaged or hostile trace is refused with an InputError that names the
// chunk and its byte offset: flipped bytes, truncation anywhere, empty files, garbage, lengths past
// the end, unknown types and flags, bad zstd, records that decode short or long, broken structure.
// Each technique's own chunks have their suite beside their folder (tests/traces/format/<technique>/).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "model/common/error.h"
#include "model/nbuffer/nbuffer.h"
#include "tests/traces/format/chunk_builder.h"
#include "traces/format/technique_chunks.h"

namespace {

using namespace nbsim::trace;
using namespace nbsim::trace::testing;
using nbsim::InputError;

Bytes sample_bytes() {
  static const Bytes b = [] {
    const fs::path f = scratch("sample.nbtrace");
    write_sample_trace(f);
    return read_file(f);
  }();
  return b;
}

// One valid chunk of every type: HEAD, SCEN, FRAM, DRAW, DPTH, NBLV, TRTH, DRWS, STNC, LGHT,
// FEND (and END). The depth snapshot is named "final" and the levels' source "after_occluders".
std::vector<std::pair<ChunkType, Bytes>> one_of_each() {
  return {{ChunkType::Header, encode(sample_properties())},
          {ChunkType::Scene, encode(sample_scene())},
          {ChunkType::FrameBegin, encode(sample_frame_begin(0))},
          {ChunkType::Draw, encode(sample_draw(0, 3))},
          {ChunkType::Depth, encode(sample_depth(DepthWhich::Final, 32, 16))},
          {ChunkType::Levels, encode(sample_levels(nbsim::FarOp::Max, 8, 4, 3))},
          {ChunkType::Truth, encode(sample_truth(6, 8, 4))},
          {ChunkType::DrawBatch, encode(DrawBatch{{sample_draw_v2(1, 3), sample_draw_v2(2, 0)}})},
          {ChunkType::Stencil, encode(sample_stencil("mask", 8, 4))},
          {ChunkType::Light, encode(sample_light(0))},
          {ChunkType::FrameEnd, encode(FrameEnd{0, 3, 0.5})}};
}

// The builder's traces are sound when nothing is broken (so each refusal below has one cause).
TEST(TraceCorruptionTest, BuilderBaselineReads) {
  Builder t;
  for (const auto& [type, payload] : one_of_each()) t.chunk(type, payload);
  t.end(1);
  EXPECT_EQ(read_error(t.b), "");
  EXPECT_EQ(read_error(sample_bytes()), "");
}

// Flipping any byte (all eight bits, or only the lowest) is refused, naming the chunk that holds it.
TEST(TraceCorruptionTest, EveryFlippedByteRefused) {
  const Bytes good = sample_bytes();
  const std::vector<std::size_t> offsets = chunk_offsets(good);
  for (std::size_t i = 0; i < good.size(); ++i) {
    for (const std::uint8_t mask : {std::uint8_t{0xFF}, std::uint8_t{0x01}}) {
      Bytes b = good;
      b[i] ^= mask;
      const std::string e = read_error(b);
      ASSERT_FALSE(e.empty()) << "byte " << i << " flipped with mask " << int(mask) << " was not detected";
      if (i < kMagic.size()) {
        EXPECT_TRUE(has(e, "not an nbsim trace")) << "byte " << i << ": " << e;
      } else if (i < kPreambleBytes) {
        EXPECT_TRUE(has(e, "preamble at byte 0: CRC-32 mismatch")) << "byte " << i << ": " << e;
      } else {
        const std::size_t k = chunk_of(offsets, i);
        EXPECT_TRUE(has(e, "chunk " + std::to_string(k) + " ") && has(e, "at byte " + std::to_string(offsets[k]) + ":"))
            << "byte " << i << " lies in chunk " << k << " at " << offsets[k] << ": " << e;
      }
    }
  }
}

// Cutting the file at any length is refused, naming the chunk cut (or the missing END's place).
TEST(TraceCorruptionTest, EveryTruncationRefused) {
  const Bytes good = sample_bytes();
  const std::vector<std::size_t> offsets = chunk_offsets(good);
  for (std::size_t n = 0; n < good.size(); ++n) {
    const Bytes b(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(n));
    const std::string e = read_error(b);
    ASSERT_FALSE(e.empty()) << "a trace cut to " << n << " bytes was accepted";
    if (n == 0) {
      EXPECT_TRUE(has(e, "empty")) << e;
    } else if (n < kPreambleBytes) {
      EXPECT_TRUE(has(e, "preamble") && has(e, "truncated")) << n << ": " << e;
    } else {
      const std::size_t k = n >= offsets.back() ? offsets.size() - 1 : chunk_of(offsets, n);
      EXPECT_TRUE(has(e, "chunk " + std::to_string(k) + " ") && has(e, "at byte " + std::to_string(offsets[k]) + ":"))
          << "cut at " << n << " inside chunk " << k << ": " << e;
      EXPECT_TRUE(has(e, "truncated") || has(e, "past the end")) << n << ": " << e;
    }
  }
}

// The same through the file reader, on disk, for a spread of lengths.
TEST(TraceCorruptionTest, TruncatedFilesOnDiskRefused) {
  const Bytes good = sample_bytes();
  const fs::path f = scratch("cut.nbtrace");
  for (std::size_t n = 0; n < good.size(); n += 97) {
    write_file(f, Bytes(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(n)));
    EXPECT_THROW(read_all(TraceReader(f)), InputError) << "cut to " << n;
  }
}

// A zero-length file is refused as empty, naming the file.
TEST(TraceCorruptionTest, ZeroLengthFile) {
  const fs::path f = scratch("zero.nbtrace");
  write_file(f, {});
  try {
    TraceReader t(f);
    FAIL() << "an empty file was accepted";
  } catch (const InputError& e) {
    EXPECT_TRUE(has(e.what(), f.string()) && has(e.what(), "empty (0 bytes)")) << e.what();
  }
}

// Garbage is not a trace; garbage after a valid preamble is refused at chunk 0.
TEST(TraceCorruptionTest, Garbage) {
  Lcg rng{5};
  Bytes junk(4096);
  for (auto& c : junk) c = static_cast<std::uint8_t>(rng.next() >> 24);
  const fs::path f = scratch("junk.nbtrace");
  write_file(f, junk);
  try {
    TraceReader t(f);
    FAIL() << "garbage accepted";
  } catch (const InputError& e) {
    EXPECT_TRUE(has(e.what(), "not an nbsim trace")) << e.what();
  }
  for (std::uint32_t seed = 0; seed < 64; ++seed) {
    Builder t;
    Lcg r{seed};
    for (int i = 0; i < 200; ++i) t.b.push_back(static_cast<std::uint8_t>(r.next() >> 24));
    const std::string e = read_error(t.b);
    EXPECT_TRUE(has(e, "chunk 0 ") && has(e, "at byte 16:")) << e;
  }
  const std::string text = "This is a text file, not a trace.\n";
  EXPECT_TRUE(has(read_error(Bytes(text.begin(), text.end())), "not an nbsim trace"));
}

// A stored length past the end of the file or above the limit is refused before any allocation.
TEST(TraceCorruptionTest, LengthPastTheEnd) {
  const Bytes good = sample_bytes();
  const std::vector<std::size_t> offsets = chunk_offsets(good);
  const std::size_t at = offsets[3];  // the DRAW batch of frame 0
  struct Row {
    std::uint64_t stored;
    std::string message;
  };
  const Row rows[] = {
      {good.size(), "points past the end of the file"},
      {good.size() - at - kChunkHeaderBytes - 3, "points past the end of the file"},  // the CRC cannot fit
      {std::uint64_t{1} << 62, "exceeds the format's chunk limit"},
      {~std::uint64_t{0}, "exceeds the format's chunk limit"},
  };
  for (const Row& row : rows) {
    Bytes b = good;
    put_le64(b, at + 8, row.stored);
    const std::string e = read_error(b);
    EXPECT_TRUE(has(e, row.message) && has(e, "chunk 3 (DRWS) at byte " + std::to_string(at) + ":")) << e;
  }
}

// Framing that is intact (CRC fixed up) but means nothing to this version is refused.
TEST(TraceCorruptionTest, UnknownTypesFlagsAndLengths) {
  const Bytes good = sample_bytes();
  const std::vector<std::size_t> offsets = chunk_offsets(good);
  const std::size_t at = offsets[3];
  struct Row {
    std::function<void(Bytes&)> edit;
    std::string message;
  };
  const Row rows[] = {
      {[&](Bytes& b) { put_le32(b, at, fourcc("ZZZZ")); }, "chunk 3 (ZZZZ)"},              // unknown type, named
      {[&](Bytes& b) { put_le32(b, at, 0x00000001); }, "chunk 3 (0x00000001)"},          // unprintable type in hex
      {[&](Bytes& b) { put_le32(b, at + 4, 4); }, "unknown flags 0x00000004"},           // reserved flag bits
      {[&](Bytes& b) { put_le32(b, at + 4, kFlagTechnique); }, "core chunk type flagged as a technique"},
      {[&](Bytes& b) { put_le64(b, at + 16, le64_at(b, at + 8) + 1); }, "raw length"},   // raw != stored, uncompressed
      {[&](Bytes& b) { put_le64(b, at + 16, (std::uint64_t{256} << 20) + 1); }, "raw length 268435457 exceeds"},
      {[&](Bytes& b) { put_le32(b, at + 4, kFlagZstd); }, "not a zstd frame"},          // flagged but not zstd
  };
  for (const Row& row : rows) {
    Bytes b = good;
    row.edit(b);
    refit_crc(b, at);
    const std::string e = read_error(b);
    EXPECT_TRUE(has(e, row.message) && has(e, "at byte " + std::to_string(at) + ":")) << "expected '" << row.message << "': " << e;
  }
  EXPECT_TRUE(has(read_error([&] {
                    Bytes b = good;
                    put_le32(b, at, fourcc("ZZZZ"));
                    refit_crc(b, at);
                    return b;
                  }()),
                  "unknown chunk type"));
}

// A zstd payload that does not decompress to the declared raw length is refused.
TEST(TraceCorruptionTest, BadZstdPayloads) {
  const Bytes depth = encode(sample_depth(DepthWhich::Final, 32, 32));
  const Bytes framed = encode_chunk(ChunkType::Depth, depth, true);
  ASSERT_EQ(framed[4], kFlagZstd) << "the test needs a compressed chunk";
  auto trace_with = [&](const std::function<void(Bytes&)>& edit) {
    Builder t;
    t.add(Properties{}).add(sample_frame_begin(0));
    Bytes c = framed;
    edit(c);
    refit_crc(c, 0);
    t.b.insert(t.b.end(), c.begin(), c.end());
    ++t.chunks;
    t.add(FrameEnd{0, 0, 0.0}).end(1);
    return t.b;
  };
  EXPECT_EQ(read_error(trace_with([](Bytes&) {})), "") << "baseline";
  // The raw length disagrees with the frame's content size.
  std::string e = read_error(trace_with([](Bytes& c) { put_le64(c, 16, le64_at(c, 16) - 4); }));
  EXPECT_TRUE(has(e, "the zstd frame holds") && has(e, "chunk 2 (DPTH)")) << e;
  // The compressed bytes are damaged after the frame header (CRC recomputed).
  e = read_error(trace_with([](Bytes& c) {
    for (std::size_t i = kChunkHeaderBytes + 8; i < c.size() - kChunkCrcBytes; i += 3) c[i] ^= 0x5A;
  }));
  EXPECT_TRUE(has(e, "chunk 2 (DPTH)") && (has(e, "zstd") || has(e, "decompresses"))) << e;
}

// Every record type refuses a payload one byte short or one byte long (CRC intact).
TEST(TraceCorruptionTest, RecordsThatDecodeShortOrLong) {
  const auto chunks = one_of_each();
  for (std::size_t k = 0; k <= chunks.size(); ++k) {  // k == chunks.size(): the END record
    for (const bool longer : {false, true}) {
      Builder t;
      for (std::size_t i = 0; i < chunks.size(); ++i) {
        Bytes p = chunks[i].second;
        if (i == k) longer ? p.push_back(0) : p.pop_back();
        t.chunk(chunks[i].first, p, i == 4);  // the depth snapshot compressed, to decode through zstd
      }
      Bytes end = encode(EndMarker{t.chunks, 1});
      if (k == chunks.size()) longer ? end.push_back(0) : end.pop_back();
      t.chunk(ChunkType::End, end);
      const std::string e = read_error(t.b);
      const std::string type = k == chunks.size() ? "END " : chunk_type_name(chunks[k].first);
      EXPECT_TRUE(has(e, "chunk " + std::to_string(k) + " (" + type + ")")) << e;
      EXPECT_TRUE(has(e, longer ? "decodes long" : "decodes short")) << type << (longer ? " long: " : " short: ") << e;
    }
  }
}

// Field values outside their types are refused, naming the field.
TEST(TraceCorruptionTest, FieldValuesOutOfRange) {
  struct Row {
    ChunkType type;
    std::function<void(Bytes&)> edit;
    std::string message;
  };
  const Row rows[] = {
      {ChunkType::Draw, [](Bytes& p) { p[4] = 16; }, "field 'role' is 16"},                     // DrawRole 0..15
      {ChunkType::Draw, [](Bytes& p) { p[15] = 2; }, "field 'state.write' is 2, not 0 or 1"},   // bools are 0/1
      {ChunkType::Draw, [](Bytes& p) { p[14] = 8; }, "state.func"},                             // DepthFunc 0..7
      {ChunkType::Draw, [](Bytes& p) { p[13] = 32; }, "field 'level' is 32"},                  // levels below 32
      {ChunkType::FrameBegin, [](Bytes& p) { p[4] = 5; }, "field 'mode' is 5"},                 // TestMode 0..4
      {ChunkType::Depth, [](Bytes& p) { put_le32(p, 0, 0); }, "field 'width' is 1634625894"},  // "fina" read as a width
      {ChunkType::Depth, [](Bytes& p) { p[4] = ' '; }, "depth image name ' inal' is not"},          // names are like keys
      {ChunkType::Depth, [](Bytes& p) { put_le32(p, 9, 0); }, "field 'width' is 0, outside 1 .. 16384"},  // sides >= 1
      {ChunkType::Depth, [](Bytes& p) { put_le32(p, 9, 100000); }, "field 'width' is 100000"},
      {ChunkType::Depth, [](Bytes& p) { put_le32(p, 9, 0x80000000u); }, "field 'width' is -2147483648"},  // negative side
      {ChunkType::Depth, [](Bytes& p) { put_le32(p, 0, 65); }, "is a string of 65 bytes, above the limit of 64"},
      {ChunkType::Levels, [](Bytes& p) { p[19] = 2; }, "field 'op' is 2"},                      // FarOp 0..1
      {ChunkType::Levels, [](Bytes& p) { put_le32(p, 28, 33); }, "field 'levels' is 33"},       // at most 32 levels
      {ChunkType::Draw, [](Bytes& p) { p[80 + 48] = 2; }, "field 'topology' is 2"},            // Topology 0..1
      {ChunkType::DrawBatch, [](Bytes& p) { p[4 + 4] = 16; }, "field 'role' is 16"},              // each draw checked
      // The batch's first draw: 128 bytes of version 1 fields, topology, 3 point sizes, stencil.test,
      // stencil.front.func, ref, value_mask, write_mask, then stencil.front.fail at 4 + 159.
      {ChunkType::DrawBatch, [](Bytes& p) { p[4 + 159] = 8; }, "field 'stencil.front.fail' is 8"},  // StencilOp 0..7
      {ChunkType::Draw, [](Bytes& p) { p[128] = 1; }, "point draw with 3 vertices and 0 point sizes"},  // sizes per point
      {ChunkType::Stencil, [](Bytes& p) { put_le32(p, 8, 0); }, "field 'width' is 0"},
      {ChunkType::Stencil, [](Bytes& p) { put_le32(p, 12, 1000); }, "needs 8000 bytes"},         // texels past the end
      {ChunkType::Truth, [](Bytes& p) { put_le32(p, 0, 0xFFFFFFFFu); }, "counts 4294967295 elements"},  // hostile count
      {ChunkType::Scene, [](Bytes& p) { put_le32(p, 0, 0x7FFFFFFFu); }, "counts 2147483647 elements"},
      {ChunkType::Header, [](Bytes& p) { put_le32(p, 0, 5000); }, "counts 5000 elements"},
  };
  for (const Row& row : rows) {
    Builder t;
    std::size_t k = 0, at = 0;
    for (const auto& [type, payload] : one_of_each()) {
      Bytes p = payload;
      if (type == row.type) {
        row.edit(p);
        k = t.chunks;
        at = t.b.size();
      }
      t.chunk(type, p);
    }
    t.end(1);
    const std::string e = read_error(t.b);
    EXPECT_TRUE(has(e, row.message)) << "expected '" << row.message << "': " << e;
    EXPECT_TRUE(has(e, "chunk " + std::to_string(k) + " (" + chunk_type_name(row.type) + ") at byte " + std::to_string(at)))
        << e;
  }
}

// Chunks in an order the format forbids, or counts that disagree, are refused (FORMAT.md
// "Structure"), naming the offending chunk.
TEST(TraceCorruptionTest, StructureRulesRefused) {
  const FrameEnd fend0{0, 0, 0.0};
  auto draw = [](std::uint32_t index, std::int32_t object, std::int32_t node) {
    DrawRecord d = sample_draw(index, 0);
    d.object = object;
    d.node = node;
    return d;
  };
  GroundTruth bad_ids = sample_truth(6, 8, 4);
  bad_ids.ids[3] = 6;
  struct Row {
    std::function<Bytes()> build;
    std::string chunk;  // "chunk N (TYPE)"
    std::string message;
  };
  const Properties P;
  const Row rows[] = {
      {[&] { return Builder().add(sample_frame_begin(0)).b; }, "chunk 0 (FRAM)", "the first chunk must be HEAD"},
      {[&] { return Builder().add(P).add(P).end(0).b; }, "chunk 1 (HEAD)", "a second HEAD"},
      {[&] { return Builder().add(P).add(sample_frame_begin(0)).add(fend0).add(sample_scene()).end(1).b; },
       "chunk 3 (SCEN)", "directly follow HEAD"},
      {[&] { return Builder().add(P).add(draw(0, -1, -1)).b; }, "chunk 1 (DRAW)", "outside a frame"},
      {[&] { return Builder().add(P).add(sample_truth(0, 0, 0)).b; }, "chunk 1 (TRTH)", "outside a frame"},
      {[&] { return Builder().add(P).add(fend0).b; }, "chunk 1 (FEND)", "FEND outside a frame"},
      {[&] { return Builder().add(P).add(sample_frame_begin(0)).add(sample_frame_begin(1)).b; }, "chunk 2 (FRAM)",
       "FEND is missing"},
      {[&] { return Builder().add(P).add(sample_frame_begin(3)).add(FrameEnd{3, 0, 0}).add(sample_frame_begin(3)).b; },
       "chunk 3 (FRAM)", "frame number 3 does not increase"},
      {[&] { return Builder().add(P).add(sample_frame_begin(0)).add(FrameEnd{1, 0, 0}).b; }, "chunk 2 (FEND)",
       "FEND of frame 1 closes frame 0"},
      {[&] { return Builder().add(P).add(sample_frame_begin(0)).add(draw(0, -1, -1)).add(FrameEnd{0, 2, 0}).b; },
       "chunk 3 (FEND)", "counts 2 draws, but frame 0 has 1"},
      {[&] { return Builder().add(P).add(sample_frame_begin(0)).end(0).b; }, "chunk 2 (END )", "END inside frame 0"},
      {[&] { return Builder().add(P).add(EndMarker{5, 0}).b; }, "chunk 1 (END )", "counts 5 chunks"},
      {[&] { return Builder().add(P).add(sample_frame_begin(0)).add(fend0).add(EndMarker{3, 2}).b; }, "chunk 3 (END )",
       "counts 2 frames, the file has 1"},
      {[&] {
         Bytes b = Builder().add(P).end(0).b;
         b.push_back(0);
         return b;
       },
       "chunk 1 (END )", "data follows the END chunk"},
      {[&] {
         Builder t;
         t.add(P).end(0);
         t.add(sample_frame_begin(0));
         return t.b;
       },
       "chunk 1 (END )", "data follows the END chunk"},
      // Per-record rules, checked by the frame reader.
      {[&] { return Builder().add(P).add(sample_frame_begin(0)).add(draw(1, -1, -1)).add(FrameEnd{0, 1, 0}).end(1).b; },
       "chunk 2 (DRAW)", "draw index 1 in frame 0, expected 0"},
      {[&] {
         return Builder().add(P).add(sample_frame_begin(0)).add(sample_depth(DepthWhich::Final, 2, 2))
             .add(sample_depth(DepthWhich::Final, 2, 2)).add(fend0).end(1).b;
       },
       "chunk 3 (DPTH)", "a second 'final' depth snapshot"},
      {[&] {
         return Builder().add(P).add(sample_frame_begin(0)).add(sample_levels(nbsim::FarOp::Min, 2, 2, 1))
             .add(sample_levels(nbsim::FarOp::Min, 2, 2, 1)).add(fend0).end(1).b;
       },
       "chunk 3 (NBLV)", "a second N-buffer with op 'min'"},
      {[&] {
         return Builder().add(P).add(sample_frame_begin(0)).add(sample_truth(0, 0, 0)).add(sample_truth(0, 0, 0))
             .add(fend0).end(1).b;
       },
       "chunk 3 (TRTH)", "a second ground truth"},
      {[&] {
         return Builder().add(P).add(sample_scene()).add(sample_frame_begin(0)).add(draw(0, 6, -1)).add(FrameEnd{0, 1, 0})
             .end(1).b;
       },
       "chunk 3 (DRAW)", "names object 6, but the scene has 6 objects"},
      {[&] {
         return Builder().add(P).add(sample_scene()).add(sample_frame_begin(0)).add(draw(0, 1, 3)).add(FrameEnd{0, 1, 0})
             .end(1).b;
       },
       "chunk 3 (DRAW)", "BVH node 3"},
      {[&] {
         return Builder().add(P).add(sample_scene()).add(sample_frame_begin(0)).add(sample_truth(5, 0, 0)).add(fend0)
             .end(1).b;
       },
       "chunk 3 (TRTH)", "ground truth for 5 objects, but the scene has 6"},
      {[&] { return Builder().add(P).add(sample_scene()).add(sample_frame_begin(0)).add(bad_ids).add(fend0).end(1).b; },
       "chunk 3 (TRTH)", "ID-buffer pixel 3 holds object 6"},
  };
  for (const Row& row : rows) {
    const std::string e = read_error(row.build());
    EXPECT_TRUE(has(e, row.chunk) && has(e, row.message)) << "expected " << row.chunk << ": '" << row.message << "' in: " << e;
  }
  // Without a scene, object and node ids are not checked against anything.
  EXPECT_EQ(read_error(Builder().add(P).add(sample_frame_begin(0)).add(draw(0, 99, 99)).add(FrameEnd{0, 1, 0}).end(1).b), "");
}

// Version 2's chunk types and the technique flag do not exist in a version-1 file: refused.
TEST(TraceCorruptionTest, Version2ChunksRefusedInVersion1Files) {
  const Properties P;
  struct Row {
    std::function<void(Builder&)> add;
    std::string message;
  };
  const Row rows[] = {
      {[](Builder& t) { t.add(DrawBatch{{sample_draw(0, 3)}}); }, "chunk type DRWS exists since format version 2, the file is version 1"},
      {[](Builder& t) { t.add(sample_stencil("m", 2, 2)); }, "chunk type STNC exists since format version 2"},
      {[](Builder& t) { t.add(sample_light(0)); }, "chunk type LGHT exists since format version 2"},
      {[](Builder& t) { t.technique(sample_raw_record()); }, "unknown flags 0x00000002 (format version 1)"},
  };
  for (const Row& row : rows) {
    Builder t(1);
    t.add(P).add(sample_frame_begin(0));
    row.add(t);
    t.add(FrameEnd{0, 1, 0}).end(1);
    const std::string e = read_error(t.b);
    EXPECT_TRUE(has(e, "chunk 2 (") && has(e, row.message)) << "expected '" << row.message << "': " << e;
  }
}

// Technique chunks: a registered type decodes into its fields, an unregistered one is kept raw;
// one outside a frame, one that does not match its registered description, or the flag on an
// unprintable type is refused naming the chunk.
TEST(TraceCorruptionTest, TechniqueChunks) {
  const Properties P;
  const TechniqueRecord good = sample_technique_record(3);
  {
    Builder t;
    t.add(P).add(sample_frame_begin(0)).technique(good).technique(sample_raw_record()).add(FrameEnd{0, 0, 0}).end(1);
    FrameReader frames(TraceReader(t.b, "t.nbtrace"));
    const auto f = frames.next();
    ASSERT_TRUE(f);
    ASSERT_EQ(f->technique_records.size(), 2u);
    expect_same(good, f->technique_records[0]);
    EXPECT_TRUE(f->technique_records[0].payload.empty()) << "a decoded record keeps its fields, not its bytes";
    EXPECT_FALSE(f->technique_records[1].decoded) << "an unregistered type stays raw";
    EXPECT_EQ(f->technique_records[1].payload, sample_raw_record().payload);
  }
  std::string e = read_error(Builder().add(P).technique(good).b);
  EXPECT_TRUE(has(e, "chunk 1 (TSTX)") && has(e, "outside a frame")) << e;
  TechniqueRecord shorter = good;
  shorter.decoded = false;  // written as its payload, one byte short
  shorter.payload = encode(good);
  shorter.payload.pop_back();
  e = read_error(Builder().add(P).add(sample_frame_begin(0)).technique(shorter).add(FrameEnd{0, 0, 0}).end(1).b);
  EXPECT_TRUE(has(e, "chunk 2 (TSTX)") && has(e, "decodes short")) << e;
  TechniqueRecord longer = shorter;
  longer.payload = encode(good);
  longer.payload.push_back(0);
  e = read_error(Builder().add(P).add(sample_frame_begin(0)).technique(longer).add(FrameEnd{0, 0, 0}).end(1).b);
  EXPECT_TRUE(has(e, "chunk 2 (TSTX)") && has(e, "decodes long")) << e;
  Builder t;
  t.add(P).add(sample_frame_begin(0)).chunk(static_cast<ChunkType>(0x01020304u), {1, 2}, false, kFlagTechnique);
  e = read_error(t.b);
  EXPECT_TRUE(has(e, "chunk 2 (0x01020304)") && has(e, "four printable characters")) << e;
}

// A chunk whose stored payload is empty: its CRC covers the chunk header alone, as the writer
// computes it (zlib's CRC of an empty, null buffer is 0 whatever the running value, so a reader
// that used it would refuse such chunks as damaged). An unknown technique chunk with no payload
// reads and stays raw, and the writer writes one that reads back; a known chunk with no payload is
// refused for what it is, a record that ends before its fields, never as a CRC mismatch.
TEST(TraceCorruptionTest, EmptyPayloads) {
  const Properties P;
  TechniqueRecord empty;
  empty.type = fourcc("EMPT");
  {
    Builder t;
    t.add(P).add(sample_frame_begin(0)).technique(empty).add(FrameEnd{0, 0, 0}).end(1);
    ASSERT_EQ(read_error(t.b), "");
    FrameReader frames(TraceReader(t.b, "t.nbtrace"));
    const auto f = frames.next();
    ASSERT_TRUE(f);
    ASSERT_EQ(f->technique_records.size(), 1u);
    EXPECT_FALSE(f->technique_records[0].decoded);
    EXPECT_EQ(f->technique_records[0].type, fourcc("EMPT"));
    EXPECT_TRUE(f->technique_records[0].payload.empty());
  }
  {
    const fs::path file = scratch("empty_chunk.nbtrace");
    TraceWriter w(file, {});
    w.begin_frame(FrameBegin{});
    w.write(empty);
    w.end_frame({0, 0, 0.0});
    w.close();
    FrameReader frames(file);
    const auto f = frames.next();
    ASSERT_TRUE(f);
    ASSERT_EQ(f->technique_records.size(), 1u);
    EXPECT_TRUE(f->technique_records[0].payload.empty());
    EXPECT_FALSE(frames.next());
  }
  // Every known type with an empty payload, where its kind of chunk may stand.
  const auto refused = [&](const Bytes& b, const std::string& chunk) {
    const std::string e = read_error(b);
    EXPECT_TRUE(has(e, chunk)) << chunk << ": " << e;
    EXPECT_FALSE(has(e, "CRC")) << chunk << ": " << e;
    EXPECT_TRUE(has(e, "the payload of 0 bytes") && has(e, "(it decodes short)")) << chunk << ": " << e;
  };
  refused(Builder().chunk(ChunkType::Header, {}).b, "chunk 0 (HEAD)");
  refused(Builder().add(P).chunk(ChunkType::Scene, {}).b, "chunk 1 (SCEN)");
  refused(Builder().add(P).chunk(ChunkType::FrameBegin, {}).b, "chunk 1 (FRAM)");
  for (const ChunkType t : {ChunkType::Draw, ChunkType::Depth, ChunkType::Levels, ChunkType::Truth, ChunkType::DrawBatch,
                            ChunkType::Stencil, ChunkType::Light, ChunkType::FrameEnd})
    refused(Builder().add(P).add(sample_frame_begin(0)).chunk(t, {}).b, "chunk 2 (" + chunk_type_name(static_cast<std::uint32_t>(t)) + ")");
  refused(Builder().add(P).chunk(ChunkType::End, {}).b, "chunk 1 (END )");
  ASSERT_FALSE(technique_chunks().empty());
  for (const ChunkSpec& spec : technique_chunks())
    refused(Builder().add(P).add(sample_frame_begin(0)).chunk(static_cast<ChunkType>(spec.type), {}, false, kFlagTechnique).b,
            "chunk 2 (" + chunk_type_name(spec.type) + ")");
}

// Draw batches: empty ones, counts past the payload, indices that do not continue across DRAW and
// DRWS chunks, and FEND counts that disagree with the batched draws are refused.
TEST(TraceCorruptionTest, DrawBatchRules) {
  const Properties P;
  auto with_index = [](std::uint32_t i) { return sample_draw(i, 3); };
  struct Row {
    std::function<Bytes()> build;
    std::string chunk, message;
  };
  const Row rows[] = {
      {[&] { return Builder().add(P).add(sample_frame_begin(0)).add(DrawBatch{}).add(FrameEnd{0, 0, 0}).end(1).b; },
       "chunk 2 (DRWS)", "an empty draw batch"},
      {[&] {
         return Builder().add(P).add(sample_frame_begin(0)).chunk(ChunkType::DrawBatch, {1, 0}).add(FrameEnd{0, 0, 0}).end(1).b;
       },
       "chunk 2 (DRWS)", "too short for a draw count"},
      {[&] {
         Bytes p = encode(DrawBatch{{with_index(0)}});
         put_le32(p, 0, 3);  // three draws announced, one there
         return Builder().add(P).add(sample_frame_begin(0)).chunk(ChunkType::DrawBatch, p).add(FrameEnd{0, 3, 0}).end(1).b;
       },
       "chunk 2 (DRWS)", "decodes short"},
      {[&] {
         return Builder().add(P).add(sample_frame_begin(0)).add(with_index(0)).add(DrawBatch{{with_index(2)}})
             .add(FrameEnd{0, 2, 0}).end(1).b;
       },
       "chunk 3 (DRWS)", "draw index 2 in frame 0, expected 1"},
      {[&] {
         return Builder().add(P).add(sample_frame_begin(0)).add(DrawBatch{{with_index(0), with_index(1)}})
             .add(FrameEnd{0, 1, 0}).end(1).b;
       },
       "chunk 3 (FEND)", "counts 1 draws, but frame 0 has 2"},
  };
  for (const Row& row : rows) {
    const std::string e = read_error(row.build());
    EXPECT_TRUE(has(e, row.chunk) && has(e, row.message)) << "expected " << row.chunk << ": '" << row.message << "' in: " << e;
  }
  // DRAW chunks and batches mix, indices continuing.
  EXPECT_EQ(read_error(Builder().add(P).add(sample_frame_begin(0)).add(with_index(0)).add(DrawBatch{{with_index(1), with_index(2)}})
                           .add(with_index(3)).add(FrameEnd{0, 4, 0}).end(1).b),
            "");
}

// Version 2's per-frame rules: names unique per kind, one light, one N-buffer per (source, op).
TEST(TraceCorruptionTest, Version2FrameRules) {
  const Properties P;
  const FrameEnd fend0{0, 0, 0.0};
  NBufferLevels from_litmap = sample_levels(nbsim::FarOp::Min, 2, 2, 1);
  from_litmap.source = "litmap_min";
  struct Row {
    std::function<Bytes()> build;
    std::string chunk, message;
  };
  const Row rows[] = {
      {[&] {
         return Builder().add(P).add(sample_frame_begin(0)).add(sample_stencil("mask", 2, 2)).add(sample_stencil("mask", 1, 1))
             .add(fend0).end(1).b;
       },
       "chunk 3 (STNC)", "a second 'mask' stencil snapshot in frame 0"},
      {[&] { return Builder().add(P).add(sample_frame_begin(0)).add(sample_light(0)).add(sample_light(1)).add(fend0).end(1).b; },
       "chunk 3 (LGHT)", "a second light camera in frame 0"},
      {[&] {
         return Builder().add(P).add(sample_frame_begin(0)).add(from_litmap).add(from_litmap).add(fend0).end(1).b;
       },
       "chunk 3 (NBLV)", "a second N-buffer with op 'min' built from 'litmap_min'"},
      {[&] { return Builder().add(P).add(sample_light(0)).b; }, "chunk 1 (LGHT)", "outside a frame"},
      {[&] { return Builder().add(P).add(sample_stencil("m", 1, 1)).b; }, "chunk 1 (STNC)", "outside a frame"},
  };
  for (const Row& row : rows) {
    const std::string e = read_error(row.build());
    EXPECT_TRUE(has(e, row.chunk) && has(e, row.message)) << "expected " << row.chunk << ": '" << row.message << "' in: " << e;
  }
  // The same op from two sources is two level sets.
  EXPECT_EQ(read_error(Builder().add(P).add(sample_frame_begin(0)).add(sample_levels(nbsim::FarOp::Min, 2, 2, 1)).add(from_litmap)
                           .add(fend0).end(1).b),
            "");
}

// Flipping any byte of a trace made of version 2's chunks (DRWS, STNC, LGHT, a technique chunk)
// is refused, naming the chunk that holds it.
TEST(TraceCorruptionTest, EveryFlippedByteOfVersion2ChunksRefused) {
  Builder t;
  t.add(Properties{{"viewport", "8x4"}}).add(sample_frame_begin(0));
  t.add(DrawBatch{{sample_draw_v2(0, 3), sample_draw_v2(1, 2)}}).add(sample_stencil("mask", 8, 4)).add(sample_light(0));
  t.technique(sample_technique_record(1)).add(FrameEnd{0, 2, 0.0}).end(1);
  const Bytes good = t.b;
  ASSERT_EQ(read_error(good), "");
  const std::vector<std::size_t> offsets = chunk_offsets(good);
  for (std::size_t i = kPreambleBytes; i < good.size(); ++i) {
    for (const std::uint8_t mask : {std::uint8_t{0xFF}, std::uint8_t{0x01}}) {
      Bytes b = good;
      b[i] ^= mask;
      const std::string e = read_error(b);
      ASSERT_FALSE(e.empty()) << "byte " << i << " flipped with mask " << int(mask) << " was not detected";
      const std::size_t k = chunk_of(offsets, i);
      EXPECT_TRUE(has(e, "chunk " + std::to_string(k) + " ") && has(e, "at byte " + std::to_string(offsets[k]) + ":"))
          << "byte " << i << " lies in chunk " << k << " at " << offsets[k] << ": " << e;
    }
  }
}

// Hostile payloads behind intact CRCs: random bytes overwritten in every record type (version 2's
// included) are either read or refused with an InputError naming the chunk; the reader never
// aborts or crashes on them (each read runs in this process: an abort fails the whole suite).
TEST(TraceCorruptionTest, RandomPayloadEditsNeverCrash) {
  const auto chunks = one_of_each();
  Lcg rng{2026};
  int refused = 0, read = 0;
  for (int round = 0; round < 3000; ++round) {
    const std::size_t k = rng.next() % chunks.size();
    Builder t;
    for (std::size_t i = 0; i < chunks.size(); ++i) {
      Bytes p = chunks[i].second;
      if (i == k && !p.empty()) {
        const std::uint32_t edits = 1 + rng.next() % 4;
        for (std::uint32_t e = 0; e < edits; ++e) p[rng.next() % p.size()] = static_cast<std::uint8_t>(rng.next() >> 24);
      }
      t.chunk(chunks[i].first, p);
    }
    t.end(1);
    const std::string e = read_error(t.b);
    if (e.empty()) {
      ++read;
      continue;
    }
    ++refused;
    EXPECT_TRUE(has(e, "t.nbtrace: chunk ")) << "refusals name the file and chunk: " << e;
  }
  EXPECT_GT(refused, 500) << "random edits of ids, counts, enums and names break rules";
  EXPECT_GT(read, 0) << "edits of float fields read as other values";
}

// A header property value that is not UTF-8 is refused at chunk 0, naming the key and the byte
// (run.json and `trace info --json` hold the values, and JSON is UTF-8); valid UTF-8 reads.
TEST(TraceCorruptionTest, NonUtf8PropertyValueRefused) {
  const struct {
    const char* value;
    const char* why;
  } bad[] = {
      {"city\xff", "0xff never occurs in UTF-8"},
      {"\x80lone", "a continuation byte without a lead byte"},
      {"\xc0\xaf", "an overlong encoding of '/'"},
      {"\xed\xa0\x80", "a UTF-16 surrogate (U+D800)"},
      {"\xf4\x90\x80\x80", "above U+10FFFF"},
      {"ab\xe2\x82", "a sequence cut short by the end"},
      {"\xe2(\xa1", "a lead byte followed by ASCII"},
  };
  for (const auto& row : bad) {
    Builder t;
    t.add(Properties{{"viewport", "8x8"}, {"scene", row.value}}).end(0);
    const std::string e = read_error(t.b);
    EXPECT_TRUE(has(e, "chunk 0 (HEAD)") && has(e, "property 'scene'") && has(e, "not UTF-8")) << row.why << ": " << e;
  }
  Builder good;
  good.add(Properties{{"viewport", "8x8"}, {"scene", "na\xc3\xafve \xe2\x9c\x93 \xf0\x9d\x84\x9e"}}).end(0);
  EXPECT_EQ(read_error(good.b), "") << "two-, three- and four-byte UTF-8 read";
}

// Replay compares the depth images "after_occluders" and "final" with a depth buffer of the
// viewport's size: a reader asked for them refuses one of another size (swapped sides, 1xN, a
// viewport edited in the header), naming the chunk; other images, and the same file read without
// the request, may have any size (a technique's litmaps need not match the viewport).
TEST(TraceCorruptionTest, ReplayedDepthOfAnotherSizeThanTheViewportRefused) {
  const auto read = [](const Bytes& b) {
    try {
      FrameReader frames(TraceReader(b, "t.nbtrace"));
      frames.require_viewport_depths({"after_occluders", "final"});
      while (frames.next()) {
      }
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const struct {
    const char* viewport;
    DepthSnapshot depth;
    const char* what;
  } rows[] = {
      {"8x4", sample_depth(DepthWhich::Final, 4, 8), "depth image 'final' is 4x8, but the header's viewport is 8x4"},
      {"8x4", sample_depth(DepthWhich::AfterOccluders, 1, 32), "depth image 'after_occluders' is 1x32"},
      {"9x4", sample_depth(DepthWhich::Final, 8, 4), "depth image 'final' is 8x4, but the header's viewport is 9x4"},
  };
  for (const auto& row : rows) {
    Builder t;
    t.add(Properties{{"viewport", row.viewport}}).add(sample_frame_begin(0)).add(row.depth).add(FrameEnd{0, 0, 0.0}).end(1);
    EXPECT_EQ(read_error(t.b), "") << row.what << ": the format itself allows any size";
    const std::string e = read(t.b);
    EXPECT_TRUE(has(e, "t.nbtrace: chunk 2 (DPTH)") && has(e, row.what)) << e;
  }
  DepthSnapshot litmap = sample_depth(DepthWhich::Final, 4, 8);
  litmap.name = "litmap_min";
  Builder ok;
  ok.add(Properties{{"viewport", "8x4"}}).add(sample_frame_begin(0)).add(sample_depth(DepthWhich::Final, 8, 4)).add(litmap);
  ok.add(sample_stencil("volumes", 3, 1)).add(FrameEnd{0, 0, 0.0}).end(1);
  EXPECT_EQ(read(ok.b), "") << "a replayed depth of the viewport's size and other images of any size read";
}

// A draw of `vertices` identical clip-space vertices: 16 bytes each raw, compressing to almost
// nothing (a hostile file's cheap way to declare a big frame).
DrawRecord flat_draw(std::uint32_t index, std::size_t vertices) {
  DrawRecord d;
  d.index = index;
  d.clip_positions.assign(vertices, {0.0f, 0.0f, 0.5f, 1.0f});
  return d;
}

// A frame whose chunks are each within the chunk limit but together above the per-frame limit
// (64 MiB + 128 bytes a viewport pixel) is refused at the chunk that crosses it, before that chunk
// is decompressed, naming the frame and the limit.
TEST(TraceCorruptionTest, FrameAboveByteLimitRefused) {
  const Properties p{{"viewport", "8x8"}};
  const std::uint64_t limit = (std::uint64_t{64} << 20) + 128 * 64;
  const std::size_t vertices = 1500000;  // 24 MB raw a draw: the third crosses the limit
  Builder t;
  t.add(p).add(sample_frame_begin(0));
  for (std::uint32_t i = 0; i < 3; ++i) t.chunk(ChunkType::Draw, encode(flat_draw(i, vertices)), true);
  t.add(FrameEnd{0, 3, 0.0}).end(1);
  ASSERT_LT(t.b.size(), 1u << 20) << "the hostile file itself is small";
  const std::string e = read_error(t.b);
  EXPECT_TRUE(has(e, "chunk 4 (DRAW)")) << "the third DRAW crosses the limit: " << e;
  EXPECT_TRUE(has(e, "per-frame limit of " + std::to_string(limit) + " bytes")) << e;
  EXPECT_TRUE(has(e, "64 MiB + 128 bytes a pixel of the 8x8 viewport")) << "the rule in words: " << e;
  // The same draws in a frame of a 1024x1024 viewport (192 MiB) read.
  Builder big;
  big.add(Properties{{"viewport", "1024x1024"}}).add(sample_frame_begin(0));
  for (std::uint32_t i = 0; i < 3; ++i) big.chunk(ChunkType::Draw, encode(flat_draw(i, vertices)), true);
  big.add(FrameEnd{0, 3, 0.0}).end(1);
  EXPECT_EQ(read_error(big.b), "") << "72 MB of draws fit a 1024x1024 frame";
}

// The per-frame byte count starts again at every frame: frames of 48 MB each read, however many.
TEST(TraceCorruptionTest, FrameByteLimitIsPerFrame) {
  Builder t;
  t.add(Properties{{"viewport", "8x8"}});
  for (std::uint32_t f = 0; f < 3; ++f) {
    t.add(sample_frame_begin(f));
    for (std::uint32_t i = 0; i < 2; ++i) t.chunk(ChunkType::Draw, encode(flat_draw(i, 1500000)), true);
    t.add(FrameEnd{f, 2, 0.0});
  }
  t.end(3);
  EXPECT_EQ(read_error(t.b), "");
}

// A draw batch whose count takes the frame above the per-frame draw limit (2^20) is refused
// before its draws are decoded, naming the limit.
TEST(TraceCorruptionTest, FrameAboveDrawLimitRefused) {
  Bytes batch(8, 0);
  put_le32(batch, 0, (1u << 20) + 1);
  Builder t;
  t.add(Properties{{"viewport", "8x8"}}).add(sample_frame_begin(0)).chunk(ChunkType::DrawBatch, batch);
  t.add(FrameEnd{0, (1u << 20) + 1, 0.0}).end(1);
  const std::string e = read_error(t.b);
  EXPECT_TRUE(has(e, "chunk 2 (DRWS)")) << e;
  EXPECT_TRUE(has(e, "above the per-frame limit of 1048576 draws")) << e;
}

}  // namespace

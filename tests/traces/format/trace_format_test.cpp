// TraceFormatTest: the trace format of traces/FORMAT.md round-trips every record bit for bit,
// streams long traces, keeps reading version-1 files and refuses newer versions; the writer's rules.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <functional>

#include "model/common/error.h"
#include "tests/traces/format/sample_trace.h"

namespace {

using namespace nbsim::trace;
using namespace nbsim::trace::testing;
using nbsim::InputError;

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

std::uint32_t le32_at(const Bytes& b, std::size_t at) {
  return static_cast<std::uint32_t>(b[at]) | static_cast<std::uint32_t>(b[at + 1]) << 8 |
         static_cast<std::uint32_t>(b[at + 2]) << 16 | static_cast<std::uint32_t>(b[at + 3]) << 24;
}

// zlib's CRC-32 is the ISO-HDLC one FORMAT.md names, with its standard check value.
TEST(TraceFormatTest, Crc32IsTheStandardOne) {
  const std::string s = "123456789";
  EXPECT_EQ(crc32(std::span(reinterpret_cast<const std::uint8_t*>(s.data()), s.size())), 0xCBF43926u);
}

// The preamble is magic, version and a CRC-32 of both, as FORMAT.md's table says.
TEST(TraceFormatTest, PreambleLayout) {
  const auto p = encode_preamble(1);
  const Bytes magic = {0x89, 'N', 'B', 'T', 'R', 0x0D, 0x0A, 0x1A};
  EXPECT_TRUE(std::equal(magic.begin(), magic.end(), p.begin()));
  const Bytes b(p.begin(), p.end());
  EXPECT_EQ(le32_at(b, 8), 1u);
  EXPECT_EQ(le32_at(b, 12), crc32(std::span(p).first(12)));
}

// Payload sizes and a few field offsets agree with FORMAT.md's record tables.
TEST(TraceFormatTest, PayloadLayoutMatchesFormatDoc) {
  EXPECT_EQ(encode(sample_frame_begin(3)).size(), 145u) << "FRAM";
  EXPECT_EQ(encode(FrameEnd{}).size(), 16u) << "FEND";
  EXPECT_EQ(encode(EndMarker{}).size(), 12u) << "END";
  for (std::size_t v : {0u, 1u, 9u}) EXPECT_EQ(encode(sample_draw(1, v)).size(), 120u + 16u * v) << "DRAW with " << v;
  DrawRecord points = sample_draw_v2(1, 5);
  ASSERT_EQ(points.topology, Topology::Points);
  EXPECT_EQ(encode(points).size(), 120u + 16u * 5 + 4u * 5) << "DRAW of 5 points with their sizes";
  EXPECT_EQ(encode(sample_depth(DepthWhich::Final, 5, 3)).size(), 4u + 5u + 8u + 4u * 15u) << "DPTH named 'final'";
  EXPECT_EQ(encode(sample_levels(nbsim::FarOp::Max, 5, 3, 4)).size(), 4u + 15u + 13u + 4u * 60u) << "NBLV from 'after_occluders'";
  EXPECT_EQ(encode(sample_stencil("m", 5, 3)).size(), 4u + 1u + 8u + 15u) << "STNC";
  EXPECT_EQ(encode(sample_light(0)).size(), 140u) << "LGHT";
  EXPECT_EQ(encode(DrawBatch{{sample_draw(0, 3), sample_draw(1, 0)}}).size(), 4u + 120u + 48u + 120u) << "DRWS";
  EXPECT_EQ(encode(sample_truth(6, 5, 3)).size(), 20u + 4u * 6u + 4u * 15u) << "TRTH with IDs";
  EXPECT_EQ(encode(sample_truth(6, 0, 0)).size(), 20u + 4u * 6u) << "TRTH without IDs";

  DrawRecord d = sample_draw(4, 2);
  d.object = 0x01020304;
  d.gl.fragments = 0x1122334455667788ull;
  const Bytes b = encode(d);
  EXPECT_EQ(b[4], 4) << "role at offset 4";
  EXPECT_EQ(le32_at(b, 5), 0x01020304u) << "object at offset 5, little-endian";
  EXPECT_EQ(le32_at(b, 21), 2u) << "vertex count at offset 21";
  const std::size_t a = 25 + 16 * 2;
  EXPECT_EQ(le32_at(b, a + 23), 0x55667788u) << "gl.fragments at a+23";
  EXPECT_EQ(le32_at(b, a + 27), 0x11223344u);

  const Bytes c = encode_chunk(ChunkType::FrameEnd, encode(FrameEnd{7, 2, 0.5}));
  EXPECT_EQ(c.size(), 24u + 16u + 4u);
  EXPECT_EQ(std::string(c.begin(), c.begin() + 4), "FEND") << "fourcc in file order";
  EXPECT_EQ(le32_at(c, 40), crc32(std::span(c).first(40))) << "CRC over header and payload";
}

// Every chunk type round-trips bit for bit: header properties, scene, three frames, END.
TEST(TraceFormatTest, RoundTripsEveryChunkType) {
  const fs::path f = scratch("round_trip.nbtrace");
  write_sample_trace(f);
  FrameReader frames(f);
  const TraceReader& t = frames.trace();
  EXPECT_EQ(t.version(), kFormatVersion);
  EXPECT_EQ(t.properties(), sample_properties()) << "keys, values and their order";
  ASSERT_NE(t.property("seed"), nullptr);
  EXPECT_EQ(*t.property("seed"), "7");
  EXPECT_EQ(t.property("no_such_key"), nullptr);
  ASSERT_NE(t.scene(), nullptr);
  expect_same(sample_scene(), *t.scene());
  const auto want = sample_frames();
  std::size_t n = 0;
  while (const auto fr = frames.next()) {
    ASSERT_LT(n, want.size());
    EXPECT_EQ(fr->ordinal, n);
    expect_same(want[n], *fr);
    ++n;
  }
  EXPECT_EQ(n, want.size());
  ASSERT_TRUE(t.end().has_value());
  EXPECT_EQ(t.end()->frames, 3u);
  EXPECT_EQ(t.end()->chunks, t.stats().chunks - 1) << "END counts the chunks before it";
  EXPECT_EQ(t.file_bytes(), fs::file_size(f));
  EXPECT_GT(t.stats().compressed_chunks, 0u) << "the 32x24 depth snapshots are worth compressing";
}

// Empty vectors everywhere (no properties, an empty scene, a draw without geometry, ground truth
// for zero objects) round-trip.
TEST(TraceFormatTest, RoundTripsEmptyVectors) {
  const fs::path f = scratch("empty_vectors.nbtrace");
  {
    TraceWriter w(f, {});
    w.write(SceneObjects{});
    w.begin_frame(FrameBegin{});
    DrawRecord d;
    w.write(d);
    w.write(GroundTruth{});
    w.end_frame({0, 1, 0.0});
    w.close();
  }
  FrameReader frames(f);
  EXPECT_TRUE(frames.trace().properties().empty());
  ASSERT_NE(frames.trace().scene(), nullptr);
  expect_same(SceneObjects{}, *frames.trace().scene());
  const auto fr = frames.next();
  ASSERT_TRUE(fr);
  ASSERT_EQ(fr->draws.size(), 1u);
  expect_same(DrawRecord{}, fr->draws[0]);
  ASSERT_TRUE(fr->truth);
  expect_same(GroundTruth{}, *fr->truth);
  EXPECT_TRUE(fr->depths.empty());
  EXPECT_TRUE(fr->levels.empty());
  EXPECT_FALSE(frames.next());
}

// Large vectors (a 20,000-object scene, 30,000 clip-space vertices, a 512x512 depth, 8 levels of
// 256x256) round-trip, compressed where that helps.
TEST(TraceFormatTest, RoundTripsLargeVectors) {
  const fs::path f = scratch("large.nbtrace");
  const SceneObjects scene = sample_scene(20000);
  const DrawRecord draw = sample_draw(0, 30000);
  const DepthSnapshot depth = sample_depth(DepthWhich::Final, 512, 512, 3);
  const NBufferLevels levels = sample_levels(nbsim::FarOp::Min, 256, 256, 8);
  GroundTruth truth = sample_truth(20000, 512, 512);
  {
    TraceWriter w(f, sample_properties());
    w.write(scene);
    w.begin_frame(sample_frame_begin(9));
    w.write(draw);
    w.write(depth);
    w.write(levels);
    w.write(truth);
    w.end_frame({9, 1, 2.0});
    w.close();
  }
  FrameReader frames(f);
  expect_same(scene, *frames.trace().scene());
  const auto fr = frames.next();
  ASSERT_TRUE(fr);
  expect_same(draw, fr->draws.at(0));
  expect_same(depth, fr->depths.at(0));
  expect_same(levels, fr->levels.at(0));
  expect_same(truth, *fr->truth);
  EXPECT_LT(fs::file_size(f), frames.trace().stats().raw_bytes / 2) << "depth, levels and IDs compress well";
}

// The writer compresses payloads of at least 1 KiB only when zstd makes them smaller.
TEST(TraceFormatTest, CompressesOnlyWhenItHelps) {
  const fs::path f = scratch("compress.nbtrace");
  DepthSnapshot noise = sample_depth(DepthWhich::AfterOccluders, 64, 64);
  Lcg rng{99};
  for (float& v : noise.texels) v = std::bit_cast<float>(rng.next());
  {
    TraceWriter w(f, {});
    w.begin_frame(sample_frame_begin(0));
    w.write(sample_draw(0, 3));                                // 128 bytes: too small to try
    w.write(noise);                                            // random bits: zstd cannot shrink them
    w.write(sample_depth(DepthWhich::Final, 64, 64));          // flat regions: compressed
    w.end_frame({0, 1, 0.0});
    w.close();
  }
  TraceReader t(f);
  std::vector<Chunk> chunks;
  while (auto c = t.next()) chunks.push_back(std::move(*c));
  ASSERT_EQ(chunks.size(), 5u);
  EXPECT_FALSE(chunks[1].compressed) << "a small DRAW is stored as is";
  EXPECT_FALSE(chunks[2].compressed) << "incompressible noise is stored as is";
  EXPECT_EQ(chunks[2].stored_bytes, chunks[2].payload.size());
  EXPECT_TRUE(chunks[3].compressed) << "a flat depth image is compressed";
  EXPECT_LT(chunks[3].stored_bytes * 2, chunks[3].payload.size());
  expect_same(noise, t.decode<DepthSnapshot>(chunks[2]));
}

// The chunk walk yields every chunk after HEAD and SCEN with its index, type and byte offset.
TEST(TraceFormatTest, ChunkWalkNamesEveryChunk) {
  const fs::path f = scratch("walk.nbtrace");
  write_sample_trace(f);
  const std::vector<std::size_t> offsets = chunk_offsets(read_file(f));
  TraceReader t(f);
  std::vector<ChunkType> types;
  std::uint64_t index = 2;  // HEAD and SCEN were read by the constructor
  while (auto c = t.next()) {
    EXPECT_EQ(c->index, index);
    ASSERT_LT(c->index, offsets.size());
    EXPECT_EQ(c->offset, offsets[c->index]) << "chunk " << c->index;
    types.push_back(c->type);
    ++index;
  }
  EXPECT_EQ(offsets.size(), index + 1) << "END is the last chunk";
  ASSERT_GE(types.size(), 4u);
  EXPECT_EQ(types.front(), ChunkType::FrameBegin);
  EXPECT_EQ(types.back(), ChunkType::FrameEnd);
  EXPECT_EQ(offsets[0], kPreambleBytes) << "HEAD follows the preamble";
}

// A trace may hold only its header: no scene, no frames.
TEST(TraceFormatTest, HeaderOnlyTrace) {
  const fs::path f = scratch("header_only.nbtrace");
  {
    TraceWriter w(f, {{"scene", "none"}});
    w.close();
    EXPECT_EQ(w.chunks_written(), 2u);
    EXPECT_EQ(w.bytes_written(), fs::file_size(f));
  }
  FrameReader frames(f);
  EXPECT_EQ(frames.trace().scene(), nullptr);
  EXPECT_FALSE(frames.next());
  ASSERT_TRUE(frames.trace().end());
  EXPECT_EQ(frames.trace().end()->chunks, 1u);
  EXPECT_EQ(frames.trace().end()->frames, 0u);
}

// A long trace streams frame by frame: 3000 frames read back in order, each checked.
TEST(TraceFormatTest, StreamsManyFrames) {
  const fs::path f = scratch("many.nbtrace");
  constexpr std::uint32_t kFrames = 3000;
  {
    TraceWriter w(f, sample_properties());
    for (std::uint32_t i = 0; i < kFrames; ++i) {
      w.begin_frame(sample_frame_begin(2 * i));
      w.write(sample_draw(0, 6, i));
      w.write(sample_draw(1, 0, i));
      w.write(sample_depth(DepthWhich::Final, 16, 16, i));
      w.end_frame({2 * i, 2, static_cast<double>(i)});
    }
    w.close();
    EXPECT_EQ(w.frames_written(), kFrames);
  }
  FrameReader frames(f);
  std::uint32_t n = 0;
  while (const auto fr = frames.next()) {
    ASSERT_EQ(fr->begin.frame, 2 * n);
    ASSERT_EQ(fr->draws.size(), 2u);
    expect_same(sample_draw(0, 6, n), fr->draws[0]);
    ASSERT_EQ(fr->end.gl_ms, static_cast<double>(n));
    ++n;
  }
  EXPECT_EQ(n, kFrames);
  EXPECT_EQ(frames.trace().end()->frames, kFrames);
  EXPECT_EQ(frames.trace().stats().draws, 2u * kFrames);
}

// A version above ours is refused with a message saying it is newer (the preamble CRC patched
// too, so it is not mistaken for damage).
TEST(TraceFormatTest, RefusesNewerVersion) {
  const fs::path f = scratch("newer.nbtrace");
  write_sample_trace(f);
  Bytes b = read_file(f);
  const auto pre = encode_preamble(kFormatVersion + 1);
  std::copy(pre.begin(), pre.end(), b.begin());
  const std::string e = error_of([&] { TraceReader(b, "newer.nbtrace"); });
  EXPECT_TRUE(has(e, "newer")) << e;
  EXPECT_TRUE(has(e, "version " + std::to_string(kFormatVersion + 1))) << e;
  EXPECT_TRUE(has(e, "newer.nbtrace")) << e;
}

// Version 0 never existed: refused as damage.
TEST(TraceFormatTest, RefusesVersionZero) {
  Bytes b = read_file([] {
    const fs::path f = scratch("v0.nbtrace");
    write_sample_trace(f);
    return f;
  }());
  const auto pre = encode_preamble(0);
  std::copy(pre.begin(), pre.end(), b.begin());
  const std::string e = error_of([&] { TraceReader(b, "v0"); });
  EXPECT_TRUE(has(e, "version 0")) << e;
}

// A trace written by version 1 (committed in tests/traces/format/data) reads back exactly. When the format
// moves to version 2, this fixture must keep reading: that is the older-version guarantee.
// Regenerate it only while kFormatVersion is 1: NBSIM_WRITE_TRACE_FIXTURE=<path> ./trace_tests.
TEST(TraceFormatTest, ReadsVersion1Fixture) {
  if (const char* out = std::getenv("NBSIM_WRITE_TRACE_FIXTURE"); out && kFormatVersion == 1) write_sample_trace(out);
  const fs::path fixture = fs::path(NBSIM_TRACE_DATA_DIR) / "sample_v1.nbtrace";
  ASSERT_TRUE(fs::exists(fixture)) << fixture;
  FrameReader frames(fixture);
  EXPECT_EQ(frames.trace().version(), 1u);
  EXPECT_EQ(frames.trace().properties(), sample_properties());
  expect_same(sample_scene(), *frames.trace().scene());
  const auto want = sample_frames();
  std::size_t n = 0;
  while (const auto fr = frames.next()) expect_same(want.at(n++), *fr);
  EXPECT_EQ(n, want.size());
}

// Version 1's two depth images read as the names "after_occluders" and "final" (Frame::depth by
// DepthWhich still finds them), its N-buffers as built from "after_occluders", and its draws with
// version 2's defaults (triangles, no stencil test, no discard, no gl_FragDepth).
TEST(TraceFormatTest, Version1RecordsGetVersion2Defaults) {
  FrameReader frames(fs::path(NBSIM_TRACE_DATA_DIR) / "sample_v1.nbtrace");
  frames.next();
  const auto f = frames.next();  // frame 2: both depth images, max and min levels
  ASSERT_TRUE(f);
  ASSERT_NE(f->depth(DepthWhich::AfterOccluders), nullptr);
  ASSERT_NE(f->depth(DepthWhich::Final), nullptr);
  EXPECT_EQ(f->depth(DepthWhich::AfterOccluders), f->depth("after_occluders"));
  ASSERT_EQ(f->levels.size(), 2u);
  for (const NBufferLevels& l : f->levels) EXPECT_EQ(l.source, "after_occluders");
  EXPECT_NE(f->nbuffer("after_occluders", nbsim::FarOp::Min), nullptr);
  for (const DrawRecord& d : f->draws) {
    EXPECT_EQ(d.topology, Topology::Triangles);
    EXPECT_TRUE(d.point_sizes.empty());
    EXPECT_FALSE(d.stencil.test);
    EXPECT_EQ(d.stencil.front.func, DepthFunc::Always);
    EXPECT_EQ(d.stencil.back.write_mask, 0xFFFFFFFFu);
    EXPECT_FALSE(d.discards);
    EXPECT_FALSE(d.writes_depth);
  }
  EXPECT_TRUE(f->stencils.empty());
  EXPECT_FALSE(f->light);
  EXPECT_TRUE(f->technique_records.empty());
}

// Every record and field of version 2 round-trips bit for bit: point and stencil draws in DRWS
// batches (more draws than one batch holds), named depth images, N-buffers per source and op,
// stencil images, the light camera, registered and raw technique records.
TEST(TraceFormatTest, RoundTripsEveryVersion2Record) {
  const fs::path f = scratch("v2.nbtrace");
  write_sample_trace_v2(f);
  FrameReader frames(f);
  EXPECT_EQ(frames.trace().version(), 2u);
  const auto want = sample_frames_v2();
  std::size_t n = 0;
  while (const auto fr = frames.next()) {
    ASSERT_LT(n, want.size());
    expect_same(want[n], *fr);
    ++n;
  }
  EXPECT_EQ(n, want.size());
  // The draws went in batches: frame 0's 1029 need several, the others one each.
  TraceReader t(f);
  std::vector<std::size_t> batch_sizes;
  while (const auto c = t.next())
    if (c->type == ChunkType::DrawBatch) batch_sizes.push_back(t.decode<DrawBatch>(*c).draws.size());
  std::vector<std::size_t> expected;
  for (std::size_t left = 1029; left > 0; left -= std::min(left, kDrawsPerBatch)) expected.push_back(std::min(left, kDrawsPerBatch));
  expected.insert(expected.end(), {3, 4});
  ASSERT_GT(expected.size(), 3u) << "frame 0 needs more than one batch";
  EXPECT_EQ(batch_sizes, expected) << "frame 0: full batches and the rest; frames 2 and 5: one batch each";
}

// A trace written by version 2 (committed in tests/traces/format/data) reads back exactly, so that later
// versions keep reading it. Regenerate only while kFormatVersion is 2:
// NBSIM_WRITE_TRACE_FIXTURE_V2=<path> ./trace_tests --gtest_filter='*Version2Fixture'.
TEST(TraceFormatTest, ReadsVersion2Fixture) {
  if (const char* out = std::getenv("NBSIM_WRITE_TRACE_FIXTURE_V2"); out && kFormatVersion == 2) write_sample_trace_v2(out);
  const fs::path fixture = fs::path(NBSIM_TRACE_DATA_DIR) / "sample_v2.nbtrace";
  ASSERT_TRUE(fs::exists(fixture)) << fixture;
  FrameReader frames(fixture);
  EXPECT_EQ(frames.trace().version(), 2u);
  const auto want = sample_frames_v2();
  std::size_t n = 0;
  while (const auto fr = frames.next()) expect_same(want.at(n++), *fr);
  EXPECT_EQ(n, want.size());
}

// A writer destroyed without close() leaves a trace without END, which readers refuse.
TEST(TraceFormatTest, UnclosedWriterLeavesTruncatedTrace) {
  const fs::path f = scratch("unclosed.nbtrace");
  {
    TraceWriter w(f, sample_properties());
    w.begin_frame(sample_frame_begin(0));
    w.end_frame({0, 0, 0.0});
  }
  const std::string e = error_of([&] { read_all(TraceReader(f)); });
  EXPECT_TRUE(has(e, "without an END chunk")) << e;
  EXPECT_TRUE(has(e, "chunk 3 at byte")) << "names the missing chunk's index and offset: " << e;
}

// Property keys and values outside the format's rules are refused before anything is written.
TEST(TraceFormatTest, WriterRefusesBadProperties) {
  struct Row {
    Properties props;
    std::string message;
  };
  const Row rows[] = {
      {{{"", "x"}}, "key ''"},                                    // keys are not empty
      {{{"GL RENDERER", "x"}}, "key 'GL RENDERER'"},             // no spaces in keys
      {{{std::string(65, 'k'), "x"}}, "1 to 64 characters"},     // keys at most 64 bytes
      {{{"seed", "1"}, {"seed", "2"}}, "appears twice"},          // keys are unique
      {{{"command_line", std::string(65537, 'v')}}, "65537 bytes"},  // values at most 64 KiB
  };
  for (const Row& row : rows) {
    const fs::path f = scratch("bad_props.nbtrace");
    const std::string e = error_of([&] { TraceWriter w(f, row.props); });
    EXPECT_TRUE(has(e, row.message)) << "expected '" << row.message << "' in: " << e;
  }
}

// Scene records that would make a replay misbehave (BVH cycles, dangling ids) are refused.
TEST(TraceFormatTest, SceneRules) {
  struct Row {
    std::function<void(SceneObjects&)> damage;
    std::string message;
  };
  const Row rows[] = {
      {[](SceneObjects& s) { s.triangles.pop_back(); }, "triangle counts"},            // one count per object
      {[](SceneObjects& s) { s.node_first.pop_back(); }, "different sizes"},           // parallel BVH vectors
      {[](SceneObjects& s) { s.node_left[0] = 3; }, "outside -1 .. 2"},                // child ids exist
      {[](SceneObjects& s) { s.node_right[0] = -1; }, "one child"},                    // two children or none
      {[](SceneObjects& s) { s.node_right[0] = 1; }, "more than one parent"},          // a tree, not a DAG
      {[](SceneObjects& s) { s.node_left = {-1, 2, -1}; s.node_right = {-1, 1, -1}; }, "cycle"},  // no cycles
      {[](SceneObjects& s) { s.node_count[2] = 99; }, "beyond the 6 leaf entries"},    // leaf ranges inside
      {[](SceneObjects& s) { s.leaf_objects[1] = 6; }, "names object 6"},              // leaf ids exist
  };
  EXPECT_EQ(record_problem(sample_scene()), "") << "the sample scene is valid";
  for (const Row& row : rows) {
    SceneObjects s = sample_scene();
    row.damage(s);
    const std::string p = record_problem(s);
    EXPECT_TRUE(has(p, row.message)) << "expected '" << row.message << "' in: " << p;
    // The decoder refuses the same record.
    const Bytes payload = encode(s);
    const std::string e = error_of([&] { decode_scene(payload, 1); });
    EXPECT_TRUE(has(e, row.message)) << e;
  }
}

// Missing files, directories and uncreatable outputs are InputErrors naming the path.
TEST(TraceFormatTest, RefusesUnopenableFiles) {
  std::string e = error_of([] { TraceReader("/nonexistent/x.nbtrace"); });
  EXPECT_TRUE(has(e, "/nonexistent/x.nbtrace") && has(e, "does not exist")) << e;
  e = error_of([] { TraceReader(fs::temp_directory_path()); });
  EXPECT_TRUE(has(e, "not a regular file")) << e;
  e = error_of([] { TraceWriter("/nonexistent/dir/x.nbtrace", {}); });
  EXPECT_TRUE(has(e, "cannot create trace '/nonexistent/dir/x.nbtrace'")) << e;
}

// Breaking the writer's order is a bug of the caller: it aborts with a message.
TEST(TraceWriterDeathTest, AbortsOnMisuse) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  // The threadsafe style runs this body again in a child process that dies (no clean-up): the
  // child inherits the path through the environment and writes into this process's scratch folder.
  if (!std::getenv("NBSIM_MISUSE_TRACE")) ::setenv("NBSIM_MISUSE_TRACE", scratch("misuse.nbtrace").c_str(), 1);
  const fs::path f = std::getenv("NBSIM_MISUSE_TRACE");
  EXPECT_DEATH(
      {
        TraceWriter w(f, {});
        w.write(sample_draw(0, 0));
      },
      "outside begin_frame");
  EXPECT_DEATH(
      {
        TraceWriter w(f, {});
        w.begin_frame(sample_frame_begin(4));
        w.end_frame({4, 0, 0.0});
        w.begin_frame(sample_frame_begin(4));
      },
      "frame numbers must increase");
  EXPECT_DEATH(
      {
        TraceWriter w(f, {});
        w.begin_frame(sample_frame_begin(0));
        w.write(sample_draw(1, 0));
      },
      "draw index 1 in frame 0, expected 0");
  EXPECT_DEATH(
      {
        TraceWriter w(f, {});
        w.begin_frame(sample_frame_begin(0));
        DepthSnapshot d = sample_depth(DepthWhich::Final, 4, 4);
        d.texels.pop_back();
        w.write(d);
      },
      "holds 15 elements");
  EXPECT_DEATH(
      {
        TraceWriter w(f, {});
        w.begin_frame(sample_frame_begin(0));
        w.write(sample_depth(DepthWhich::Final, 4, 4));
        w.write(sample_depth(DepthWhich::Final, 8, 8));
      },
      "a second 'final' depth snapshot");
  EXPECT_DEATH(
      {
        TraceWriter w(f, {});
        w.begin_frame(sample_frame_begin(0));
        w.write(sample_stencil("mask", 4, 4));
        w.write(sample_stencil("mask", 4, 4));
      },
      "a second 'mask' stencil snapshot");
  EXPECT_DEATH(
      {
        TraceWriter w(f, {});
        w.begin_frame(sample_frame_begin(0));
        w.write_light(sample_light(0));
        w.write_light(sample_light(0));
      },
      "a second light camera");
  EXPECT_DEATH(
      {
        TraceWriter w(f, {});
        w.begin_frame(sample_frame_begin(0));
        w.write(sample_levels(nbsim::FarOp::Max, 4, 4, 2));
        w.write(sample_levels(nbsim::FarOp::Max, 4, 4, 2));
      },
      "a second N-buffer with op 0 built from 'after_occluders'");
  EXPECT_DEATH(
      {
        TraceWriter w(f, {});
        w.begin_frame(sample_frame_begin(0));
        DrawRecord d = sample_draw(0, 3);
        d.topology = Topology::Points;  // without point sizes
        w.write(d);
      },
      "a point draw with 3 vertices and 0 point sizes");
  EXPECT_DEATH(
      {
        TraceWriter w(f, {});
        w.begin_frame(sample_frame_begin(0));
        TechniqueRecord r;
        r.type = fourcc("NOPE");
        r.decoded = true;
        w.write(r);
      },
      "NOPE is not registered");
}

// A property value that is not UTF-8 is refused by the writer too (an InputError naming the key).
TEST(TraceFormatTest, WriterRefusesNonUtf8Property) {
  EXPECT_THROW(
      {
        try {
          TraceWriter w(scratch("latin1.nbtrace"), {{"scene", "caf\xe9"}});
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find("property 'scene' has a value that is not UTF-8"), std::string::npos) << e.what();
          throw;
        }
      },
      InputError);
}

// The writer refuses (InputError, not a crash) a frame that readers would refuse as above the
// per-frame byte limit, naming the frame and the limit.
TEST(TraceFormatTest, WriterRefusesFrameAboveByteLimit) {
  const fs::path f = scratch("frame_limit.nbtrace");
  TraceWriter w(f, {{"viewport", "8x8"}});
  w.begin_frame(sample_frame_begin(0));
  DrawRecord d;
  d.clip_positions.assign(1500000, {0.0f, 0.0f, 0.5f, 1.0f});  // 24 MB a draw, flushed one by one (4 MiB batches)
  std::string error;
  try {
    for (std::uint32_t i = 0; i < 3; ++i) {
      d.index = i;
      w.write(d);
    }
    w.end_frame({0, 3, 0.0});
  } catch (const InputError& e) {
    error = e.what();
  }
  EXPECT_TRUE(error.find("frame 0's records come to") != std::string::npos &&
              error.find("per-frame limit of 67117056 bytes") != std::string::npos)
      << "the third draw crosses 64 MiB + 128 bytes x 64 pixels: " << error;
}

// The per-frame limit holds the largest real frames with room to spare: a 2048x2048
// occlusion-culling frame (two depth images, 11 N-buffer planes of max and of min, an ID buffer, a
// stencil image, 20,000 draws of 1 KiB) and a 512x512 one.
TEST(TraceFormatTest, FrameLimitHoldsReal2048Frames) {
  for (const int side : {512, 2048}) {
    Header h;
    h.viewport = Viewport{side, side};
    const std::uint64_t px = static_cast<std::uint64_t>(side) * static_cast<std::uint64_t>(side);
    const std::uint64_t levels = side == 2048 ? 11 : 9;
    const std::uint64_t frame = 2 * 4 * px + 2 * 4 * levels * px + 4 * px + px + 20000 * 1024;
    EXPECT_GE(h.frame_byte_limit(), frame) << side << "x" << side << ": " << h.frame_byte_limit_rule();
  }
}

}  // namespace

// Deterministic sample records and traces for the trace tests (format, corruption, CLI), and
// bit-exact comparisons of records. Header-only: each test binary includes it once.
// tests/traces/format/data/sample_v1.nbtrace was written from these values (write_sample_trace): change
// them and TraceFormatTest.ReadsVersion1Fixture fails; add new samples instead.
#pragma once

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <string>
#include <vector>
#include <unistd.h>

#include "traces/format/codec.h"
#include "traces/format/reader.h"
#include "traces/format/technique_chunks.h"
#include "traces/format/writer.h"
#include "tests/common/scratch.h"

namespace nbsim::trace::testing {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;

inline fs::path scratch(const std::string& name) {
  return nbsim::testing::scratch_path("nbsim_trace", name);
}

inline Bytes read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), {});
}

inline void write_file(const fs::path& p, const Bytes& b) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

// Floats whose bits a careless codec would change: signed zero, subnormal, NaN with a payload,
// infinities, the largest float, the float just below 1.
inline const std::vector<float>& awkward_floats() {
  static const std::vector<float> v = {-0.0f,
                                       1e-40f,
                                       std::bit_cast<float>(0x7FC12345u),
                                       std::bit_cast<float>(0xFF812345u),
                                       std::numeric_limits<float>::infinity(),
                                       -std::numeric_limits<float>::infinity(),
                                       std::numeric_limits<float>::max(),
                                       std::nextafter(1.0f, 0.0f),
                                       0.1f,
                                       1.0f};
  return v;
}

// A small LCG: the same numbers on every machine.
struct Lcg {
  std::uint32_t s;
  std::uint32_t next() { return s = s * 1664525u + 1013904223u; }
  float unit() { return static_cast<float>(next() >> 8) / 16777216.0f; }  // [0, 1)
};

inline Properties sample_properties() {
  return {{"GL_RENDERER", "llvmpipe (LLVM 15.0.6, 256 bits)"},
          {"GL_VERSION", "4.5 (Core Profile) Mesa 22.3.6"},
          {"mesa_version", "22.3.6"},
          {"viewport", "32x24"},
          {"depth_format", "DEPTH_COMPONENT32F"},
          {"depth_func", "LESS"},
          {"technique", "occlusion_culling"},
          {"scene", "city"},
          {"seed", "7"},
          {"nbsim_version", "0.1.0"},
          {"command_line", "nbsim capture city --size 32x24 --frames 3 -o \"sample trace.nbtrace\""},
          {"empty.value", ""}};
}

// `objects` objects under a BVH: node 0 the root over two leaves (a pair of children), ids split.
inline SceneObjects sample_scene(std::uint32_t objects = 6) {
  SceneObjects s;
  for (std::uint32_t i = 0; i < objects; ++i) {
    const float f = static_cast<float>(i);
    s.objects.push_back({{f, -f * 0.5f, 0.25f + f}, {f + 1.5f, 2.0f, 3.0f + f}});
    s.triangles.push_back(12 + i);
  }
  s.objects.front().lo[0] = -0.0f;
  const std::uint32_t half = objects / 2;
  s.node_bounds = {{{-1, -2, -3}, {10, 20, 30}}, {{-1, -2, -3}, {5, 6, 7}}, {{4, 5, 6}, {10, 20, 30}}};
  s.node_left = {1, -1, -1};
  s.node_right = {2, -1, -1};
  s.node_first = {0, 0, half};
  s.node_count = {objects, half, objects - half};
  for (std::uint32_t i = 0; i < objects; ++i) s.leaf_objects.push_back(objects - 1 - i);
  return s;
}

inline FrameBegin sample_frame_begin(std::uint32_t frame, TestMode mode = TestMode::NBuffer) {
  FrameBegin f;
  f.frame = frame;
  f.mode = mode;
  for (std::size_t i = 0; i < 16; ++i) {
    f.view[i] = static_cast<float>(i) * 0.25f - static_cast<float>(frame);
    f.proj[i] = awkward_floats()[i % awkward_floats().size()];
  }
  f.eye = {1.5f + static_cast<float>(frame), -0.0f, 1e30f};
  return f;
}

inline DrawRecord sample_draw(std::uint32_t index, std::size_t vertices, std::uint32_t seed = 1) {
  Lcg rng{seed * 7919u + index};
  DrawRecord d;
  d.index = index;
  d.role = static_cast<DrawRole>(index % 7);
  d.object = static_cast<std::int32_t>(index % 5) - 1;
  d.node = index % 2 ? 2 : -1;
  d.level = static_cast<std::uint8_t>(index % 9);
  d.state.func = static_cast<DepthFunc>(index % 8);
  d.state.write = index % 2 == 0;
  d.state.test = index % 3 != 0;
  d.state.cull = static_cast<CullFace>(index % 4);
  d.state.front_ccw = index % 5 != 1;
  d.state.clip = static_cast<ClipControl>(index % 2);
  d.state.depth_clamp = index % 3 == 1;
  for (std::size_t v = 0; v < vertices; ++v)
    d.clip_positions.push_back({rng.unit() * 4 - 2, rng.unit() * 4 - 2, rng.unit(), 1.0f + rng.unit()});
  if (!d.clip_positions.empty()) d.clip_positions[0] = {-0.0f, 1e-40f, std::bit_cast<float>(0x7FC12345u), 1.0f};
  d.has_bounds = index % 2 == 1;
  d.bounds = {static_cast<std::int32_t>(index) - 3, 7, 16, static_cast<std::int32_t>(index % 4), 0.375f + 1e-7f,
              index % 4 == 3, index % 3 == 0};
  d.gl = {1000u + index * 17u, 900u + index, (1ull << 40) + index, 3ull * index};
  return d;
}

// A draw with every field of version 2 set away from its default: point sprites with sizes, both
// stencil faces, discard and gl_FragDepth.
inline DrawRecord sample_draw_v2(std::uint32_t index, std::size_t vertices, std::uint32_t seed = 1) {
  DrawRecord d = sample_draw(index, vertices, seed);
  d.topology = vertices % 3 == 0 && index % 2 == 0 ? Topology::Triangles : Topology::Points;
  if (d.topology == Topology::Points)
    for (std::size_t v = 0; v < vertices; ++v) d.point_sizes.push_back(v == 0 ? -0.0f : 1.0f + static_cast<float>(v % 32));
  d.stencil.test = index % 2 == 0;
  d.stencil.front = {DepthFunc::Gequal, -7, 0x0Fu, 0xF0u, StencilOp::IncrWrap, StencilOp::Invert, StencilOp::Replace};
  d.stencil.back = {DepthFunc::NotEqual, 255, 0xFFFFFF00u, 0x1u, StencilOp::DecrWrap, StencilOp::Zero, StencilOp::Decr};
  d.discards = index % 3 != 2;
  d.writes_depth = index % 2 == 1;
  return d;
}

inline StencilSnapshot sample_stencil(const std::string& name, std::int32_t w, std::int32_t h) {
  StencilSnapshot s;
  s.name = name;
  s.width = w;
  s.height = h;
  for (std::int32_t i = 0; i < w * h; ++i) s.texels.push_back(static_cast<std::uint8_t>((i / 7) % 3 == 0 ? 0 : i * 37));
  return s;
}

inline Camera sample_light(std::uint32_t frame) {
  Camera c;
  for (std::size_t i = 0; i < 16; ++i) {
    c.view[i] = awkward_floats()[(i + 3) % awkward_floats().size()];
    c.proj[i] = static_cast<float>(i) * -0.5f + static_cast<float>(frame);
  }
  c.eye = {-0.0f, 100.0f + static_cast<float>(frame), std::bit_cast<float>(0x7FC00001u)};
  return c;
}

// A technique chunk type for the tests, with a field of every kind (registered once per process).
inline constexpr std::uint32_t kTestChunk = fourcc("TSTX");
inline void register_test_chunk() {
  static const bool once = [] {
    register_technique_chunk({kTestChunk,
                              "test_technique",
                              "TestRecord",
                              {{"count", FieldKind::U32, "a u32"},
                               {"offset", FieldKind::I32, "an i32"},
                               {"total", FieldKind::U64, "a u64"},
                               {"scale", FieldKind::F32, "an f32"},
                               {"ms", FieldKind::F64, "an f64"},
                               {"label", FieldKind::String, "a string"},
                               {"depths", FieldKind::VecF32, "floats"},
                               {"ids", FieldKind::VecU32, "u32s"},
                               {"deltas", FieldKind::VecI32, "i32s"}}});
    return true;
  }();
  (void)once;
}

inline TechniqueRecord sample_technique_record(std::uint32_t seed) {
  register_test_chunk();
  TechniqueRecord r;
  r.type = kTestChunk;
  r.decoded = true;
  r.fields = {{"count", std::uint64_t{4000000000u + seed}},
              {"offset", std::int64_t{-5 - static_cast<std::int64_t>(seed)}},
              {"total", std::uint64_t{(1ull << 60) + seed}},
              {"scale", 0.375},
              {"ms", 1.0 / 3.0},
              {"label", std::string("litmap \"max\"")},
              {"depths", std::vector<float>{-0.0f, 1e-40f, 0.5f}},
              {"ids", std::vector<std::uint32_t>{seed, 0xFFFFFFFFu}},
              {"deltas", std::vector<std::int32_t>{}}};
  return r;
}

// A technique record of a type this build does not know: kept raw.
inline TechniqueRecord sample_raw_record() {
  TechniqueRecord r;
  r.type = fourcc("RAWX");
  r.payload = {1, 2, 3, 4, 5, 0, 255};
  return r;
}

// A depth image with flat regions and a gradient (compresses like a real depth buffer), plus
// the awkward floats in the first texels.
inline DepthSnapshot sample_depth(DepthWhich which, std::int32_t w, std::int32_t h, std::uint32_t seed = 1) {
  DepthSnapshot d;
  d.name = std::string(to_string(which));
  d.width = w;
  d.height = h;
  d.texels.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 1.0f);
  Lcg rng{seed};
  for (std::int32_t y = 0; y < h; ++y)
    for (std::int32_t x = 0; x < w; ++x)
      if ((x / 8 + y / 8 + static_cast<std::int32_t>(seed)) % 3 != 0)
        d.texels[static_cast<std::size_t>(y) * w + x] = 0.5f + 0.001f * static_cast<float>(x) + 0.0001f * static_cast<float>(y);
  d.texels[d.texels.size() / 2] = rng.unit();
  return d;
}

inline NBufferLevels sample_levels(FarOp op, std::int32_t w, std::int32_t h, std::int32_t levels) {
  NBufferLevels l;
  l.op = static_cast<std::uint8_t>(op);
  l.width = w;
  l.height = h;
  l.levels = levels;
  const auto plane = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  l.texels.resize(plane * static_cast<std::size_t>(levels));
  for (std::size_t i = 0; i < l.texels.size(); ++i)
    l.texels[i] = static_cast<float>(i / plane + 1) / static_cast<float>(levels + 1) + static_cast<float>(i % 7) * 1e-6f;
  return l;
}

// Ground truth consistent with an ID buffer of w x h (or none when w == 0).
inline GroundTruth sample_truth(std::uint32_t objects, std::int32_t w, std::int32_t h) {
  GroundTruth t;
  t.visible_pixels.assign(objects, 0);
  if (w == 0) {
    for (std::uint32_t i = 0; i < objects; i += 2) t.visible_pixels[i] = 100 + i;
    for (std::uint32_t n : t.visible_pixels) t.covered_pixels += n;
    return t;
  }
  t.id_width = w;
  t.id_height = h;
  t.ids.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  for (std::int32_t y = 0; y < h; ++y)
    for (std::int32_t x = 0; x < w; ++x) {
      const std::int32_t id = (x / 5 + 2 * (y / 4)) % (static_cast<std::int32_t>(objects) + 1) - 1;
      t.ids[static_cast<std::size_t>(y) * w + x] = id;
      if (id >= 0) {
        ++t.visible_pixels[static_cast<std::size_t>(id)];
        ++t.covered_pixels;
      }
    }
  return t;
}

// The frames of the small sample trace: what write_sample_trace writes, frame by frame.
struct SampleFrame {
  FrameBegin begin;
  std::vector<DrawRecord> draws;
  std::vector<DepthSnapshot> depths;
  std::vector<NBufferLevels> levels;
  std::vector<StencilSnapshot> stencils;
  std::optional<Camera> light;
  std::vector<TechniqueRecord> technique_records;
  std::optional<GroundTruth> truth;
  FrameEnd end;
};

// Frames 0, 2, 5 (gaps are allowed): frame 2 has both depth snapshots, max and min levels and an
// ID buffer; frame 5 only draws and a final depth. Depth bulky enough (32x24) to be compressed.
inline std::vector<SampleFrame> sample_frames(std::uint32_t objects = 6) {
  std::vector<SampleFrame> fs;
  const std::uint32_t numbers[] = {0, 2, 5};
  for (std::uint32_t k = 0; k < 3; ++k) {
    SampleFrame f;
    f.begin = sample_frame_begin(numbers[k], static_cast<TestMode>(k + 1));
    for (std::uint32_t i = 0; i < k + 2; ++i) f.draws.push_back(sample_draw(i, i == 1 ? 0 : 3 * (i + k + 1), k));
    if (k == 1) {
      f.depths.push_back(sample_depth(DepthWhich::AfterOccluders, 32, 24, 2));
      f.levels.push_back(sample_levels(FarOp::Max, 32, 24, 5));
      f.levels.push_back(sample_levels(FarOp::Min, 32, 24, 5));
      f.truth = sample_truth(objects, 32, 24);
    } else {
      f.truth = sample_truth(objects, 0, 0);
    }
    f.depths.push_back(sample_depth(DepthWhich::Final, 32, 24, k + 5));
    if (k == 2) f.truth.reset();
    f.end = {numbers[k], static_cast<std::uint32_t>(f.draws.size()), 1.25 * (k + 1) + 1e-12};
    fs.push_back(std::move(f));
  }
  return fs;
}

// The sample frames with every record and field of version 2: frame 2 adds point and stencil
// draws, two more depth images ("litmap_min", "litmap_max"), their min and max N-buffers, two
// stencil images, a light camera and technique records (one registered, one raw); frame 5 a raw
// technique record only. Frame 0 has 1029 draws (more than one DRWS batch of the writer's holds).
inline std::vector<SampleFrame> sample_frames_v2(std::uint32_t objects = 6) {
  std::vector<SampleFrame> fs = sample_frames(objects);
  for (std::size_t k = 0; k < fs.size(); ++k)
    for (std::size_t i = 0; i < fs[k].draws.size(); ++i)
      fs[k].draws[i] = sample_draw_v2(static_cast<std::uint32_t>(i), fs[k].draws[i].clip_positions.size(), static_cast<std::uint32_t>(k));
  for (std::uint32_t i = static_cast<std::uint32_t>(fs[0].draws.size()); i < 1029; ++i)
    fs[0].draws.push_back(sample_draw_v2(i, i % 4, 9));
  fs[0].end.draws = static_cast<std::uint32_t>(fs[0].draws.size());
  SampleFrame& f = fs[1];
  for (const char* name : {"litmap_min", "litmap_max"}) {
    DepthSnapshot d = sample_depth(DepthWhich::Final, 16, 8, 11);
    d.name = name;
    f.depths.push_back(d);
  }
  NBufferLevels min = sample_levels(nbsim::FarOp::Min, 16, 8, 4), max = sample_levels(nbsim::FarOp::Max, 16, 8, 4);
  min.source = "litmap_min";
  max.source = "litmap_max";
  f.levels.push_back(min);
  f.levels.push_back(max);
  f.stencils = {sample_stencil("shadow_mask", 32, 24), sample_stencil("volumes", 3, 1)};
  f.light = sample_light(2);
  f.technique_records = {sample_technique_record(1), sample_raw_record(), sample_technique_record(2)};
  fs[2].technique_records = {sample_raw_record()};
  return fs;
}

inline void write_frame(TraceWriter& w, const SampleFrame& f) {
  w.begin_frame(f.begin);
  for (const DrawRecord& d : f.draws) w.write(d);
  for (const DepthSnapshot& d : f.depths) w.write(d);
  for (const NBufferLevels& l : f.levels) w.write(l);
  for (const StencilSnapshot& st : f.stencils) w.write(st);
  if (f.light) w.write_light(*f.light);
  for (const TechniqueRecord& t : f.technique_records) w.write(t);
  if (f.truth) w.write(*f.truth);
  w.end_frame(f.end);
}

// The sample trace: HEAD, SCEN, the three sample frames, END.
inline void write_sample_trace(const fs::path& file) {
  TraceWriter w(file, sample_properties());
  w.write(sample_scene());
  for (const SampleFrame& f : sample_frames()) write_frame(w, f);
  w.close();
}

// The same with every record and field of version 2 (sample_frames_v2).
inline void write_sample_trace_v2(const fs::path& file) {
  TraceWriter w(file, sample_properties());
  w.write(sample_scene());
  for (const SampleFrame& f : sample_frames_v2()) write_frame(w, f);
  w.close();
}

// ---- bit-exact comparison ----------------------------------------------------------------------

inline std::uint32_t bits(float f) { return std::bit_cast<std::uint32_t>(f); }

template <std::size_t N>
::testing::AssertionResult same_floats(const std::array<float, N>& a, const std::array<float, N>& b) {
  for (std::size_t i = 0; i < N; ++i)
    if (bits(a[i]) != bits(b[i]))
      return ::testing::AssertionFailure() << "element " << i << ": bits " << std::hex << bits(a[i]) << " vs " << bits(b[i]);
  return ::testing::AssertionSuccess();
}

template <class T>
::testing::AssertionResult same_words(const std::vector<T>& a, const std::vector<T>& b) {
  static_assert(sizeof(T) == 4);
  if (a.size() != b.size()) return ::testing::AssertionFailure() << "sizes " << a.size() << " vs " << b.size();
  if (!a.empty() && std::memcmp(a.data(), b.data(), 4 * a.size()) != 0)
    return ::testing::AssertionFailure() << "contents differ (bit-exact comparison)";
  return ::testing::AssertionSuccess();
}

inline void expect_same(const SceneObjects& a, const SceneObjects& b) {
  ASSERT_EQ(a.objects.size(), b.objects.size());
  for (std::size_t i = 0; i < a.objects.size(); ++i) {
    EXPECT_TRUE(same_floats(a.objects[i].lo, b.objects[i].lo)) << "object " << i;
    EXPECT_TRUE(same_floats(a.objects[i].hi, b.objects[i].hi)) << "object " << i;
  }
  ASSERT_EQ(a.node_bounds.size(), b.node_bounds.size());
  for (std::size_t i = 0; i < a.node_bounds.size(); ++i) {
    EXPECT_TRUE(same_floats(a.node_bounds[i].lo, b.node_bounds[i].lo)) << "node " << i;
    EXPECT_TRUE(same_floats(a.node_bounds[i].hi, b.node_bounds[i].hi)) << "node " << i;
  }
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.node_left, b.node_left);
  EXPECT_EQ(a.node_right, b.node_right);
  EXPECT_EQ(a.node_first, b.node_first);
  EXPECT_EQ(a.node_count, b.node_count);
  EXPECT_EQ(a.leaf_objects, b.leaf_objects);
}

inline void expect_same(const FrameBegin& a, const FrameBegin& b) {
  EXPECT_EQ(a.frame, b.frame);
  EXPECT_EQ(a.mode, b.mode);
  EXPECT_TRUE(same_floats(a.view, b.view)) << "view";
  EXPECT_TRUE(same_floats(a.proj, b.proj)) << "proj";
  EXPECT_TRUE(same_floats(a.eye, b.eye)) << "eye";
}

inline void expect_same(const DrawRecord& a, const DrawRecord& b) {
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.role, b.role);
  EXPECT_EQ(a.object, b.object);
  EXPECT_EQ(a.node, b.node);
  EXPECT_EQ(a.level, b.level);
  EXPECT_EQ(a.state.func, b.state.func);
  EXPECT_EQ(a.state.write, b.state.write);
  EXPECT_EQ(a.state.test, b.state.test);
  EXPECT_EQ(a.state.cull, b.state.cull);
  EXPECT_EQ(a.state.front_ccw, b.state.front_ccw);
  EXPECT_EQ(a.state.clip, b.state.clip);
  EXPECT_EQ(a.state.depth_clamp, b.state.depth_clamp);
  ASSERT_EQ(a.clip_positions.size(), b.clip_positions.size()) << "draw " << a.index;
  for (std::size_t i = 0; i < a.clip_positions.size(); ++i)
    EXPECT_TRUE(same_floats(a.clip_positions[i], b.clip_positions[i])) << "draw " << a.index << " vertex " << i;
  EXPECT_EQ(a.has_bounds, b.has_bounds);
  EXPECT_EQ(a.bounds.x, b.bounds.x);
  EXPECT_EQ(a.bounds.y, b.bounds.y);
  EXPECT_EQ(a.bounds.w, b.bounds.w);
  EXPECT_EQ(a.bounds.h, b.bounds.h);
  EXPECT_EQ(bits(a.bounds.nearest_depth), bits(b.bounds.nearest_depth));
  EXPECT_EQ(a.bounds.crosses_near, b.bounds.crosses_near);
  EXPECT_EQ(a.bounds.visible, b.bounds.visible);
  EXPECT_EQ(a.gl.fragments, b.gl.fragments);
  EXPECT_EQ(a.gl.samples_passed, b.gl.samples_passed);
  EXPECT_EQ(a.gl.clip_prims_in, b.gl.clip_prims_in);
  EXPECT_EQ(a.gl.clip_prims_out, b.gl.clip_prims_out);
  EXPECT_EQ(a.topology, b.topology) << "draw " << a.index;
  EXPECT_TRUE(same_words(a.point_sizes, b.point_sizes)) << "draw " << a.index;
  EXPECT_EQ(a.stencil.test, b.stencil.test);
  for (const auto& [x, y] : {std::pair{&a.stencil.front, &b.stencil.front}, std::pair{&a.stencil.back, &b.stencil.back}}) {
    EXPECT_EQ(x->func, y->func);
    EXPECT_EQ(x->ref, y->ref);
    EXPECT_EQ(x->value_mask, y->value_mask);
    EXPECT_EQ(x->write_mask, y->write_mask);
    EXPECT_EQ(x->fail, y->fail);
    EXPECT_EQ(x->depth_fail, y->depth_fail);
    EXPECT_EQ(x->pass, y->pass);
  }
  EXPECT_EQ(a.discards, b.discards);
  EXPECT_EQ(a.writes_depth, b.writes_depth);
}

inline void expect_same(const StencilSnapshot& a, const StencilSnapshot& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.texels, b.texels);
}

inline void expect_same(const Camera& a, const Camera& b) {
  EXPECT_TRUE(same_floats(a.view, b.view)) << "light view";
  EXPECT_TRUE(same_floats(a.proj, b.proj)) << "light proj";
  EXPECT_TRUE(same_floats(a.eye, b.eye)) << "light eye";
}

inline void expect_same(const TechniqueRecord& a, const TechniqueRecord& b) {
  EXPECT_EQ(a.type, b.type);
  EXPECT_EQ(a.decoded, b.decoded);
  if (a.decoded && b.decoded) EXPECT_EQ(encode(a), encode(b));  // the bytes a writer writes
  else EXPECT_EQ(a.payload, b.payload);
  ASSERT_EQ(a.fields.size(), b.fields.size());
  for (std::size_t i = 0; i < a.fields.size(); ++i) {
    EXPECT_EQ(a.fields[i].name, b.fields[i].name);
    if (const auto* v = std::get_if<std::vector<float>>(&a.fields[i].value)) {
      const auto* w = std::get_if<std::vector<float>>(&b.fields[i].value);
      ASSERT_NE(w, nullptr) << a.fields[i].name;
      EXPECT_TRUE(same_words(*v, *w)) << a.fields[i].name;
    } else {
      EXPECT_TRUE(a.fields[i].value == b.fields[i].value) << a.fields[i].name;
    }
  }
}

inline void expect_same(const DepthSnapshot& a, const DepthSnapshot& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_TRUE(same_words(a.texels, b.texels));
}

inline void expect_same(const NBufferLevels& a, const NBufferLevels& b) {
  EXPECT_EQ(a.source, b.source);
  EXPECT_EQ(a.op, b.op);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.levels, b.levels);
  EXPECT_TRUE(same_words(a.texels, b.texels));
}

inline void expect_same(const GroundTruth& a, const GroundTruth& b) {
  EXPECT_EQ(a.visible_pixels, b.visible_pixels);
  EXPECT_EQ(a.covered_pixels, b.covered_pixels);
  EXPECT_EQ(a.id_width, b.id_width);
  EXPECT_EQ(a.id_height, b.id_height);
  EXPECT_EQ(a.ids, b.ids);
}

inline void expect_same(const SampleFrame& want, const Frame& got) {
  expect_same(want.begin, got.begin);
  ASSERT_EQ(want.draws.size(), got.draws.size());
  for (std::size_t i = 0; i < want.draws.size(); ++i) expect_same(want.draws[i], got.draws[i]);
  ASSERT_EQ(want.depths.size(), got.depths.size());
  for (std::size_t i = 0; i < want.depths.size(); ++i) expect_same(want.depths[i], got.depths[i]);
  ASSERT_EQ(want.levels.size(), got.levels.size());
  for (std::size_t i = 0; i < want.levels.size(); ++i) expect_same(want.levels[i], got.levels[i]);
  ASSERT_EQ(want.stencils.size(), got.stencils.size());
  for (std::size_t i = 0; i < want.stencils.size(); ++i) expect_same(want.stencils[i], got.stencils[i]);
  ASSERT_EQ(want.light.has_value(), got.light.has_value());
  if (want.light) expect_same(*want.light, *got.light);
  ASSERT_EQ(want.technique_records.size(), got.technique_records.size());
  for (std::size_t i = 0; i < want.technique_records.size(); ++i) expect_same(want.technique_records[i], got.technique_records[i]);
  ASSERT_EQ(want.truth.has_value(), got.truth.has_value());
  if (want.truth) expect_same(*want.truth, *got.truth);
  EXPECT_EQ(want.end.frame, got.end.frame);
  EXPECT_EQ(want.end.draws, got.end.draws);
  EXPECT_EQ(std::bit_cast<std::uint64_t>(want.end.gl_ms), std::bit_cast<std::uint64_t>(got.end.gl_ms));
}

// Reads a whole trace (every record decoded and checked); throws InputError on any problem.
inline std::size_t read_all(TraceReader r) {
  FrameReader frames(std::move(r));
  std::size_t n = 0;
  while (frames.next()) ++n;
  return n;
}

// Byte offsets of every chunk header, walking the framing of an intact trace.
inline std::vector<std::size_t> chunk_offsets(const Bytes& b) {
  std::vector<std::size_t> at;
  std::size_t p = kPreambleBytes;
  while (p + kChunkHeaderBytes <= b.size()) {
    at.push_back(p);
    std::uint64_t stored = 0;
    for (int i = 0; i < 8; ++i) stored |= static_cast<std::uint64_t>(b[p + 8 + static_cast<std::size_t>(i)]) << (8 * i);
    p += kChunkHeaderBytes + static_cast<std::size_t>(stored) + kChunkCrcBytes;
  }
  return at;
}

// A trace holding only a header with these properties (and its end), in memory.
inline Bytes header_only(const Properties& props) {
  Bytes b;
  const auto pre = encode_preamble(kFormatVersion);
  b.assign(pre.begin(), pre.end());
  for (const Bytes& c : {encode_chunk(ChunkType::Header, encode(props)), encode_chunk(ChunkType::End, encode(EndMarker{1, 0}))})
    b.insert(b.end(), c.begin(), c.end());
  return b;
}

}  // namespace nbsim::trace::testing

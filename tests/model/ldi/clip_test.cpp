// ClipReplayTest: the model's per-fragment volume test (model/ldi/clip.h) on hand-made frames, no
// GL: a 16x16 viewport whose window coordinates map to the volume's texels one to one, a box volume
// over texels 4..11 between depths 0.25 and 0.75, and a full-screen quad at depth 0.5. Every count
// is known: 64 fragments inside, 192 outside; the readers' fetches; the discard sums; the depth
// buffer. A GL value off by one is reported, and damaged records are refused.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "model/common/error.h"
#include "model/ldi/clip.h"
#include "model/mesh/shapes.h"

namespace nbsim::ldi {
namespace {

constexpr int kSide = 16;

scene::TechniqueField field(const char* name, auto value) { return scene::TechniqueField{name, value}; }

// The box [0.25, 0.75]^2 x [0.25, 0.75] in the unit cube, and its LDI at 16x16 seen along +z:
// two layers at 0.25 and 0.75 on the texels whose centres it covers (4 .. 11).
scene::TechniqueRecord box_volume() {
  const mesh::TriMesh m = mesh::make_box({0.25f, 0.25f, 0.25f}, {0.75f, 0.75f, 0.75f});
  std::vector<std::vector<float>> texels(kSide * kSide);
  for (int y = 4; y < 12; ++y)
    for (int x = 4; x < 12; ++x) texels[static_cast<std::size_t>(y * kSide + x)] = {0.25f, 0.75f};
  const Ldi l = Ldi::from_texels(kSide, kSide, texels);
  const CompressedLdi c = compress(l);
  std::vector<float> xyz;
  std::vector<std::uint32_t> tri;
  for (const mesh::Vec3f& p : m.vertices) xyz.insert(xyz.end(), p.begin(), p.end());
  for (const mesh::Tri& t : m.triangles) tri.insert(tri.end(), t.begin(), t.end());
  scene::TechniqueRecord r;
  r.type = kLdiVolumeRecordType;
  r.decoded = true;
  r.fields = {field("volume", std::uint64_t{0}), field("shape", std::string("box")), field("center_x", 0.5), field("center_y", 0.5),
              field("center_z", 0.5), field("size", 1.0), field("mesh_vertices", xyz), field("mesh_triangles", tri),
              field("view", std::vector<float>{0, 0, 1, 1, 0, 0, 0, 1, 0}), field("width", std::uint64_t{kSide}),
              field("height", std::uint64_t{kSide}), field("layer_count", static_cast<std::uint64_t>(l.layer_count())),
              field("layers", l.depths()), field("crop_x", std::int64_t{c.crop.rect.x}), field("crop_y", std::int64_t{c.crop.rect.y}),
              field("crop_w", std::int64_t{c.crop.rect.w}), field("crop_h", std::int64_t{c.crop.rect.h}),
              field("comp_side", static_cast<std::uint64_t>(c.side)), field("compressed", c.texels)};
  return r;
}

struct Expected {
  std::uint32_t discarded = 0, fetches = 0, hash_a = 0, hash_b = 0, samples = 0, crc = 0;
};

// What GL would record for the quad at window depth 0.5 (the fragments of the 8x8 square inside).
Expected expected(bool keep_inside) {
  Expected e;
  std::vector<float> depth(kSide * kSide, 1.0f);
  const float z = 0.5f;
  std::uint32_t zbits = 0;
  std::memcpy(&zbits, &z, 4);
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x) {
      const bool inside = x >= 4 && x < 12 && y >= 4 && y < 12;
      e.fetches += inside ? 2 : 0;  // every reader: two layers (all, layers) or the index and one range (ranges)
      if (inside != keep_inside) {
        const std::uint32_t key = mix_bits(static_cast<std::uint32_t>(y * kSide + x) ^ mix_bits(zbits));
        ++e.discarded, e.hash_a += key, e.hash_b += mix_bits(key + 0x9e3779b9u);
      } else {
        ++e.samples, depth[static_cast<std::size_t>(y * kSide + x)] = z;
      }
    }
  e.crc = depth_crc(depth);
  return e;
}

// Window (x, y, z) -> world (x / 16, y / 16, z): view_proj maps the world's unit cube onto NDC.
scene::TechniqueRecord clip_record(std::uint64_t reader, bool keep_inside, const Expected& e, std::uint32_t draw = 0) {
  const std::vector<float> view_proj = {2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, -1, -1, -1, 1};
  const std::vector<float> window_to_texel = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  scene::TechniqueRecord r;
  r.type = kLdiClipRecordType;
  r.decoded = true;
  r.fields = {field("volume_count", std::uint64_t{1}), field("reader", reader), field("width", std::uint64_t{kSide}),
              field("height", std::uint64_t{kSide}), field("epsilon", 1e-6), field("view_proj", view_proj),
              field("window_to_texel", window_to_texel), field("draws", std::vector<std::uint32_t>{draw}),
              field("keep_inside", std::vector<std::uint32_t>{keep_inside ? 1u : 0u}),
              field("gl_discarded", std::vector<std::uint32_t>{e.discarded}), field("gl_fetches", std::vector<std::uint32_t>{e.fetches}),
              field("gl_hash_a", std::vector<std::uint32_t>{e.hash_a}), field("gl_hash_b", std::vector<std::uint32_t>{e.hash_b}),
              field("depth_crc", std::uint64_t{e.crc})};
  return r;
}

// A frame: the volume (when `with_volume`), the quad covering the viewport at NDC z 0, the LDIC.
scene::Frame quad_frame(std::uint64_t reader, bool keep_inside, const Expected& e, bool with_volume = true) {
  scene::Frame f;
  scene::DrawRecord d;
  d.index = 0;
  d.role = scene::DrawRole::Scene;
  d.state.cull = scene::CullFace::None;
  d.clip_positions = {{-1, -1, 0, 1}, {1, -1, 0, 1}, {1, 1, 0, 1}, {-1, -1, 0, 1}, {1, 1, 0, 1}, {-1, 1, 0, 1}};
  d.gl.fragments = kSide * kSide;
  d.gl.samples_passed = e.samples;
  f.draws.push_back(d);
  if (with_volume) f.technique_records.push_back(box_volume());
  f.technique_records.push_back(clip_record(reader, keep_inside, e));
  return f;
}

TEST(ClipReplayTest, EveryReaderDiscardsInsideTheBox) {
  for (std::uint64_t reader : {0u, 1u, 2u}) {
    SCOPED_TRACE(reader);
    ClipReplay replay(true, memory::CacheConfig{});
    const Expected e = expected(false);
    const ClipFrameCounts k = replay.run_frame(quad_frame(reader, false, e));
    ASSERT_EQ(k.draws.size(), 1u);
    const ClipDrawCounts& d = k.draws[0];
    EXPECT_EQ(d.discarded, 64u);
    EXPECT_EQ(d.path.depth.passed, 192u);
    EXPECT_EQ(d.path.depth.depth_tests, 192u) << "a discarded fragment is never depth tested";
    EXPECT_EQ(d.fetches, 128u);
    EXPECT_EQ(k.reader_fetches[0] + k.reader_fetches[1] + k.reader_fetches[2], 3 * 128u);
    EXPECT_EQ(k.draw_mismatches, 0u);
    EXPECT_FALSE(k.depth_mismatch);
    EXPECT_EQ(k.volume_mismatches, 0u);
    EXPECT_EQ(d.classified, 256u);
    EXPECT_EQ(d.misclassified, 0u) << "the LDI is exact on texel centres";
    EXPECT_EQ(d.volume_tests, 256u);
    EXPECT_EQ(d.cache_hits + d.cache_misses, 128u);
  }
}

TEST(ClipReplayTest, TheLensFocusKeepsOnlyTheInside) {
  ClipReplay replay(true, memory::CacheConfig{});
  const Expected e = expected(true);
  const ClipFrameCounts k = replay.run_frame(quad_frame(1, true, e));
  EXPECT_EQ(k.draws[0].discarded, 192u);
  EXPECT_EQ(k.draws[0].path.depth.passed, 64u);
  EXPECT_EQ(k.draw_mismatches, 0u);
  EXPECT_FALSE(k.depth_mismatch);
}

TEST(ClipReplayTest, VolumesStayForTheFramesAfter) {
  ClipReplay replay(true, memory::CacheConfig{});
  const Expected e = expected(false);
  EXPECT_EQ(replay.run_frame(quad_frame(1, false, e)).volumes_loaded, 1u);
  const ClipFrameCounts later = replay.run_frame(quad_frame(1, false, e, false));
  EXPECT_EQ(later.volumes_loaded, 0u);
  EXPECT_EQ(later.draws[0].discarded, 64u);
  EXPECT_EQ(later.draw_mismatches, 0u);
}

TEST(ClipReplayTest, AGlValueUnlikeTheModelsIsCounted) {
  ClipReplay replay(true, memory::CacheConfig{});
  Expected e = expected(false);
  e.hash_b += 1;  // one discarded fragment's identity differs
  const ClipFrameCounts k = replay.run_frame(quad_frame(1, false, e));
  EXPECT_EQ(k.draw_mismatches, 1u);
  EXPECT_EQ(k.decision_mismatches, 1u);
  e = expected(false);
  e.crc ^= 1;
  EXPECT_TRUE(replay.run_frame(quad_frame(1, false, e)).depth_mismatch);
}

TEST(ClipReplayTest, DamagedRecordsAreRefused) {
  const Expected e = expected(false);
  {
    ClipReplay replay(true, memory::CacheConfig{});
    EXPECT_THROW(replay.run_frame(quad_frame(1, false, e, false)), InputError) << "a clipping frame before any volume";
  }
  {
    ClipReplay replay(true, memory::CacheConfig{});
    scene::Frame f = quad_frame(1, false, e);
    f.technique_records.back() = clip_record(1, false, e, 7);
    EXPECT_THROW(replay.run_frame(f), InputError) << "a draw the frame does not have";
  }
  {
    ClipReplay replay(true, memory::CacheConfig{});
    scene::Frame f = quad_frame(1, false, e);
    std::get<std::vector<float>>(f.technique_records.back().fields[6].value).pop_back();
    EXPECT_THROW(replay.run_frame(f), InputError) << "window_to_texel is short";
  }
  {
    ClipReplay replay(true, memory::CacheConfig{});
    scene::Frame f = quad_frame(1, false, e);
    auto& tri = std::get<std::vector<std::uint32_t>>(f.technique_records.front().fields[7].value);
    tri.resize(tri.size() - 3);  // one triangle fewer: a hole
    EXPECT_THROW(replay.run_frame(f), InputError) << "the volume's mesh is not closed";
  }
}

}  // namespace
}  // namespace nbsim::ldi

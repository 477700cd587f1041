// ReliefRecordsTest: the relief technique's readers of RLFH and RLFF (model/relief/records.h) on a
// hand-made frame: a good frame reads back field for field, and every damage the readers check
// (missing records and fields, lengths, NaN, ranges, radii that are not whole, an N-buffer texel
// that is not the max of the heights, fragments of a draw that is not a relief box, pixel order)
// is an InputError naming the frame, the record and the problem.
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "model/nbuffer/nbuffer.h"
#include "model/relief/records.h"
#include "model/relief/roles.h"

namespace nbsim::relief {
namespace {

constexpr int kN = 4;
constexpr std::uint32_t kFrame = 9;
constexpr std::uint64_t kViewportPixels = 8 * 6;

scene::TechniqueField field(const char* name, auto value) { return scene::TechniqueField{name, value}; }

// 4x4 heights in [0, 1] (not symmetric, so a transposed reader would be caught).
std::vector<float> sample_heights() {
  std::vector<float> h(kN * kN);
  for (int j = 0; j < kN; ++j)
    for (int i = 0; i < kN; ++i) h[static_cast<std::size_t>(j * kN + i)] = static_cast<float>((i * 3 + j * 5) % 7) / 8.0f;
  return h;
}

// The max N-buffer of `heights`, level-major, as the model builds it.
std::vector<float> max_nbuffer(const std::vector<float>& heights) {
  DepthImage image(kN, kN, 0.0f);
  image.texels = heights;
  const NBuffer nb(image, NBufferConfig{FarOp::Max, StorageFormat::F32, -1});
  std::vector<float> out;
  for (int l = 0; l < nb.level_count(); ++l) out.insert(out.end(), nb.level(l).begin(), nb.level(l).end());
  return out;
}

// RLFH, fields in the registered order (traces/format/relief/relief_chunk.cpp).
scene::TechniqueRecord field_record() {
  const std::vector<float> heights = sample_heights();
  scene::TechniqueRecord r;
  r.type = kReliefFieldRecordType;
  r.decoded = true;
  r.fields = {field("size", std::uint64_t{kN}),
              field("levels", std::uint64_t{2}),
              field("max_radius", std::uint64_t{3}),
              field("field", std::string("hand-made 4x4")),
              field("heights", heights),
              field("radius", std::vector<float>{0, 1, 2, 3, 1, 0, 0, 2, 3, 3, 1, 0, 2, 1, 0, 1}),
              field("nbuffer", max_nbuffer(heights)),
              field("linear_steps", std::uint64_t{16}),
              field("binary_steps", std::uint64_t{8}),
              field("root_steps", std::uint64_t{4}),
              field("origin", std::vector<float>{2.0f, -3.0f, 5.5f}),
              field("ray_a", std::vector<float>{0.125f, 0.0f, 0.0f}),
              field("ray_b", std::vector<float>{0.0f, 0.125f, 0.0f}),
              field("ray_c", std::vector<float>{-0.5f, 1.0f, -1.0f}),
              field("view_angle", 30.0),
              field("frustum_apex", 0.0),
              field("eye_h", std::vector<float>{}),
              field("ray_q", std::vector<float>{})};
  return r;
}

// RLFF of `draw` with three fragments.
scene::TechniqueRecord fragments_record(std::uint32_t draw, std::uint32_t method) {
  scene::TechniqueRecord r;
  r.type = kReliefFragmentsRecordType;
  r.decoded = true;
  r.fields = {field("draw", std::uint64_t{draw}),
              field("method", std::uint64_t{method}),
              field("count", std::uint64_t{3}),
              field("pixel", std::vector<std::uint32_t>{9, 10, 17}),
              field("hit", std::vector<std::uint32_t>{1, 0, 2}),
              field("t", std::vector<float>{0.75f, 0.0f, 0.0f}),
              field("lookups", std::vector<std::uint32_t>{12, 8, 400}),
              field("steps", std::vector<std::uint32_t>{3, 2, 100}),
              field("bisections", std::vector<std::uint32_t>{8, 0, 0})};
  return r;
}

scene::DrawRecord draw(std::uint32_t index, scene::DrawRole role) {
  scene::DrawRecord d;
  d.index = index;
  d.role = role;
  return d;
}

// Draw 0 fills the depth buffer (a scene draw), draws 1 and 2 are relief boxes (binary, nbuffer).
scene::Frame sample_frame() {
  scene::Frame f;
  f.begin.frame = kFrame;
  f.end.frame = kFrame;
  f.draws = {draw(0, scene::DrawRole::Scene), draw(1, nbsim::relief::kReliefBoxRole), draw(2, nbsim::relief::kReliefBoxRole)};
  f.end.draws = 3;
  f.technique_records = {field_record(), fragments_record(1, 0), fragments_record(2, 4)};
  return f;
}

scene::TechniqueField& field_of(scene::Frame& f, std::uint32_t type, const char* name, int nth = 0) {
  for (scene::TechniqueRecord& r : f.technique_records)
    if (r.type == type && nth-- == 0)
      for (scene::TechniqueField& x : r.fields)
        if (x.name == name) return x;
  throw std::logic_error("no such field");
}
template <class T>
std::vector<T>& vec(scene::Frame& f, std::uint32_t type, const char* name, int nth = 0) {
  return std::get<std::vector<T>>(field_of(f, type, name, nth).value);
}

// Both readers on `f`: the InputError's message, or "" when both read it.
std::string read_error(const scene::Frame& f) {
  try {
    read_relief_field(f);
    read_relief_fragments(f, kViewportPixels);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A good frame reads back every field as recorded.
TEST(ReliefRecordsTest, GoodRecordsReadBack) {
  const scene::Frame f = sample_frame();
  const GlReliefField g = read_relief_field(f);
  EXPECT_EQ(g.field.size, kN);
  EXPECT_EQ(g.field.heights, sample_heights());
  EXPECT_EQ(g.radius.size, kN);
  EXPECT_EQ(g.radius.radius[3], 3.0f);
  EXPECT_EQ(g.max_radius, 3);
  EXPECT_EQ(g.levels, 2);
  EXPECT_EQ(g.nbuffer, max_nbuffer(sample_heights()));
  EXPECT_EQ(g.description, "hand-made 4x4");
  EXPECT_EQ(g.params.linear_steps, 16);
  EXPECT_EQ(g.params.binary_steps, 8);
  EXPECT_EQ(g.params.root_steps, 4);
  EXPECT_EQ(g.ray.origin, (std::array<float, 3>{2.0f, -3.0f, 5.5f}));
  EXPECT_EQ(g.ray.a, (std::array<float, 3>{0.125f, 0.0f, 0.0f}));
  EXPECT_EQ(g.ray.b, (std::array<float, 3>{0.0f, 0.125f, 0.0f}));
  EXPECT_EQ(g.ray.c, (std::array<float, 3>{-0.5f, 1.0f, -1.0f}));
  EXPECT_EQ(g.view_angle, 30.0);

  const std::vector<GlReliefFragments> k = read_relief_fragments(f, kViewportPixels);
  ASSERT_EQ(k.size(), 2u);
  EXPECT_EQ(k[0].draw, 1u);
  EXPECT_EQ(k[0].method, Method::Binary);
  EXPECT_EQ(k[1].draw, 2u);
  EXPECT_EQ(k[1].method, Method::NBuffer);
  EXPECT_TRUE(std::ranges::equal(k[0].pixel, std::vector<std::uint32_t>{9, 10, 17}));
  EXPECT_TRUE(std::ranges::equal(k[0].hit, std::vector<std::uint32_t>{1, 0, 2}));
  EXPECT_TRUE(std::ranges::equal(k[0].t, std::vector<float>{0.75f, 0.0f, 0.0f}));
  EXPECT_TRUE(std::ranges::equal(k[0].lookups, std::vector<std::uint32_t>{12, 8, 400}));
  EXPECT_TRUE(std::ranges::equal(k[0].steps, std::vector<std::uint32_t>{3, 2, 100}));
  EXPECT_TRUE(std::ranges::equal(k[0].bisections, std::vector<std::uint32_t>{8, 0, 0}));
}

// The view spans the record's own vectors.
TEST(ReliefRecordsTest, ViewSpansTheRecord) {
  const GlReliefField g = read_relief_field(sample_frame());
  const FieldView v = g.view();
  EXPECT_EQ(v.size, kN);
  EXPECT_EQ(v.levels, 2);
  EXPECT_EQ(v.heights.data(), g.field.heights.data());
  EXPECT_EQ(v.heights.size(), 16u);
  EXPECT_EQ(v.radius.data(), g.radius.radius.data());
  EXPECT_EQ(v.radius.size(), 16u);
  EXPECT_EQ(v.nbuffer.data(), g.nbuffer.data());
  EXPECT_EQ(v.nbuffer.size(), 32u);
}

// The level count follows the size: N = 2 has one level, 3 and 4 two, 5 three (non-powers of two round up).
TEST(ReliefRecordsTest, LevelCountFollowsTheSize) {
  for (const int n : {2, 3, 5}) {
    scene::Frame f = sample_frame();
    std::vector<float> heights(static_cast<std::size_t>(n * n), 0.25f);
    heights.back() = 1.0f;
    DepthImage image(n, n, 0.0f);
    image.texels = heights;
    const NBuffer nb(image, NBufferConfig{FarOp::Max, StorageFormat::F32, -1});
    std::vector<float> levels;
    for (int l = 0; l < nb.level_count(); ++l) levels.insert(levels.end(), nb.level(l).begin(), nb.level(l).end());
    field_of(f, kReliefFieldRecordType, "size").value = std::uint64_t(n);
    field_of(f, kReliefFieldRecordType, "levels").value = std::uint64_t(nb.level_count());
    field_of(f, kReliefFieldRecordType, "heights").value = heights;
    field_of(f, kReliefFieldRecordType, "radius").value = std::vector<float>(heights.size(), 1.0f);
    field_of(f, kReliefFieldRecordType, "nbuffer").value = levels;
    EXPECT_EQ(read_error(f), "") << n << "x" << n;
    EXPECT_EQ(read_relief_field(f).levels, n == 2 ? 1 : n <= 4 ? 2 : 3) << n;
  }
}

// Every damage is an InputError naming the frame, the record and what is wrong.
TEST(ReliefRecordsTest, DamagedRecordsAreInputErrors) {
  using F = scene::Frame;
  constexpr std::uint32_t H = kReliefFieldRecordType, K = kReliefFragmentsRecordType;
  struct Row {
    const char* why;
    std::function<void(F&)> damage;
    const char* message;
  };
  const Row rows[] = {
      // RLFH
      {"no RLFH", [](F& f) { f.technique_records.erase(f.technique_records.begin()); }, "no ReliefField (RLFH) record"},
      {"two RLFH", [](F& f) { f.technique_records.push_back(field_record()); }, "more than one ReliefField (RLFH) record"},
      {"RLFH not decoded", [](F& f) { f.technique_records[0].decoded = false; }, "was not decoded"},
      {"a missing field", [](F& f) { field_of(f, H, "root_steps").name = "root_step"; }, "has no field 'root_steps'"},
      {"a field of the wrong type", [](F& f) { field_of(f, H, "heights").value = std::vector<std::uint32_t>(16, 0); },
       "field 'heights' has the wrong type"},
      {"size 1", [](F& f) { field_of(f, H, "size").value = std::uint64_t{1}; }, "size is 1, not 2 to 1024"},
      {"size 2048", [](F& f) { field_of(f, H, "size").value = std::uint64_t{2048}; }, "size is 2048, not 2 to 1024"},
      {"levels that are not the size's", [](F& f) { field_of(f, H, "levels").value = std::uint64_t{3}; },
       "levels is 3, but a 4x4 N-buffer has 2"},
      {"max_radius 0", [](F& f) { field_of(f, H, "max_radius").value = std::uint64_t{0}; }, "max_radius is 0, not 1 to 255"},
      {"max_radius 256", [](F& f) { field_of(f, H, "max_radius").value = std::uint64_t{256}; }, "max_radius is 256, not 1 to 255"},
      {"heights one short", [](F& f) { vec<float>(f, H, "heights").pop_back(); }, "field 'heights' has 15 values, but size x size (4x4) is 16"},
      {"radius one long", [](F& f) { vec<float>(f, H, "radius").push_back(0); }, "field 'radius' has 17 values"},
      {"nbuffer one plane", [](F& f) { vec<float>(f, H, "nbuffer").resize(16); }, "field 'nbuffer' has 16 values, but levels x size x size (2x4x4) is 32"},
      {"origin of 2", [](F& f) { vec<float>(f, H, "origin").pop_back(); }, "field 'origin' has 2 values"},
      {"ray_c of 4", [](F& f) { vec<float>(f, H, "ray_c").push_back(0); }, "field 'ray_c' has 4 values"},
      {"a NaN height", [](F& f) { vec<float>(f, H, "heights")[6] = std::nanf(""); }, "field 'heights' has NaN at index 6"},
      {"height 1.5", [](F& f) { vec<float>(f, H, "heights")[9] = 1.5f; }, "height of texel (1, 2) is 1.5, outside [0, 1]"},
      {"a negative height", [](F& f) { vec<float>(f, H, "heights")[0] = -0.25f; }, "height of texel (0, 0) is -0.25"},
      {"radius 2.5", [](F& f) { vec<float>(f, H, "radius")[7] = 2.5f; }, "radius of texel (3, 1) is 2.5, not a whole number in [0, 3]"},
      {"radius above max_radius", [](F& f) { vec<float>(f, H, "radius")[4] = 4.0f; }, "radius of texel (0, 1) is 4, not a whole number"},
      {"a negative radius", [](F& f) { vec<float>(f, H, "radius")[4] = -1.0f; }, "radius of texel (0, 1) is -1"},
      {"an infinite radius", [](F& f) { vec<float>(f, H, "radius")[4] = INFINITY; }, "radius of texel (0, 1) is inf"},
      {"a NaN radius", [](F& f) { vec<float>(f, H, "radius")[5] = std::nanf(""); }, "field 'radius' has NaN at index 5"},
      {"a wrong N-buffer texel on level 1", [](F& f) { vec<float>(f, H, "nbuffer")[16 + 2 * 4 + 1] = 1.0f; },
       "not the max N-buffer of its heights: level 1 texel (1, 2) is 1, but the heights give"},
      {"level 0 is not the heights", [](F& f) { vec<float>(f, H, "nbuffer")[3] = std::nextafter(vec<float>(f, H, "nbuffer")[3], 1.0f); },
       "level 0 texel (3, 0)"},
      {"a NaN N-buffer texel", [](F& f) { vec<float>(f, H, "nbuffer")[20] = std::nanf(""); }, "field 'nbuffer' has NaN at index 20"},
      {"linear_steps 0", [](F& f) { field_of(f, H, "linear_steps").value = std::uint64_t{0}; }, "linear_steps is 0, not 1 to 1024"},
      {"linear_steps 1025", [](F& f) { field_of(f, H, "linear_steps").value = std::uint64_t{1025}; }, "linear_steps is 1025"},
      {"binary_steps 33", [](F& f) { field_of(f, H, "binary_steps").value = std::uint64_t{33}; }, "binary_steps is 33, not 0 to 32"},
      {"root_steps 33", [](F& f) { field_of(f, H, "root_steps").value = std::uint64_t{33}; }, "root_steps is 33, not 0 to 32"},
      {"a NaN in the ray frame", [](F& f) { vec<float>(f, H, "ray_b")[1] = std::nanf(""); }, "field 'ray_b' has NaN at index 1"},
      // RLFF
      {"fragments of a scene draw", [](F& f) { field_of(f, K, "draw").value = std::uint64_t{0}; },
       "ReliefFragments (RLFF) record 0: draw 0 is a scene draw, not a relief_box draw"},
      {"fragments of a draw the frame lacks", [](F& f) { field_of(f, K, "draw", 1).value = std::uint64_t{3}; },
       "record 1: draw 3 is not a draw of the frame (3 draws)"},
      {"two records of one draw", [](F& f) { field_of(f, K, "draw", 1).value = std::uint64_t{1}; },
       "record 1: draw 1 already has its fragments"},
      {"a relief box without fragments", [](F& f) { f.technique_records.pop_back(); }, "relief_box draw 2 has no ReliefFragments (RLFF) record"},
      {"RLFF not decoded", [](F& f) { f.technique_records[2].decoded = false; }, "ReliefFragments (RLFF) record 1 was not decoded"},
      {"method 5", [](F& f) { field_of(f, K, "method").value = std::uint64_t{5}; }, "method is 5, above 4"},
      {"a vector shorter than count", [](F& f) { vec<float>(f, K, "t").pop_back(); }, "field 't' has 2 values, but count is 3"},
      {"count larger than the vectors", [](F& f) { field_of(f, K, "count", 1).value = std::uint64_t{4}; }, "field 'pixel' has 3 values, but count is 4"},
      {"unsorted pixels", [](F& f) { vec<std::uint32_t>(f, K, "pixel") = {9, 17, 10}; },
       "pixels are not strictly increasing: fragment 2 is at pixel 10, after 17"},
      {"a repeated pixel", [](F& f) { vec<std::uint32_t>(f, K, "pixel") = {9, 9, 10}; }, "fragment 1 is at pixel 9, after 9"},
      {"a pixel outside the viewport", [](F& f) { vec<std::uint32_t>(f, K, "pixel")[2] = 48; },
       "fragment 2 is at pixel 48, outside the viewport's 48 pixels"},
      {"hit 3", [](F& f) { vec<std::uint32_t>(f, K, "hit", 1)[0] = 3; }, "record 1: fragment 0 has hit 3, above 2"},
      {"a NaN t", [](F& f) { vec<float>(f, K, "t")[0] = std::nanf(""); }, "fragment 0 has t NaN"},
      {"a missing RLFF field", [](F& f) { field_of(f, K, "bisections").name = "bisection"; }, "has no field 'bisections'"},
  };
  for (const Row& r : rows) {
    scene::Frame f = sample_frame();
    ASSERT_EQ(read_error(f), "") << "the sample frame is good";
    r.damage(f);
    const std::string e = read_error(f);
    EXPECT_NE(e.find("frame 9"), std::string::npos) << r.why << ": " << e;
    EXPECT_NE(e.find(r.message), std::string::npos) << r.why << ": " << (e.empty() ? "accepted" : e);
  }
}

// A frame without relief records has no fragments (and no box draw to miss them).
TEST(ReliefRecordsTest, NoBoxDrawNoFragments) {
  scene::Frame f = sample_frame();
  f.draws.resize(1);
  f.technique_records.resize(1);
  EXPECT_TRUE(read_relief_fragments(f, kViewportPixels).empty());
}

// RLFD (the depth the boxes left): read back, optional unless the boxes write depth, and every
// damage an InputError naming the frame.
TEST(ReliefRecordsTest, DepthRecord) {
  scene::Frame f = sample_frame();
  EXPECT_FALSE(read_relief_depth(f, false).has_value()) << "no RLFD and none needed";
  try {
    read_relief_depth(f, true);
    ADD_FAILURE() << "a missing RLFD was accepted where the boxes write depth";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no ReliefDepth (RLFD) record"), std::string::npos) << e.what();
  }
  scene::TechniqueRecord depth;
  depth.type = kReliefDepthRecordType;
  depth.decoded = true;
  std::vector<float> m(16, 0.0f);
  m[0] = m[5] = m[10] = m[15] = 1.0f;
  depth.fields = {field("texel_to_clip", m), field("draws", std::vector<std::uint32_t>{1, 2}),
                  field("depth_crc", std::vector<std::uint32_t>{7, 8})};
  f.technique_records.push_back(depth);
  const std::optional<GlReliefDepth> g = read_relief_depth(f, true);
  ASSERT_TRUE(g.has_value());
  EXPECT_EQ(g->texel_to_clip[10], 1.0f);
  EXPECT_EQ(g->depth_crc, (std::vector<std::uint32_t>{7, 8}));
  using F = scene::Frame;
  constexpr std::uint32_t D = kReliefDepthRecordType;
  const std::pair<std::function<void(F&)>, const char*> damages[] = {
      {[](F& frame) { vec<float>(frame, D, "texel_to_clip").pop_back(); }, "texel_to_clip has 15 values, not 16"},
      {[](F& frame) { vec<float>(frame, D, "texel_to_clip")[3] = INFINITY; }, "texel_to_clip[3] is inf"},
      {[](F& frame) { vec<std::uint32_t>(frame, D, "depth_crc").pop_back(); }, "has 2 draws but 1 CRCs"},
      {[](F& frame) { vec<std::uint32_t>(frame, D, "draws") = {0, 2}; }, "relief_box draw 1 has no depth CRC"},
      {[](F& frame) { vec<std::uint32_t>(frame, D, "draws") = {1, 2, 3}, vec<std::uint32_t>(frame, D, "depth_crc") = {1, 2, 3}; },
       "lists 3 draws, but the frame has 2 relief_box draws"},
      {[](F& frame) { field_of(frame, D, "draws").name = "draw"; }, "has no field 'draws'"},
  };
  for (const auto& [damage, message] : damages) {
    F bad = f;
    damage(bad);
    try {
      read_relief_depth(bad, false);
      ADD_FAILURE() << message << ": accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("frame 9"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace nbsim::relief

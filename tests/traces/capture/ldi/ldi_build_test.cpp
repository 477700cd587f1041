// LdiBuildTest: the LDI's GL stages (traces/capture/ldi/build.h) on llvmpipe against the model's
// plain cores (model/ldi/): GL's crop and compressed RG32UI texture equal ldi::compress of GL's own
// LDI bit for bit and decompress back to it; GL's parity test (both readers) equals
// model/ldi/vpt.h's answers and fetch counts on every test point; gl_FragCoord.z is the value the
// depth test stored; the viewpoint choice follows its rule; the recorded peel draws; and the hard
// cases: a shape touching the cube's faces, coplanar faces (odd layer counts), planes nearly
// parallel to the view (under-sampling), crop-boundary and near-surface points; and the model's
// peel (model/ldi/peel.h) replaying GL's recorded passes bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>
#include <vector>

#include "model/ldi/compression.h"
#include "model/ldi/peel.h"
#include "model/ldi/vpt.h"
#include "model/mesh/crossings.h"
#include "model/mesh/shapes.h"
#include "traces/capture/draw_recorder.h"
#include "traces/capture/ldi/build.h"
#include "traces/capture/ldi/test_points.h"
#include "traces/format/ldi/ldi_chunk.h"
#include "tests/common/gl_context_suite.h"
#include "model/ldi/roles.h"

namespace nbsim::capture {
namespace {

mesh::TriMesh placed(const char* shape, std::optional<int> parameter = std::nullopt, double margin = 0.0) {
  mesh::TriMesh m = mesh::make_shape(shape, parameter);
  mesh::normalize_to_unit_cube(m, margin);
  return m;
}

// Two boxes stacked along z sharing the face z = 0.5: seen along -z, three layers (odd), since the
// shared plane's two faces collapse into one layer under the strict test.
mesh::TriMesh stacked_boxes() {
  mesh::TriMesh a = mesh::make_box({0.1f, 0.1f, 0.0f}, {0.9f, 0.9f, 0.5f});
  const mesh::TriMesh b = mesh::make_box({0.1f, 0.1f, 0.5f}, {0.9f, 0.9f, 1.0f});
  const auto base = static_cast<std::uint32_t>(a.vertices.size());
  a.vertices.insert(a.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (mesh::Tri t : b.triangles) a.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  return a;
}

class LdiBuildTest : public testing::GlContextSuite {};

struct Case {
  const char* what;
  mesh::TriMesh mesh;
};
std::vector<Case> cases() {
  return {{"sphere", placed("sphere")}, {"nested 3", placed("nested", 3)}, {"coil 3", placed("coil", 3)}, {"knot", placed("knot")}};
}

// GL's crop and compressed texture against ldi::compress of GL's LDI, and the round trip.
void expect_compression_equal(const LdiBuild& b, const std::string& what) {
  const ldi::CompressedLdi model = ldi::compress(b.peel.ldi);
  EXPECT_EQ(b.crop.rect, model.crop.rect) << what << ": GL's crop is the bounding rectangle of the valid texels";
  EXPECT_EQ(b.crop.depth_complexity, model.crop.depth_complexity) << what;
  EXPECT_EQ(b.compressed.index_texels, model.index_texels) << what;
  EXPECT_EQ(b.compressed.range_texels, model.range_texels) << what << ": R = sum of ceil(n / 2)";
  EXPECT_EQ(b.compressed.side, model.side) << what << ": w_c = ceil_sqrt(I + R)";
  ASSERT_EQ(b.compressed.texels.size(), model.texels.size()) << what;
  std::size_t differ = 0, first = model.texels.size();
  for (std::size_t i = 0; i < model.texels.size(); ++i)
    if (b.compressed.texels[i] != model.texels[i]) ++differ, first = std::min(first, i);
  EXPECT_EQ(differ, 0u) << what << ": GL's RG32UI texture equals the model's bit for bit; first difference at value " << first;
  EXPECT_TRUE(ldi::bit_equal(ldi::decompress(b.compressed), b.peel.ldi)) << what << ": decompress(GL's texture) is GL's LDI";
}

// GL's parity test against model/ldi/vpt.h on every point, both readers; returns the points compared.
std::size_t expect_vpt_equal(const LdiBuild& b, const LdiTestPoints& p, const std::string& what) {
  const GlVptAnswers gl = gl_vpt(b, p.x, p.y, p.z);
  const ldi::CroppedLdi cropped = ldi::crop(b.peel.ldi);
  std::size_t bad_layers = 0, bad_ranges = 0;
  for (std::size_t i = 0; i < p.x.size(); ++i) {
    const ldi::VptResult l = ldi::vpt_layers(cropped, p.x[i], p.y[i], p.z[i]);
    const ldi::VptResult r = ldi::vpt_ranges(b.compressed, p.x[i], p.y[i], p.z[i]);
    const bool l_ok = gl.inside_layers[i] == static_cast<std::uint32_t>(l.inside) && gl.fetches_layers[i] == static_cast<std::uint32_t>(l.fetches);
    const bool r_ok = gl.inside_ranges[i] == static_cast<std::uint32_t>(r.inside) && gl.fetches_ranges[i] == static_cast<std::uint32_t>(r.fetches);
    if (!l_ok && bad_layers++ < 5)
      ADD_FAILURE() << what << ": layers reader differs at point " << i << " (" << p.x[i] << ", " << p.y[i] << ", " << p.z[i] << "): GL "
                    << gl.inside_layers[i] << "/" << gl.fetches_layers[i] << " model " << l.inside << "/" << l.fetches;
    if (!r_ok && bad_ranges++ < 5)
      ADD_FAILURE() << what << ": ranges reader differs at point " << i << " (" << p.x[i] << ", " << p.y[i] << ", " << p.z[i] << "): GL "
                    << gl.inside_ranges[i] << "/" << gl.fetches_ranges[i] << " model " << r.inside << "/" << r.fetches;
  }
  EXPECT_EQ(bad_layers, 0u) << what;
  EXPECT_EQ(bad_ranges, 0u) << what;
  return p.x.size();
}

// Crop and compression on GL equal the model's, bit for bit, on four shapes; decompression is lossless.
TEST_F(LdiBuildTest, GlCropAndCompressionEqualTheModel) {
  for (const Case& c : cases()) {
    const LdiBuild b = build_ldi(c.mesh, {.size_texels = 96, .grid_h = 4, .grid_v = 4, .max_layers = 64});
    ASSERT_GT(b.peel.ldi.layer_count(), 0) << c.what;
    expect_compression_equal(b, c.what);
    std::cout << c.what << ": d " << b.peel.ldi.layer_count() << ", crop " << b.crop.rect.w << "x" << b.crop.rect.h << ", I "
              << b.compressed.index_texels << ", R " << b.compressed.range_texels << ", w_c " << b.compressed.side << ", times ms "
              << b.times.viewpoint_ms << " / " << b.times.peel_ms << " / " << b.times.crop_ms << " / " << b.times.compression_ms << "\n";
  }
}

// GL's parity test equals the model's answers and fetch counts on every point (both readers).
TEST_F(LdiBuildTest, GlParityTestEqualsTheModel) {
  std::size_t compared = 0;
  for (const Case& c : cases()) {
    const LdiBuild b = build_ldi(c.mesh, {.size_texels = 80, .grid_h = 3, .grid_v = 3, .max_layers = 64});
    const LdiTestPoints p = make_test_points(b.peel.ldi, b.crop.rect, 4096, 7);
    compared += expect_vpt_equal(b, p, c.what);
  }
  EXPECT_EQ(compared, 4u * 4096u);
}

// gl_FragCoord.z (the layer) is the depth-tested z the depth buffer stored, at every texel of every
// layer, on llvmpipe: the model may replay the depth test with the layer values.
TEST_F(LdiBuildTest, FragCoordZIsTheDepthBufferValue) {
  for (const Case& c : cases()) {
    const PeelResult r = peel_ldi(c.mesh, mesh::OrthoFrame::look_along({1, 2, -3}),
                                  {.width_px = 64, .height_px = 64, .max_layers = 64, .verify_depth_buffer = true});
    EXPECT_GT(r.depth_buffer_checked, 0u) << c.what;
    EXPECT_EQ(r.depth_buffer_mismatches, 0u) << c.what << ": layer bits == depth buffer bits where a layer was written";
  }
}

// The viewpoint choice: smallest d, then largest coverage, then lowest index; the chosen
// direction's measured d is the peel's layer count (no coplanar faces here).
TEST_F(LdiBuildTest, ViewpointSelectionFollowsItsRule) {
  for (const Case& c : cases()) {
    const LdiBuild b = build_ldi(c.mesh, {.size_texels = 64, .grid_h = 4, .grid_v = 3, .max_layers = 64});
    ASSERT_EQ(b.candidate_d.size(), 12u);
    for (std::size_t i = 0; i < 12; ++i) {
      const bool better = b.candidate_d[i] < b.candidate_d[b.direction] ||
                          (b.candidate_d[i] == b.candidate_d[b.direction] && b.candidate_coverage[i] > b.candidate_coverage[b.direction]);
      const bool tie_before = i < b.direction && b.candidate_d[i] == b.candidate_d[b.direction] &&
                              b.candidate_coverage[i] == b.candidate_coverage[b.direction];
      EXPECT_FALSE(better || tie_before) << c.what << ": direction " << i << " should have been chosen over " << b.direction;
    }
    EXPECT_EQ(b.candidate_d[b.direction], static_cast<std::uint32_t>(b.peel.ldi.layer_count())) << c.what;
    std::uint32_t covered = 0;
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x) covered += b.peel.ldi.count(x, y) > 0;
    EXPECT_EQ(b.candidate_coverage[b.direction], covered) << c.what << ": coverage is the texels with a layer";
  }
}

// Each peel pass is recorded (role LdiPeel, the shape's triangles from transform feedback, the
// peel's state), the last one empty; fragments are the same every pass (same geometry).
TEST_F(LdiBuildTest, PeelPassesAreRecorded) {
  const mesh::TriMesh m = placed("nested", 2);
  DrawRecorder recorder;
  recorder.begin_frame(8);
  const LdiBuild b = build_ldi_along(m, mesh::OrthoFrame::look_along({0.3, -0.2, -1}), 64, 64, &recorder);
  const std::vector<scene::DrawRecord> draws = recorder.collect();
  ASSERT_EQ(draws.size(), static_cast<std::size_t>(b.peel.ldi.layer_count()) + 1);
  ASSERT_EQ(b.peel.ldi.layer_count(), 4) << "two shells: d = 4";
  for (std::size_t k = 0; k < draws.size(); ++k) {
    const scene::DrawRecord& d = draws[k];
    EXPECT_EQ(d.role, nbsim::ldi::kLdiPeelRole);
    EXPECT_EQ(d.clip_positions.size(), 3 * m.triangles.size()) << "pass " << k;
    EXPECT_EQ(d.state.func, scene::DepthFunc::Lequal);
    EXPECT_EQ(d.state.cull, scene::CullFace::None);
    EXPECT_EQ(d.state.clip, scene::ClipControl::ZeroToOne);
    EXPECT_EQ(d.discards, k > 0);
    EXPECT_EQ(d.gl.fragments, draws[0].gl.fragments) << "pass " << k << ": every pass rasterizes the same fragments";
    EXPECT_EQ(d.gl.samples_passed, b.peel.passes[k].samples_passed) << "pass " << k;
    EXPECT_EQ(d.gl.clip_prims_in, m.triangles.size()) << "pass " << k;
    for (const auto& p : d.clip_positions) ASSERT_EQ(p[3], 1.0f) << "w = 1: window depth is the clip z";
  }
  EXPECT_GT(draws[0].gl.samples_passed, 0u);
  EXPECT_EQ(draws.back().gl.samples_passed, 0u) << "the last pass ends the peel";
}

// A shape touching the cube's faces: the unit box seen along -z has its back face at exactly 1.0,
// a valid layer (not the +inf marker); crop, compression and both parity readers handle it, and a
// point exactly on the back face is inside (tie rule), outside just behind it.
TEST_F(LdiBuildTest, ShapeTouchingTheCubeFaces) {
  const mesh::TriMesh box = mesh::make_box();
  const LdiBuild b = build_ldi_along(box, mesh::OrthoFrame::look_along({0, 0, -1}), 32, 8);
  ASSERT_EQ(b.peel.ldi.layer_count(), 2);
  std::size_t far = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) far += b.peel.ldi.count(x, y) == 2 && b.peel.ldi.depth(x, y, 1) == 1.0f && b.peel.ldi.depth(x, y, 0) == 0.0f;
  EXPECT_EQ(far, 32u * 32u) << "every texel: front face at 0.0, back face at exactly 1.0";
  expect_compression_equal(b, "unit box");
  LdiTestPoints p;
  const float zs[] = {0.0f, 0.5f, 1.0f, std::nextafter(1.0f, 0.0f), std::nextafter(0.0f, 1.0f)};
  for (float z : zs)
    for (int x : {-1, 0, 31, 32}) {
      p.kind.push_back(static_cast<std::uint32_t>(trace::LdiPointKind::NearSurface));
      p.x.push_back(x), p.y.push_back(5), p.z.push_back(z);
    }
  expect_vpt_equal(b, p, "unit box");
  const GlVptAnswers gl = gl_vpt(b, {3}, {3}, {1.0f});
  EXPECT_EQ(gl.inside_layers[0], 1u) << "on the back face: inside (one layer in front)";
  EXPECT_EQ(gl.inside_ranges[0], 1u) << "s < z <= e with e = 1.0";
}

// Coplanar faces collapse into one layer: three layers (odd), a lone last range ending in +inf's
// bits, and GL equals the model.
TEST_F(LdiBuildTest, CoplanarFacesGiveOddLayers) {
  const LdiBuild b = build_ldi_along(stacked_boxes(), mesh::OrthoFrame::look_along({0, 0, -1}), 40, 8);
  ASSERT_EQ(b.peel.ldi.layer_count(), 3) << "front, shared plane, back";
  expect_compression_equal(b, "stacked boxes");
  std::size_t lone = 0;
  for (std::uint32_t t = b.compressed.index_texels; t < b.compressed.index_texels + b.compressed.range_texels; ++t)
    lone += b.compressed.texel(t)[1] == 0x7F800000u;
  EXPECT_EQ(lone, static_cast<std::size_t>(b.crop.rect.area())) << "one lone range (end +inf) per odd texel";
  expect_vpt_equal(b, make_test_points(b.peel.ldi, b.crop.rect, 2000, 3), "stacked boxes");
}

// The model's peel (model/ldi/peel.h) replays GL's recorded passes bit for bit: per pass the
// rasterized fragments and the samples passed equal GL's counters, and the model's layers equal
// GL's LDI in every bit; on curved shapes from oblique views and on the hard cases (the unit box
// touching the cube's faces, coplanar faces, a thin slab seen nearly edge-on).
void expect_model_peel_equal(const mesh::TriMesh& m, const mesh::OrthoFrame& frame, int size, const std::string& what) {
  DrawRecorder recorder;
  recorder.begin_frame(65);
  const LdiBuild b = build_ldi_along(m, frame, size, 64, &recorder);
  const std::vector<scene::DrawRecord> draws = recorder.collect();
  ASSERT_EQ(draws.size(), b.peel.passes.size()) << what;
  ldi::PeelReplay replay(size, size);
  replay.begin_frame();
  for (std::size_t k = 0; k < draws.size(); ++k) {
    const ldi::PeelPassCounts c = replay.pass(draws[k].clip_positions, ldi::draw_state(draws[k].state));
    EXPECT_EQ(c.fragments, draws[k].gl.fragments) << what << ", pass " << k;
    EXPECT_EQ(c.samples, draws[k].gl.samples_passed) << what << ", pass " << k;
  }
  EXPECT_EQ(replay.layer_count(), b.peel.ldi.layer_count()) << what;
  EXPECT_TRUE(ldi::bit_equal(replay.ldi(), b.peel.ldi)) << what << ": the model's layers are GL's, bit for bit";
}

TEST_F(LdiBuildTest, ModelPeelReplaysGlBitExact) {
  expect_model_peel_equal(placed("knot"), mesh::OrthoFrame::look_along({0.4, -0.7, -0.6}), 80, "knot");
  expect_model_peel_equal(placed("nested", 4), mesh::OrthoFrame::look_along({-0.1, 0.9, 0.3}), 72, "nested 4");
  expect_model_peel_equal(placed("coil", 5), grid_frame(3, 5, 8, 8), 64, "coil 5");
  expect_model_peel_equal(mesh::make_box(), mesh::OrthoFrame::look_along({0, 0, -1}), 32, "unit box (touching the faces)");
  expect_model_peel_equal(stacked_boxes(), mesh::OrthoFrame::look_along({0, 0, -1}), 40, "stacked boxes (coplanar faces)");
}

// Planes nearly parallel to the view direction: a slab 0.9 x 0.9 x 0.02 seen along a direction 0.5
// degrees off its large faces. Its silhouette is a band little more than a texel tall, and each
// large face spans the slab's whole depth across it, so the LDI samples the slab on one or two rows
// of texel centres only (under-sampling): GL covers exactly the texels whose centre line crosses
// the slab (the exact reference's; a difference would need an edge within 1/256 px of a centre),
// the model replays it bit for bit, and the parity test's misclassification against the exact
// reference on those lines is counted (recorded as a property) and stays small.
TEST_F(LdiBuildTest, NearlyParallelPlanesAreUnderSampled) {
  const mesh::TriMesh slab = mesh::make_box({0.05f, 0.05f, 0.49f}, {0.95f, 0.95f, 0.51f});
  const double tilt = 0.5 * 3.14159265358979323846 / 180.0;
  const mesh::OrthoFrame frame = mesh::OrthoFrame::look_along({std::cos(tilt), 0.0, std::sin(tilt)}, {0.0, 1.0, 0.0});
  expect_model_peel_equal(slab, frame, 64, "slab nearly edge-on");
  const LdiBuild b = build_ldi_along(slab, frame, 64, 8);
  EXPECT_EQ(b.peel.ldi.depth_complexity(), 2) << "in and out";
  const mesh::CrossingReference ref(slab, b.map.frame);
  int covered = 0, exact = 0, differ = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const std::size_t crossings = ref.crossing_depths(b.map.texel_line_point(x, y)).size();
      covered += b.peel.ldi.count(x, y) > 0;
      exact += crossings > 0;
      differ += static_cast<std::size_t>(b.peel.ldi.count(x, y)) != crossings;
    }
  ::testing::Test::RecordProperty("slab_covered_texels", std::to_string(covered));
  EXPECT_GT(covered, 0);
  EXPECT_LE(covered, 3 * 64) << "a band at most three texels tall";
  EXPECT_LE(differ, 2) << "GL covered " << covered << " texels, the exact lines " << exact;
  const LdiTestPoints p = make_test_points(b.peel.ldi, b.crop.rect, 4000, 11);
  expect_vpt_equal(b, p, "slab nearly edge-on");
  const std::vector<std::int32_t> reference = reference_crossings(ref, b.map, p, 1e-5);
  const GlVptAnswers gl = gl_vpt(b, p.x, p.y, p.z);
  std::size_t classified = 0, wrong = 0;
  for (std::size_t i = 0; i < reference.size(); ++i) {
    if (reference[i] < 0) continue;
    ++classified;
    wrong += gl.inside_layers[i] != (static_cast<std::uint32_t>(reference[i]) & 1u);
  }
  ::testing::Test::RecordProperty("slab_misclassified", std::to_string(wrong));
  ::testing::Test::RecordProperty("slab_classified", std::to_string(classified));
  EXPECT_GT(classified, 2000u);
  EXPECT_LT(wrong, classified / 20) << "misclassified " << wrong << " of " << classified;
}

// Test points: every kind is made; crop-boundary points lie on the border or one texel outside;
// near-surface points are within 3 ulps of a layer of their texel.
TEST_F(LdiBuildTest, TestPointsProbeWhatTheirKindSays) {
  const LdiBuild b = build_ldi(placed("coil", 2), {.size_texels = 64, .grid_h = 2, .grid_v = 2, .max_layers = 64});
  const LdiTestPoints p = make_test_points(b.peel.ldi, b.crop.rect, 400, 11);
  const Rect& r = b.crop.rect;
  std::size_t outside = 0;
  for (std::size_t i = 0; i < p.x.size(); ++i) {
    const auto kind = static_cast<trace::LdiPointKind>(p.kind[i]);
    EXPECT_EQ(p.kind[i], i % 4);
    if (kind == trace::LdiPointKind::CropBoundary) {
      const bool on_border = r.contains(p.x[i], p.y[i]) && (p.x[i] == r.x || p.x[i] == r.x1() - 1 || p.y[i] == r.y || p.y[i] == r.y1() - 1);
      const bool just_outside = !r.contains(p.x[i], p.y[i]) && p.x[i] >= r.x - 1 && p.x[i] <= r.x1() && p.y[i] >= r.y - 1 && p.y[i] <= r.y1();
      EXPECT_TRUE(on_border || just_outside) << "point " << i;
      outside += just_outside;
    }
    if (kind == trace::LdiPointKind::NearSurface) {
      bool near = false;
      for (int k = 0; k < b.peel.ldi.count(p.x[i], p.y[i]); ++k) {
        const float l = b.peel.ldi.depth(p.x[i], p.y[i], k);
        const auto d = static_cast<std::int64_t>(std::bit_cast<std::uint32_t>(l)) - std::bit_cast<std::uint32_t>(p.z[i]);
        near = near || (d >= -3 && d <= 3);
      }
      EXPECT_TRUE(near) << "point " << i;
    }
  }
  EXPECT_GT(outside, 10u) << "some crop-boundary points lie just outside the crop";
  expect_vpt_equal(b, p, "coil 2");
}

// The reference: a point exactly on a surface (or within epsilon) is -1, others count the
// crossings beyond them; GL misclassifies no clear point of the box.
TEST_F(LdiBuildTest, ReferenceCountsCrossingsAndSetsNearPointsApart) {
  const mesh::TriMesh box = mesh::make_box(0.25f, 0.75f);
  const mesh::OrthoFrame frame = mesh::OrthoFrame::look_along({0, 0, -1});
  const LdiBuild b = build_ldi_along(box, frame, 16, 8);
  const mesh::CrossingReference ref(box, frame);
  LdiTestPoints p;
  const float zs[] = {0.1f, 0.25f, 0.25f + 5e-6f, 0.25f + 2e-5f, 0.5f, 0.75f, 0.9f};
  for (float z : zs) p.kind.push_back(0), p.x.push_back(8), p.y.push_back(8), p.z.push_back(z);
  const std::vector<std::int32_t> got = reference_crossings(ref, b.map, p, 1e-5);
  const std::vector<std::int32_t> want = {2, -1, -1, 1, 1, -1, 0};
  EXPECT_EQ(got, want) << "crossings beyond: 2 in front of the box, -1 within 1e-5 of a face, 1 inside, 0 behind";
  const GlVptAnswers gl = gl_vpt(b, p.x, p.y, p.z);
  for (std::size_t i = 0; i < want.size(); ++i)
    if (want[i] >= 0) {
      EXPECT_EQ(gl.inside_layers[i], static_cast<std::uint32_t>(want[i] & 1)) << "point " << i;
    }
}

}  // namespace
}  // namespace nbsim::capture

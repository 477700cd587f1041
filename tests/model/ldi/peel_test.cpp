// The ldi program's plain core: the raster path's peel compare on hand-made triangles
// (RasterPeelTest), the model's peel against the exact crossing reference (PeelReplayTest), and one
// frame's comparison with GL's records, its counts and its refusals (LdiFrameTest). The frames are
// made by hand (hand_frame.h), so these tests run without GL; LdiPeelTest and LdiCliTest test
// captures on llvmpipe.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <string>

#include "model/common/error.h"
#include "model/ldi/peel.h"
#include "model/mesh/shapes.h"
#include "tests/model/ldi/hand_frame.h"

namespace nbsim::ldi {
namespace {

using testing::make_frame;

// A w x h quad over the whole viewport at depth z (two triangles, clip control zero-to-one).
std::vector<geometry::ClipPosition> quad(float z) {
  return {{-1, -1, z, 1}, {1, -1, z, 1}, {1, 1, z, 1}, {-1, -1, z, 1}, {1, 1, z, 1}, {-1, 1, z, 1}};
}

raster::DrawState lequal_state() {
  raster::DrawState s;
  s.geometry.clip = geometry::ClipControl::ZeroToOne;
  s.geometry.face.cull = geometry::CullFace::None;
  s.depth.func = raster::DepthFunc::Lequal;
  return s;
}

// A fragment must be strictly behind the peel layer; equal, nearer and +inf layers discard it, and
// a discarded fragment is counted, read, never depth tested nor passed nor written.
TEST(RasterPeelTest, DiscardsFragmentsNotStrictlyBehindTheLayer) {
  DepthImage depth(4, 4, 1.0f);
  raster::RasterPathConfig c;
  c.width_px = 4, c.height_px = 4;
  raster::RasterPath path(c, depth);
  DepthImage layer(4, 4, 0.25f);                                   // behind: kept (12 texels)
  layer.at(0, 0) = 0.5f;                                           // equal: discarded
  layer.at(1, 0) = std::nextafter(0.5f, 1.0f);                     // nearer than the layer: discarded
  layer.at(2, 0) = std::numeric_limits<float>::infinity();         // no previous layer: discarded
  layer.at(3, 0) = std::nextafter(0.5f, 0.0f);                     // one ulp in front: kept
  std::vector<std::uint8_t> mask(16, 0);
  raster::DrawState s = lequal_state();
  s.depth.peel_layer = &layer;
  s.depth.passed_mask = &mask;
  const raster::DrawCounters k = path.draw(quad(0.5f), s);
  EXPECT_EQ(k.depth.fragments, 16u) << "every rasterized fragment counts, discarded or not (GL's counter is before the discard)";
  EXPECT_EQ(k.depth.peel_reads, 16u) << "one previous-layer read a fragment";
  EXPECT_EQ(k.depth.peel_discarded, 3u);
  EXPECT_EQ(k.depth.depth_tests, 13u) << "a discarded fragment is not depth tested";
  EXPECT_EQ(k.depth.passed, 13u);
  for (int x = 0; x < 3; ++x) {
    EXPECT_EQ(depth.at(x, 0), 1.0f) << "discarded fragment wrote texel " << x;
    EXPECT_EQ(mask[static_cast<std::size_t>(x)], 0) << x;
  }
  EXPECT_EQ(depth.at(3, 0), 0.5f);
  EXPECT_EQ(mask[3], 1);
}

// Without a peel layer the compare is off: no reads, nothing discarded, the counts of a plain draw.
TEST(RasterPeelTest, NoLayerNoCompare) {
  DepthImage depth(4, 4, 1.0f), plain(4, 4, 1.0f);
  raster::RasterPathConfig c;
  c.width_px = 4, c.height_px = 4;
  raster::RasterPath path(c, depth), reference(c, plain);
  std::vector<std::uint8_t> mask(16, 0);
  raster::DrawState s = lequal_state();
  s.depth.passed_mask = &mask;
  const raster::DrawCounters k = path.draw(quad(0.75f), s);
  const raster::DrawCounters r = reference.draw(quad(0.75f), lequal_state());
  EXPECT_EQ(k.depth.peel_reads, 0u);
  EXPECT_EQ(k.depth.fragments, r.depth.fragments);
  EXPECT_EQ(k.depth.passed, r.depth.passed);
  EXPECT_EQ(k.depth.written, r.depth.written);
  EXPECT_EQ(depth.texels, plain.texels);
}

// A fragment at exactly 1.0 passes LEQUAL against the clear: the mask marks it although the buffer
// still reads 1.0 (the "shape touching the cube's far face" case).
TEST(RasterPeelTest, MaskMarksASampleAtTheClearValue) {
  DepthImage depth(4, 4, 1.0f);
  raster::RasterPathConfig c;
  c.width_px = 4, c.height_px = 4;
  raster::RasterPath path(c, depth);
  std::vector<std::uint8_t> mask(16, 0);
  raster::DrawState s = lequal_state();
  s.depth.passed_mask = &mask;
  const raster::DrawCounters k = path.draw(quad(1.0f), s);
  EXPECT_EQ(k.depth.passed, 16u);
  for (const std::uint8_t m : mask) EXPECT_EQ(m, 1);
}

// The model's LDI of a box against the exact reference: every texel's layer count equal, every
// depth within the float rounding of the interpolation (1e-6 in [0, 1]).
TEST(PeelReplayTest, BoxMatchesTheExactReference) {
  const mesh::TriMesh box = mesh::make_box(0.2f, 0.8f);
  const auto clip = testing::clip_positions(box);
  PeelReplay peel(16, 16);
  for (std::uint32_t pass = 0; pass < 4; ++pass) peel.pass(clip, draw_state(testing::peel_draw(clip, pass).state));
  EXPECT_EQ(peel.layer_count(), 2) << "a box seen along an axis has two layers";
  const Ldi l = peel.ldi();
  const mesh::CrossingReference ref(box, mesh::OrthoFrame{});
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      const std::vector<double> d = ref.crossing_depths(testing::texel_point(x, y, 16, 16, 0.5));
      ASSERT_EQ(static_cast<std::size_t>(l.count(x, y)), d.size()) << "texel " << x << "," << y;
      for (std::size_t k = 0; k < d.size(); ++k)
        EXPECT_NEAR(l.depth(x, y, static_cast<int>(k)), d[k] + 1.0, 1e-6) << "texel " << x << "," << y << " layer " << k;
    }
}

// Sampling and snapping tolerance (documented): on a sphere and on nested shells (d = 6), at most
// 3% of the covered texels may differ in layer count from the exact reference (silhouette texels,
// where the rasterizer's 8-bit subpixel snap decides), and the layers of the others are within
// 1e-5 of the reference's depths.
TEST(PeelReplayTest, CurvedShapesMatchTheReferenceWithinTolerance) {
  mesh::TriMesh sphere = mesh::make_uv_sphere();
  mesh::TriMesh nested = mesh::make_nested_shells({3, 15, 24});
  for (mesh::TriMesh* m : {&sphere, &nested}) {
    mesh::normalize_to_unit_cube(*m, 0.05);
    const auto clip = testing::clip_positions(*m);
    PeelReplay peel(32, 32);
    for (std::uint32_t pass = 0; pass < 10; ++pass) peel.pass(clip, draw_state(testing::peel_draw(clip, pass).state));
    const Ldi l = peel.ldi();
    const mesh::CrossingReference ref(*m, mesh::OrthoFrame{});
    int covered = 0, count_mismatches = 0, depth_mismatches = 0, deepest = 0;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        const std::vector<double> d = ref.crossing_depths(testing::texel_point(x, y, 32, 32, 0.5));
        covered += !d.empty() || l.count(x, y) > 0 ? 1 : 0;
        deepest = std::max(deepest, static_cast<int>(d.size()));
        if (static_cast<std::size_t>(l.count(x, y)) != d.size()) {
          ++count_mismatches;
          continue;
        }
        for (std::size_t k = 0; k < d.size(); ++k) depth_mismatches += std::fabs(l.depth(x, y, static_cast<int>(k)) - (d[k] + 1.0)) > 1e-5 ? 1 : 0;
      }
    RecordProperty(m == &sphere ? "sphere_count_mismatches" : "nested_count_mismatches", count_mismatches);
    RecordProperty(m == &sphere ? "sphere_covered" : "nested_covered", covered);
    EXPECT_GT(covered, 100);
    EXPECT_LE(count_mismatches, covered * 3 / 100) << "texels whose layer count differs from the reference";
    EXPECT_EQ(depth_mismatches, 0);
    EXPECT_EQ(l.depth_complexity(), deepest) << "the model's d is the reference's";
  }
}

// A box touching the cube's far face: its back face is at depth exactly 1.0, which passes LEQUAL
// against the clear and is a layer.
TEST(PeelReplayTest, BackFaceAtTheFarDepthIsALayer) {
  const mesh::TriMesh box = mesh::make_box(0.0f, 0.75f);  // z from 0 (depth 1.0) to 0.75 (depth 0.25)
  const auto clip = testing::clip_positions(box);
  PeelReplay peel(8, 8);
  for (std::uint32_t pass = 0; pass < 3; ++pass) peel.pass(clip, draw_state(testing::peel_draw(clip, pass).state));
  const Ldi l = peel.ldi();
  ASSERT_EQ(l.layer_count(), 2);
  EXPECT_EQ(l.count(2, 2), 2);
  EXPECT_EQ(l.depth(2, 2, 0), 0.25f);
  EXPECT_EQ(l.depth(2, 2, 1), 1.0f);
}

// A self-consistent hand-made frame (GL's stand-in is the model's own peel): every comparison
// counts zero, the reference agrees with the answers on a box, and the counts add up.
TEST(LdiFrameTest, ConsistentFrameHasNoMismatches) {
  const scene::Frame f = make_frame(mesh::make_box(0.2f, 0.8f), 16, 16);
  PeelReplay peel(16, 16);
  const LdiFrameCounts k = run_frame(f, peel);
  EXPECT_EQ(k.passes.size(), 3u);
  EXPECT_EQ(k.layers, 2);
  EXPECT_EQ(k.gl_layers, 2);
  EXPECT_EQ(k.peel_pass_mismatches, 0u);
  EXPECT_EQ(k.peel_fragments, k.gl_peel_fragments);
  EXPECT_GT(k.peel_fragments, 0u);
  EXPECT_EQ(k.layer_texel_mismatches, 0u);
  EXPECT_FALSE(k.crop_mismatch);
  EXPECT_EQ(k.compressed_mismatches, 0u);
  EXPECT_GT(k.test_points, 50u);
  EXPECT_EQ(k.parity_mismatches_layers + k.parity_mismatches_ranges + k.fetch_mismatches_layers + k.fetch_mismatches_ranges, 0u);
  EXPECT_EQ(k.fetches_layers, k.gl_fetches_layers);
  EXPECT_EQ(k.classified_points + k.near_surface_points, k.test_points);
  EXPECT_GT(k.near_surface_points, 0u) << "points on a layer are near a surface";
  EXPECT_GT(k.classified_points, 0u);
  EXPECT_EQ(k.misclassified_layers, 0u) << "a box has no silhouette texel at 16x16";
  EXPECT_EQ(k.misclassified_ranges, 0u);
  EXPECT_EQ(k.kind_points[2], k.kind_points[2]);
  // Fragments: every pass rasterizes the whole shape; the first pass's equal the reference's crossings.
  std::uint64_t crossings = 0;
  const mesh::CrossingReference ref(mesh::make_box(0.2f, 0.8f), mesh::OrthoFrame{});
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) crossings += ref.crossing_depths(testing::texel_point(x, y, 16, 16, 0.5)).size();
  EXPECT_EQ(k.passes[0].fragments, crossings);
  EXPECT_EQ(k.passes[1].peel_reads, k.passes[1].fragments);
  EXPECT_EQ(k.passes[0].peel_reads, 0u) << "pass 0 compares with nothing";
  EXPECT_EQ(k.passes[2].samples, 0u) << "the last pass ends the peel";
}

// The peel's counters against GL's: a pass whose GL fragments or samples differ is counted.
TEST(LdiFrameTest, CountsPeelPassMismatches) {
  scene::Frame f = make_frame(mesh::make_box(0.2f, 0.8f), 16, 16);
  f.draws[1].gl.fragments += 1;
  f.draws[2].gl.samples_passed += 5;
  PeelReplay peel(16, 16);
  const LdiFrameCounts k = run_frame(f, peel);
  EXPECT_EQ(k.peel_pass_mismatches, 2u);
  EXPECT_EQ(k.gl_peel_fragments, k.peel_fragments + 1);
  EXPECT_EQ(k.gl_peel_samples, k.peel_samples + 5);
}

// A GL layer one ulp off (its crop and texture recomputed, so the texture still decompresses to
// it): one texel mismatch, and the compressed textures differ in that range's value.
TEST(LdiFrameTest, CountsLayerAndCompressedMismatches) {
  const mesh::TriMesh box = mesh::make_box(0.2f, 0.8f);
  scene::Frame f = make_frame(box, 16, 16);
  std::vector<float> depths = std::get<std::vector<float>>(testing::field_of(f, kLdiImageRecordType, "layers").value);
  const std::size_t at = (1 * 16 + 8) * 16 + 8;  // layer 1 of texel (8, 8)
  depths[at] = std::nextafter(depths[at], 1.0f);
  const Ldi changed(16, 16, 2, depths);
  testing::record(f, kLdiImageRecordType) = testing::ldil_record(changed);
  PeelReplay peel(16, 16);
  const LdiFrameCounts k = run_frame(f, peel);
  EXPECT_EQ(k.layer_texel_mismatches, 1u);
  EXPECT_EQ(k.compressed_mismatches, 1u);
  EXPECT_FALSE(k.crop_mismatch);
}

// A GL crop that differs from the model's is counted (the texture recomputed for it: a GL LDI with
// one more texel covered).
TEST(LdiFrameTest, CountsCropMismatch) {
  scene::Frame f = make_frame(mesh::make_box(0.2f, 0.8f), 16, 16);
  std::vector<float> depths = std::get<std::vector<float>>(testing::field_of(f, kLdiImageRecordType, "layers").value);
  depths[0] = 0.5f;  // layer 0 of texel (0, 0): now covered, the crop grows to the corner
  testing::record(f, kLdiImageRecordType) = testing::ldil_record(Ldi(16, 16, 2, depths));
  PeelReplay peel(16, 16);
  const LdiFrameCounts k = run_frame(f, peel);
  EXPECT_TRUE(k.crop_mismatch);
  EXPECT_EQ(k.layer_texel_mismatches, 1u);
}

// A flipped GL answer or a changed fetch count is counted for its reader only.
TEST(LdiFrameTest, CountsParityAndFetchMismatchesPerReader) {
  scene::Frame f = make_frame(mesh::make_box(0.2f, 0.8f), 16, 16);
  auto& inside = std::get<std::vector<std::uint32_t>>(testing::field_of(f, kLdiTestsRecordType, "gl_inside_layers").value);
  inside[3] ^= 1u;
  auto& fetches = std::get<std::vector<std::uint32_t>>(testing::field_of(f, kLdiTestsRecordType, "gl_fetches_ranges").value);
  fetches[4] += 1;
  fetches[5] += 1;
  PeelReplay peel(16, 16);
  const LdiFrameCounts k = run_frame(f, peel);
  EXPECT_EQ(k.parity_mismatches_layers, 1u);
  EXPECT_EQ(k.parity_mismatches_ranges, 0u);
  EXPECT_EQ(k.fetch_mismatches_ranges, 2u);
  EXPECT_EQ(k.fetch_mismatches_layers, 0u);
  EXPECT_EQ(k.gl_fetches_ranges, k.fetches_ranges + 2);
}

// Misclassification is against the reference (odd = inside); a reference of -1 is counted apart;
// the kind breakdown follows the point's kind.
TEST(LdiFrameTest, CountsMisclassificationAgainstTheReference) {
  scene::Frame f = make_frame(mesh::make_box(0.2f, 0.8f), 16, 16);
  auto& reference = std::get<std::vector<std::int32_t>>(testing::field_of(f, kLdiTestsRecordType, "reference").value);
  const auto& kind = std::get<std::vector<std::uint32_t>>(testing::field_of(f, kLdiTestsRecordType, "kind").value);
  PeelReplay peel(16, 16);
  const LdiFrameCounts before = run_frame(f, peel);
  std::size_t p = 0;
  while (reference[p] < 0 || kind[p] != 3) ++p;  // a classified midway point
  reference[p] += 1;                              // the other parity
  std::size_t q = 0;
  while (reference[q] < 0 || q == p) ++q;
  reference[q] = -1;  // now near a surface
  const LdiFrameCounts k = run_frame(f, peel);
  EXPECT_EQ(k.misclassified_layers, 1u);
  EXPECT_EQ(k.misclassified_ranges, 1u);
  EXPECT_EQ(k.kind_misclassified_layers[3], 1u);
  EXPECT_EQ(k.near_surface_points, before.near_surface_points + 1);
  EXPECT_EQ(k.classified_points, before.classified_points - 1);
}

// A damaged LDIL or LDIT is an InputError naming the frame and the problem.
TEST(LdiFrameTest, RefusesDamagedRecords) {
  struct Row {
    const char* why;
    void (*damage)(scene::Frame&);
    const char* message;
  };
  const Row rows[] = {
      {"width that does not match the layers", [](scene::Frame& f) { testing::field_of(f, kLdiImageRecordType, "width").value = std::uint64_t{15}; },
       "layers"},
      {"zero width", [](scene::Frame& f) { testing::field_of(f, kLdiImageRecordType, "width").value = std::uint64_t{0}; }, "each side"},
      {"a NaN depth",
       [](scene::Frame& f) { std::get<std::vector<float>>(testing::field_of(f, kLdiImageRecordType, "layers").value)[300] = std::nanf(""); },
       "NaN"},
      {"a broken compressed texture (an index offset)",
       [](scene::Frame& f) { std::get<std::vector<std::uint32_t>>(testing::field_of(f, kLdiImageRecordType, "compressed").value)[0] += 1; },
       "compressed"},
      {"a compressed texture of the wrong size",
       [](scene::Frame& f) { std::get<std::vector<std::uint32_t>>(testing::field_of(f, kLdiImageRecordType, "compressed").value).pop_back(); },
       "compressed"},
      {"a crop outside the LDI", [](scene::Frame& f) { testing::field_of(f, kLdiImageRecordType, "crop_x").value = std::int64_t{15}; },
       "crop"},
      {"no LDIL", [](scene::Frame& f) { testing::record(f, kLdiImageRecordType).type = 0x58585858u; }, "no LdiImage"},
      {"a test vector of the wrong length",
       [](scene::Frame& f) { std::get<std::vector<std::int32_t>>(testing::field_of(f, kLdiTestsRecordType, "x").value).pop_back(); },
       "count is"},
      {"a NaN test depth",
       [](scene::Frame& f) { std::get<std::vector<float>>(testing::field_of(f, kLdiTestsRecordType, "z").value)[2] = std::nanf(""); }, "NaN"},
      {"a kind out of range",
       [](scene::Frame& f) { std::get<std::vector<std::uint32_t>>(testing::field_of(f, kLdiTestsRecordType, "kind").value)[1] = 4; }, "kind"},
      {"a missing field", [](scene::Frame& f) { testing::field_of(f, kLdiTestsRecordType, "reference").name = "referenc"; }, "reference"},
  };
  for (const Row& r : rows) {
    scene::Frame f = make_frame(mesh::make_box(0.2f, 0.8f), 16, 16, 7);
    r.damage(f);
    PeelReplay peel(16, 16);
    try {
      run_frame(f, peel);
      ADD_FAILURE() << r.why << ": accepted";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("frame 7"), std::string::npos) << r.why << ": " << m;
      EXPECT_NE(m.find(r.message), std::string::npos) << r.why << ": " << m;
    }
  }
}

// An LDI of another size than the peel's render target is refused, not drawn out of bounds.
TEST(LdiFrameTest, RefusesAnotherSizeThanThePeel) {
  const scene::Frame f = make_frame(mesh::make_box(0.2f, 0.8f), 16, 16);
  PeelReplay peel(8, 8);
  EXPECT_THROW(run_frame(f, peel), InputError);
}

}  // namespace
}  // namespace nbsim::ldi

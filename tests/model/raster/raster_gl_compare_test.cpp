// RasterGlCompareTest: the counter comparison of the raster path against GL. Each test captures a
// small fresh trace with the GL renderer on Mesa (llvmpipe) and replays it: per draw, rasterized
// fragments and passed samples must match GL's counters within the comparison's thresholds (99% of
// draws exact, totals within 0.01%), the clipper's input and output counts GL's, and 99.99% of the
// depth snapshot pixels lie within 1e-6 of GL's.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <string>

#include "tests/model/raster/trace_compare.h"
#include "traces/capture/capture.h"
#include "tests/common/scratch.h"

namespace nbsim::raster_compare {
namespace {

namespace fs = std::filesystem;

struct Capture {
  const char* name;
  const char* mode;  // occlusion_culling's --mode
  const char* path;  // camera path by name
  bool reversed_z;
};

CompareSummary capture_and_compare(const Capture& c) {
  const fs::path dir = nbsim::testing::scratch_dir("nbsim_raster");
  const fs::path file = dir / (std::string(c.name) + ".nbtrace");
  capture::CaptureOptions o;
  o.width = 160;
  o.height = 120;
  o.frames = 3;
  o.technique = "occlusion_culling";
  o.scene = "city";
  o.path = c.path;
  o.options = {{"objects", "700"}, {"seed", "5"}, {"mode", c.mode}};
  o.reversed_z = c.reversed_z;
  capture::capture(o, file.string());
  CompareSummary s = compare_trace(file);
  fs::remove_all(dir);
  return s;
}

void expect_matches_gl(const CompareSummary& s, const char* what) {
  ASSERT_GT(s.draws, 100u) << what << ": the capture must have draws with geometry";
  EXPECT_TRUE(s.within_thresholds()) << what << ": " << to_json(s);
  EXPECT_GE(static_cast<double>(s.draws_exact), 0.99 * static_cast<double>(s.draws)) << what << ": draws exact";
  EXPECT_NEAR(static_cast<double>(s.fragments_model), static_cast<double>(s.fragments_gl),
              1e-4 * static_cast<double>(s.fragments_gl))
      << what << ": total rasterized fragments";
  EXPECT_NEAR(static_cast<double>(s.passed_model), static_cast<double>(s.passed_gl),
              1e-4 * static_cast<double>(s.passed_gl))
      << what << ": total passed samples";
  EXPECT_EQ(s.clip_in_model, s.clip_in_gl) << what << ": clipper input primitives";
  EXPECT_EQ(s.clip_out_model, s.clip_out_gl) << what << ": clipper output primitives (llvmpipe setup's count)";
  EXPECT_GE(static_cast<double>(s.depth_pixels_matching), 0.9999 * static_cast<double>(s.depth_pixels))
      << what << ": depth snapshot pixels within 1e-6";
  EXPECT_EQ(s.fullscreen_exact, s.fullscreen_draws) << what << ": N-buffer build passes cover W x H";
  // Inexact draws are listed for whoever looks; the thresholds above decide.
  for (const DrawMismatch& m : s.mismatches)
    std::cerr << what << ": frame " << m.frame << " draw " << m.draw << " (role " << static_cast<int>(m.role)
              << "): fragments GL " << m.gl_fragments << " model " << m.model_fragments << ", passed GL " << m.gl_passed
              << " model " << m.model_passed << ", clip out GL " << m.gl_clip_out << " model " << m.model_clip_out
              << "\n";
  ::testing::Test::RecordProperty("draws", std::to_string(s.draws));
  ::testing::Test::RecordProperty("draws_exact", std::to_string(s.draws_exact));
  ::testing::Test::RecordProperty("depth_pixels_identical", std::to_string(s.depth_pixels_identical));
}

// Occlusion queries on a walk: occluders, bounding boxes with depth writes off, visible objects.
TEST(RasterGlCompareTest, WalkWithOcclusionQueriesMatchesGl) {
  expect_matches_gl(capture_and_compare({"oq_walk", "oq", "walk", false}),
                    "oq walk");
}

// The hierarchical N-buffer mode on a fly-over: more clipping (the camera is high, looking down).
TEST(RasterGlCompareTest, FlyWithNBufferHierarchyMatchesGl) {
  expect_matches_gl(capture_and_compare({"nbh_fly", "nb_hier", "fly", false}),
                    "nb_hier fly");
}

// Reversed Z: clip control ZERO_TO_ONE, GREATER, clear 0.
TEST(RasterGlCompareTest, ReversedZMatchesGl) {
  expect_matches_gl(capture_and_compare({"oq_rz", "oq", "walk", true}),
                    "oq reversed z");
}

}  // namespace
}  // namespace nbsim::raster_compare

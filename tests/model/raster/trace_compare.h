// Counter comparison of the raster path (model/raster/raster_path.h) against GL on a captured
// trace: per draw, rasterized fragments, passed samples and clipper output against GL's counters;
// per frame, the model's depth buffer against GL's snapshots. Shared by RasterGlCompareTest and
// the raster_trace_compare tool.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "model/raster/raster_path.h"
#include "traces/format/records.h"

namespace nbsim::raster_compare {

struct CompareOptions {
  int batch_triangles = 85;
  bool fused_viewport = true;
  bool fused_interpolation = true;
  double depth_tolerance = 1e-6;  // a depth pixel "matches" within this absolute difference
  int max_mismatches = 20;        // draws listed in CompareSummary::mismatches
};

struct DrawMismatch {
  std::uint32_t frame = 0, draw = 0;
  trace::DrawRole role = trace::DrawRole::Visible;
  std::int32_t object = -1;
  std::uint64_t triangles = 0;
  std::uint64_t gl_fragments = 0, model_fragments = 0;
  std::uint64_t gl_passed = 0, model_passed = 0;
  std::uint64_t gl_clip_out = 0, model_clip_out = 0;
};

struct CompareSummary {
  std::uint64_t frames = 0;
  std::uint64_t draws = 0;        // draws with geometry
  std::uint64_t draws_exact = 0;  // fragments and passed samples both equal to GL's
  std::uint64_t draws_fragments_exact = 0;
  std::uint64_t draws_passed_exact = 0;
  std::uint64_t draws_clip_exact = 0;  // clipper input and output equal to GL's
  std::uint64_t fullscreen_draws = 0;  // N-buffer build passes (W x H fragments each in GL)
  std::uint64_t fullscreen_exact = 0;  // ... whose GL fragment count is W x H
  std::uint64_t other_draws = 0;       // other records without geometry (shader-side queries)
  std::uint64_t fragments_model = 0, fragments_gl = 0;
  std::uint64_t passed_model = 0, passed_gl = 0;
  std::uint64_t clip_in_model = 0, clip_in_gl = 0, clip_out_model = 0, clip_out_gl = 0;
  std::uint64_t depth_snapshots = 0;
  std::uint64_t depth_pixels = 0;
  std::uint64_t depth_pixels_matching = 0;   // within depth_tolerance
  std::uint64_t depth_pixels_identical = 0;  // bit for bit
  std::uint64_t stencil_pixels = 0;           // pixels of the frames' "stencil" images
  std::uint64_t stencil_pixels_matching = 0;  // equal to the stencil buffer at the frame's end
  double depth_max_abs_error = 0.0;
  raster::DrawCounters totals;  // the model's counters summed over the draws with geometry
  double model_seconds = 0.0;   // host time spent in RasterPath::draw
  std::vector<DrawMismatch> mismatches;

  // The comparison's thresholds: at least 99% of draws exact, total fragment and passed-sample
  // error at most 0.01%, at least 99.99% of depth pixels within the tolerance.
  bool within_thresholds() const;
};

// Replays every frame of the trace (throws InputError for an unreadable trace).
CompareSummary compare_trace(const std::filesystem::path& trace, const CompareOptions& options = {});

// One JSON object with the summary's numbers (no mismatch list).
std::string to_json(const CompareSummary& s);

// The model's draw state for a trace record (model/raster/raster_path.h).
using raster::draw_state;

}  // namespace nbsim::raster_compare

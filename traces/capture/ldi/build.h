// The layered depth image built on GL (Trapp & Doellner), stage by stage, on the current GL
// context: viewpoint selection over a grid of directions, depth peeling (peel.h), cropping and
// depth-range compression, plus the volumetric parity test on GL with both readers. The `ldi`
// capture technique (ldi.h) and a Table 1 command use it; every result is GL's, read back, in the
// model's types (model/ldi/), so the model can be compared with it bit for bit.
//
// Viewpoint grid (s_H x s_V directions, index v * s_H + h): azimuth phi = 2 pi (h + 0.5) / s_H
// around the vertical (y) axis and an elevation band by equal area, y = -1 + 2 (v + 0.5) / s_V; the
// view direction is (sqrt(1 - y^2) cos phi, y, sqrt(1 - y^2) sin phi), its frame
// OrthoFrame::look_along(direction, +y) (never parallel: |y| < 1). The bands split the sphere of
// directions into s_H s_V cells of equal area with one direction at each centre, so the grid covers
// every direction (an orthographic view and its opposite see the same layers; both are in the grid).
// Each direction is measured by one GL pass at the LDI size counting fragments per texel
// (imageAtomicAdd into an R32UI image; no depth test, no culling) with the peel's vertex stage:
// d = the largest count, coverage = texels with a count > 0. The choice: smallest d, then largest
// coverage, then lowest index.
#pragma once

#include <cstdint>
#include <vector>

#include "model/ldi/compression.h"
#include "model/ldi/ldi.h"
#include "model/mesh/crossings.h"
#include "model/mesh/mesh.h"
#include "traces/capture/gl_program.h"
#include "traces/capture/ldi/peel.h"

namespace nbsim::capture {

class DrawRecorder;

struct LdiBuildConfig {
  int size_texels = 256;  // square LDI side, 1 to ldi::kMaxSideTexels
  int grid_h = 8;         // s_H >= 1
  int grid_v = 8;         // s_V >= 1
  int max_layers = 64;    // 1 to ldi::kMaxLayers; a deeper shape is refused (InputError naming it)
};

// Wall-clock milliseconds of each stage (std::chrono::steady_clock, each bounded by glFinish),
// read-backs of the stage's results included, and so is compiling and linking the stage's programs:
// the first build in a process pays llvmpipe's shader compilation (measured: the sphere at 96^2,
// 111 / 73 / 77 / 155 ms), later builds hit Mesa's in-process cache (the next shape: 23 / 17 / 1.8 /
// 2.6 ms). A timing table should run one build first and discard it.
struct LdiStageTimes {
  double viewpoint_ms = 0.0, peel_ms = 0.0, crop_ms = 0.0, compression_ms = 0.0;
};

struct LdiBuild {
  std::vector<std::uint32_t> candidate_d, candidate_coverage;  // per direction of the grid
  std::uint32_t direction = 0;                                  // the chosen one, v * grid_h + h
  OrthoMapping map;    // the chosen direction's view mapping (its frame included)
  PeelResult peel{ldi::Ldi(1, 1, 0, {}), {}};  // GL's LDI and the per-pass counters
  ldi::Crop crop;      // GL's crop (rect from the crop shader, d = the peel's layer count)
  ldi::CompressedLdi compressed;  // GL's compressed texture, read back
  LdiStageTimes times;
};

// The frame of direction (h, v) of an s_H x s_V grid (see above).
mesh::OrthoFrame grid_frame(int h, int v, int grid_h, int grid_v);

// Runs the four stages on the mesh (in the unit cube). With a recorder, the peel passes are recorded
// (peel.h). Throws InputError for a bad config or a shape deeper than max_layers,
// std::runtime_error for a GL failure.
LdiBuild build_ldi(const mesh::TriMesh& m, const LdiBuildConfig& config, DrawRecorder* recorder = nullptr);

// The last three stages along a given frame, without viewpoint selection (candidate vectors empty,
// direction 0, viewpoint_ms 0): for axis-aligned views (a shape touching the cube's faces) and tests.
LdiBuild build_ldi_along(const mesh::TriMesh& m, const mesh::OrthoFrame& frame, int size_texels, int max_layers,
                         DrawRecorder* recorder = nullptr);

// Fills two fresh GL texture names (GL_TEXTURE_2D_ARRAY, GL_TEXTURE_2D) with b's parity-test
// textures: the cropped layered R32F texture (GL's layers inside GL's crop, d deep) and the RG32UI
// compressed one, nearest filtering; a 1x1 stand-in each when the LDI has no layer.
void upload_vpt_textures(const LdiBuild& b, GLuint cropped, GLuint compressed);

// GL's volumetric parity test (shaders/ldi/vpt.comp) of points (x, y: texels of the LDI, possibly
// outside it; z: linear depth) with both readers: the cropped layered texture built from b's LDI and
// crop, and b's compressed texture, uploaded as GL produced them.
struct GlVptAnswers {
  std::vector<std::uint32_t> inside_layers, fetches_layers, inside_ranges, fetches_ranges;
  std::vector<std::uint32_t> inside_all, fetches_all;  // the paper's reader: every layer read
};
GlVptAnswers gl_vpt(const LdiBuild& b, const std::vector<std::int32_t>& x, const std::vector<std::int32_t>& y,
                    const std::vector<float>& z);

// GL's answers scored against the exact reference (test_points.h: crossings beyond each point, odd:
// inside; kLdiNearSurface: counted apart), and the fetches both readers made.
struct VptScore {
  std::uint64_t near_surface = 0;     // points with reference -1, not classified
  std::uint64_t wrong_layers = 0;     // classified points the uncompressed reader answers wrongly
  std::uint64_t wrong_ranges = 0;     // likewise, the compressed reader
  std::uint64_t readers_disagree = 0; // points where the readers' answers differ (0: compression is lossless)
  std::uint64_t fetches_layers = 0, fetches_ranges = 0;
};
VptScore score_vpt(const GlVptAnswers& gl, const std::vector<std::int32_t>& reference);

}  // namespace nbsim::capture

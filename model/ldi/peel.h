// The layered-depth-image program's plain core (no SystemC; model/ldi/unit.h wraps it with timing,
// memory and statistics): the depth peel replayed at the LDI's resolution through the model's own
// raster path and depth buffer, then the model's LDI compared with GL's (the LDIL record: layers,
// crop, compressed texture) and the volumetric parity test run on it at GL's test points (LDIT).
// Conventions are ldi.h's (linear depth in [0, 1], y up, +inf where a texel has no more layers).
//
// The peel as the capture runs it (traces/FORMAT.md "What an LDI trace holds"): one LdiPeel draw a
// pass, in pass order, the depth buffer cleared to 1.0 before each, depth func LEQUAL, cull none;
// pass k > 0 discards a fragment unless its depth is strictly greater than layer k - 1 at its texel
// (raster::DepthState::peel_layer: one extra read a fragment). Layer k is the depth buffer where a
// sample of pass k passed (a written mask, so a fragment at exactly 1.0 that passed LEQUAL against
// the clear is a layer) and +inf elsewhere; a pass that passes no sample ends the peel (its layer is
// not a layer).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "model/common/depth.h"
#include "model/ldi/compression.h"
#include "model/ldi/ldi.h"
#include "model/raster/raster_path.h"
#include "model/scene/frame.h"

namespace nbsim::ldi {

inline constexpr std::uint32_t kLdiImageRecordType = 0x4C49444Cu;  // fourcc "LDIL" (traces/format/ldi/ldi_chunk.h)
inline constexpr std::uint32_t kLdiTestsRecordType = 0x5449444Cu;  // fourcc "LDIT"
// LDIT's point kinds (traces/format/ldi/ldi_chunk.h LdiPointKind, fixed values) and their names.
inline constexpr std::size_t kPointKinds = 4;
inline constexpr std::array<const char*, kPointKinds> kPointKindNames = {"random", "crop_boundary", "near_surface", "midway"};
inline constexpr std::int32_t kNearSurfaceReference = -1;  // LDIT `reference` of a point within epsilon of a surface

// One peel pass's counts.
struct PeelPassCounts {
  std::uint64_t triangles = 0;       // triangles handed to setup (after clipping)
  std::uint64_t blocks = 0;          // 4x4 blocks with at least one fragment
  std::uint64_t fragments = 0;       // rasterized fragments (GL's fragment counter: before the discard)
  std::uint64_t peel_reads = 0;      // previous-layer reads (every fragment of a pass k > 0)
  std::uint64_t peel_discarded = 0;  // fragments not strictly behind the previous layer
  std::uint64_t depth_tests = 0;
  std::uint64_t samples = 0;         // kept and passed the depth test (GL_SAMPLES_PASSED)
  std::uint64_t layer_texels = 0;    // texels of the layer this pass wrote (a sample passed there)
};

// The model's peel of one frame: its own depth buffer and previous layer, separate from any other
// render target. Not copyable (the raster path points into its buffers).
class PeelReplay {
 public:
  // A width x height LDI (1 .. kMaxSideTexels; InputError otherwise).
  PeelReplay(int width, int height, bool fused_interpolation = true);
  PeelReplay(const PeelReplay&) = delete;
  PeelReplay& operator=(const PeelReplay&) = delete;

  int width() const noexcept { return width_; }
  int height() const noexcept { return height_; }
  // Forgets the frame's layers (the next pass is pass 0).
  void begin_frame();
  // The next pass: the draw's triangles (clip positions, three a triangle) under its recorded state,
  // with the peel compare against the previous layer from pass 1 on.
  PeelPassCounts pass(std::span<const geometry::ClipPosition> clip_positions, const raster::DrawState& state);
  int passes() const noexcept { return passes_; }
  // Layers found so far: the passes that passed a sample, before the first that passed none.
  int layer_count() const noexcept { return layer_count_; }
  // The layers as an LDI (validated: ldi.h's rules).
  Ldi ldi() const;

 private:
  int width_, height_;
  DepthImage depth_, previous_;
  std::vector<std::uint8_t> written_;
  std::vector<float> layers_;  // layer-major, layer_count_ layers
  raster::RasterPath path_;
  int passes_ = 0, layer_count_ = 0;
  bool ended_ = false;
};

// The raster state of a recorded draw (model/raster/raster_path.h).
using raster::draw_state;

// GL's LDI image of a frame (LDIL), checked: InputError naming the frame and the problem (a missing
// record or field, sizes that do not match, NaN or out-of-range depths, a crop outside the LDI).
struct GlLdiImage {
  int width = 0, height = 0, layer_count = 0;
  Ldi layers{1, 1, 0, {}};
  Rect crop;
  CompressedLdi compressed;  // as recorded (not checked here: decompress() checks it)
};
GlLdiImage read_ldi_image(const scene::Frame& f);
// Only LDIL's width and height, checked as read_ldi_image checks them (the peel's render target).
std::array<int, 2> read_ldi_size(const scene::Frame& f);

// GL's test points of a frame (LDIT), checked likewise (every vector `count` long, kinds below
// kPointKinds, answers 0 or 1, references >= -1, no NaN depth).
struct GlLdiTests {
  std::uint64_t count = 0;
  double epsilon = 0.0;
  std::vector<std::uint32_t> kind;
  std::vector<std::int32_t> x, y;
  std::vector<float> z;
  std::vector<std::uint32_t> gl_inside_layers, gl_fetches_layers, gl_inside_ranges, gl_fetches_ranges;
  std::vector<std::int32_t> reference;
  // The paper's reader (every layer read) at the same points, from the frame's LDIA record when it
  // has one (captures before the paper's reader have none: has_all false, the vectors empty).
  bool has_all = false;
  std::vector<std::uint32_t> gl_inside_all, gl_fetches_all;
};
GlLdiTests read_ldi_tests(const scene::Frame& f);

// One frame's comparison of the model with GL (all counts of this frame).
struct LdiFrameCounts {
  // The peel.
  std::vector<PeelPassCounts> passes;
  std::uint64_t peel_fragments = 0, gl_peel_fragments = 0, peel_samples = 0, gl_peel_samples = 0;
  std::uint64_t peel_pass_mismatches = 0;  // passes whose fragments or samples differ from GL's
  int layers = 0, gl_layers = 0;           // the model's layer count and LDIL's layer_count
  std::uint64_t layer_texel_mismatches = 0;  // (texel, layer) values whose bits differ, over the larger count
  // Crop and compression of the model's LDI against GL's.
  bool crop_mismatch = false;
  std::uint64_t compressed_mismatches = 0;  // values (two a texel) that differ, over the larger texture
  std::uint64_t m_crop = 0, m_comp = 0;     // the model's, in the paper's units (values)
  // The VPT on the model's LDI at GL's test points.
  std::uint64_t test_points = 0;
  std::uint64_t parity_mismatches_layers = 0, parity_mismatches_ranges = 0;
  std::uint64_t fetch_mismatches_layers = 0, fetch_mismatches_ranges = 0;
  std::uint64_t fetches_layers = 0, fetches_ranges = 0, gl_fetches_layers = 0, gl_fetches_ranges = 0;
  std::uint64_t misclassified_layers = 0, misclassified_ranges = 0, classified_points = 0, near_surface_points = 0;
  // The paper's reader (vpt_all_layers), at the points of a frame with LDIA (else all 0).
  std::uint64_t all_points = 0, parity_mismatches_all = 0, fetch_mismatches_all = 0, fetches_all = 0, gl_fetches_all = 0,
                misclassified_all = 0;
  std::array<std::uint64_t, kPointKinds> kind_points{}, kind_classified{}, kind_misclassified_layers{},
      kind_misclassified_ranges{};
};

// Runs the frame: every LdiPeel draw in order through `peel` (sized to LDIL's width x height by the
// caller), then the comparisons. InputError naming the frame for a damaged LDIL or LDIT, a peel draw
// that is not triangles, or GL's compressed texture not decompressing to GL's layers bit for bit.
LdiFrameCounts run_frame(const scene::Frame& f, PeelReplay& peel);

}  // namespace nbsim::ldi

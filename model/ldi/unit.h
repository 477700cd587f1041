// LdiUnit: the frame program of layered depth images and the volumetric parity test (Trapp &
// Doellner). Per frame (the plain core is peel.h):
//  1. the LDIL record gives the LDI's size; every LdiPeel draw is replayed in order at that size
//     through the unit's own raster path and depth buffer (a render target apart from the
//     observer's depth unit), with the peel's strict compare against the model's previous layer;
//     per pass the model's fragments and passed samples are compared with GL's counters, per frame
//     the model's layers with GL's (texel bits) and its layer count with LDIL's layer_count;
//  2. the model's LDI is cropped and compressed and compared with GL's crop and RG32UI texture, and
//     GL's texture must decompress to GL's layers (lossless; a damaged texture is an InputError);
//  3. the parity test at every LDIT point on the model's LDI, uncompressed (cropped layers) and
//     compressed, answers and fetch counts against GL's, misclassification against the exact
//     reference (points within epsilon of a surface counted apart), also per point kind.
// Timing: a pass is a pipeline of setup, the 4x4 block walk and the fragment tests (the peel read
// and the depth test share the test lanes); its slowest stage sets its cycles, plus a latency.
// The parity tests cost vpt_cycles_per_point a point plus a latency. Memory: the unit is the
// channel's client "ldi": the peel reads 4 bytes of the previous layer a fragment (pass k > 0) and
// writes 4 bytes a layer texel; the tests fetch 4 bytes a layer texel and 8 bytes an RG32UI texel.
// Plain bytes, no cache (the fetch addresses in VptResult are not used yet).
// Clipping and lens frames (an LdiClip record; clip.h): every draw replayed at the viewport's size
// through the unit's raster path with the volume test as the fragment stage's discard. A draw is a
// pipeline of setup, the block walk, the volume tests (clip_lanes lanes; the costs above) and the
// depth tests (tests_per_cycle); its slowest stage sets its cycles, plus a latency. The tests' fetches
// go through the LDI texel cache; a miss moves a line over the channel (client "ldi").
#pragma once

#include <array>
#include <memory>
#include <optional>

#include "model/config/schema.h"
#include "model/cp/unit.h"
#include "model/ldi/clip.h"
#include "model/ldi/peel.h"
#include "model/memory/memory.h"

namespace nbsim::ldi {

struct LdiUnitConfig {
  double setup_triangles_per_cycle = 1.0;  // peel triangles through setup a cycle; tunable
  double blocks_per_cycle = 1.0;           // 4x4 blocks from the rasterizer a cycle; tunable
  double tests_per_cycle = 16.0;           // fragment tests (peel reads + depth tests) a cycle, a 4x4 block's lanes; tunable
  int pass_latency_cycles = 50;            // fill and drain of a peel pass; tunable
  double vpt_cycles_per_point = 1.0;       // issue cost of one parity test (its fetches are memory's); tunable
  int vpt_latency_cycles = 20;             // per frame's batch of parity tests; tunable
  // The volume test of a clipping or lens draw (clip.h), in lane-cycles of the fragment stage, which
  // runs clip_lanes fragments at once: rebuilding the point and checking the crop, once a volume;
  // a layer fetch; a range fetch (its texel's coordinates: a division and a remainder). Not
  // calibrated against hardware; tunable.
  double clip_lanes = 16.0;
  double clip_volume_test_cycles = 8.0;
  double clip_layer_fetch_cycles = 1.0;
  double clip_range_fetch_cycles = 4.0;
  int clip_draw_latency_cycles = 50;       // fill and drain of one clipping draw; tunable
  int clip_cache_bytes = 16 * 1024;        // the LDI texel cache; 0: every fetch misses; tunable
  int clip_cache_line_bytes = 64;
  int clip_cache_ways = 4;

  // Declares "ldi.<field>".
  static void describe(config::Schema& s, LdiUnitConfig& c);
  // Throws InputError naming the key for a value out of its limits.
  void validate() const;
};

class LdiUnit : public sim::Unit, public cp::FrameProgram {
 public:
  // `memory`: the shared channel; the unit registers as its client "ldi". `fused_interpolation`:
  // the depth plane evaluated with FMA (depth.fused_interpolation).
  LdiUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const LdiUnitConfig& config, memory::Channel& memory,
          bool fused_interpolation);

  void run_frame(const std::shared_ptr<const scene::Frame>& f, cp::CommandProcessor& cp) override;

  // Cycles of one peel pass from its counts (the timing rule above).
  static std::uint64_t pass_cycles(const PeelPassCounts& p, const LdiUnitConfig& c);

 private:
  // Spends `cycles` of work while `bytes` move on the channel; returns the cycles it took.
  std::uint64_t timed(std::uint64_t cycles, std::uint64_t bytes);

  LdiUnitConfig config_;
  memory::Channel& memory_;
  int client_;
  bool fused_;
  std::optional<PeelReplay> peel_;  // re-made when the LDI's size changes; one frame's buffers at a time
  std::unique_ptr<ClipReplay> clip_;  // clipping and lens frames: the volumes stay from frame to frame

  void run_clip_frame(const scene::Frame& f);
  // Cycles of one clipping draw from its counts (the timing rule above).
  std::uint64_t clip_draw_cycles(const ClipDrawCounts& d, ClipReader reader) const;

  stats::Counter &frames_, &peel_passes_, &peel_triangles_, &peel_blocks_, &peel_fragments_, &gl_peel_fragments_, &peel_samples_,
      &gl_peel_samples_, &peel_reads_, &peel_discarded_, &peel_layer_texels_, &peel_pass_mismatches_, &layers_, &gl_layers_,
      &layer_count_mismatches_, &layer_texel_mismatches_, &crop_mismatch_, &compressed_mismatches_, &m_crop_, &m_comp_,
      &test_points_, &parity_mismatches_layers_, &parity_mismatches_ranges_, &fetch_mismatches_layers_, &fetch_mismatches_ranges_,
      &fetches_layers_, &fetches_ranges_, &gl_fetches_layers_, &gl_fetches_ranges_, &misclassified_layers_,
      &misclassified_ranges_, &all_points_, &parity_mismatches_all_, &fetch_mismatches_all_, &fetches_all_, &gl_fetches_all_,
      &misclassified_all_, &classified_points_, &near_surface_points_, &peel_cycles_, &vpt_cycles_, &peel_bytes_, &vpt_bytes_,
      &memory_stall_cycles_;
  stats::Counter &clip_frames_, &clip_draws_, &clip_fragments_, &gl_clip_fragments_, &clip_samples_, &gl_clip_samples_,
      &clip_discarded_, &gl_clip_discarded_, &clip_fetches_, &gl_clip_fetches_, &clip_depth_tests_, &clip_volume_tests_,
      &clip_draw_mismatches_, &clip_decision_mismatches_, &clip_depth_mismatches_, &clip_volumes_, &clip_volume_mismatches_,
      &clip_classified_, &clip_near_surface_, &clip_misclassified_, &clip_fetches_layers_, &clip_fetches_all_, &clip_fetches_ranges_,
      &clip_cache_hits_, &clip_cache_misses_, &clip_cycles_, &clip_bytes_;
  std::array<stats::Counter*, kPointKinds> kind_points_{}, kind_classified_{}, kind_misclassified_layers_{},
      kind_misclassified_ranges_{};
};

}  // namespace nbsim::ldi

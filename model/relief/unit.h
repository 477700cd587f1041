// ReliefUnit: the frame program of relief textures (Baboud & Decoret) with the N-buffer walk. Per
// frame the plain core (replay.h) rasterizes every relief_box draw, runs each fragment's walk with
// the draw's method, compares it with GL's and scores it against the exact reference. Timing of a
// draw: setup, the 4x4 block walk and the early depth tests as a pipeline (the slowest stage), in
// parallel with the ray-walk unit: `lanes` walkers, each fragment costing cycles_per_lookup a
// lookup, cycles_per_step a step and cycles_per_bisection a bisection; the draw takes the larger of
// the two (and never less than its longest ray's lookups), plus a latency. Memory: every lookup
// goes through the unit's heightfield texel cache (heights, radii and N-buffer levels, 4 bytes a
// texel, one address space; virtual border texels need no memory), whose misses are line reads of
// the channel's client "relief".
#pragma once

#include <array>
#include <memory>
#include <optional>

#include "model/config/schema.h"
#include "model/cp/unit.h"
#include "model/memory/memory.h"
#include "model/relief/replay.h"

namespace nbsim::relief {

struct ReliefUnitConfig {
  double setup_triangles_per_cycle = 1.0;  // box triangles through setup a cycle; tunable
  double blocks_per_cycle = 1.0;           // 4x4 blocks from the rasterizer a cycle; tunable
  double tests_per_cycle = 16.0;           // early depth tests a cycle; tunable
  int lanes = 16;                          // ray walkers working at once; tunable
  double cycles_per_lookup = 1.0;          // a walker's cycles a texel lookup (a cache hit); tunable
  double cycles_per_step = 1.0;            // a walker's cycles a step (the step's arithmetic); tunable
  double cycles_per_bisection = 1.0;       // a walker's cycles a bisection; tunable
  int draw_latency_cycles = 50;            // fill and drain of one box draw; tunable
  int cache_bytes = 16 * 1024;             // heightfield texel cache (0: every lookup misses); tunable
  int cache_line_bytes = 64;               // tunable
  int cache_ways = 4;                      // tunable
  double hit_tolerance_texels = kDefaultHitTolerance;  // score.h's tolerance; tunable
  bool score = true;  // score every walk against the exact reference (false: no hit errors, as GL's timed passes)

  // Declares "relief.<field>".
  static void describe(config::Schema& s, ReliefUnitConfig& c);
  // Throws InputError naming the key for a value out of its limits.
  void validate() const;
};

class ReliefUnit : public sim::Unit, public cp::FrameProgram {
 public:
  // `box_height`: the trace header's relief_box_height. `memory`: the shared channel; the unit
  // registers as its client "relief".
  ReliefUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const ReliefUnitConfig& config, memory::Channel& memory,
             int width, int height, double box_height, bool fused_interpolation, CoveringSpec covering = {},
             BoxDepth box_depth = BoxDepth::None);

  void run_frame(const std::shared_ptr<const scene::Frame>& f, cp::CommandProcessor& cp) override;

  // Cycles of one box draw from its counts (the timing rule above), memory aside.
  static std::uint64_t draw_cycles(const BoxDrawCounts& d, const ReliefUnitConfig& c);

 private:
  static void on_draw(void* self, const BoxDrawCounts& d);
  void account(const BoxDrawCounts& d);

  struct PerMethod {
    stats::Counter *draws, *rasterized, *fragments, *gl_fragments, *samples, *gl_samples, *pixel_mismatches, *walk_mismatches, *lookups,
        *gl_lookups, *steps, *bisections, *hits, *capped, *reference_hits, *wrong_hit, *wrong_miss, *far_hit, *errors,
        *distance_microtexels, *cycles, *cache_misses, *storage_bytes, *depth_written, *depth_mismatches, *scene_after_draws,
        *scene_after_samples, *scene_hidden, *levels_eager_texels, *levels_on_demand_texels, *levels_on_demand_mismatches;
  };

  ReliefUnitConfig config_;
  memory::Channel& memory_;
  int client_;
  double box_height_;
  ReliefReplay replay_;
  TexelCache cache_;
  stats::Counter &frames_, &scene_draws_, &scene_depth_tests_, &scene_mismatches_, &box_draws_, &unscored_draws_, &cache_hits_, &cache_misses_, &memory_bytes_, &memory_stall_cycles_, &cycles_,
      &radius_texels_, &radius_sum_, &radius_zero_;
  std::array<PerMethod, kMethods> per_method_{};
};

}  // namespace nbsim::relief

// AppsUnit: the frame program of the apps technique: a recorded program's frames replayed by the
// plain core (replay.h), each replayed draw charged as the raster path would run it: its captured
// triangles through setup at setup_triangles_per_cycle and its depth tests at tests_per_cycle (the
// slower of the two), plus draw_overhead_cycles; a flagged draw costs the overhead only. Counters:
// per reason the draws flagged, the replayed draws compared with GL's samples passed (matched or
// not), the ones after a stale change, and the final depth compared with GL's.
// In a cull mode (AppsCull) it is also the draw tester of its core (replay.h): over the mode's
// query structure (which spends its own time on this thread: updates, rebuilds, queries), or, for
// occlusion queries, the full-resolution test, each query a box of the rectangle's pixels at
// tests_per_cycle plus oq_latency_cycles the draw waits for its result. Its per-frame
// values are exact: a frame's counting starts once the frame's clear has reached the depth unit,
// that is once the frame before has left the pipeline (the unit listens to the depth unit).
#pragma once

#include <array>
#include <fstream>
#include <memory>

#include "model/apps/replay.h"
#include "model/config/schema.h"
#include "model/cp/unit.h"
#include "model/depth/unit.h"

namespace nbsim::apps {

struct AppsUnitConfig {
  double setup_triangles_per_cycle = 1.0;  // tunable
  double tests_per_cycle = 16.0;           // depth tests a cycle; tunable
  int draw_overhead_cycles = 8;            // a draw's state and launch; tunable
  int oq_latency_cycles = 200;             // an occlusion query's round trip, which its draw waits for; tunable

  // Declares "apps.<field>".
  static void describe(config::Schema& s, AppsUnitConfig& c);
  void validate() const;
};

// How the unit culls the draws (cull.mode and cull.granularity on an apps trace).
struct AppsCull {
  bool on = false;                        // false: every draw replayed (trace, none)
  query::Structure* structure = nullptr;  // null with on: occlusion queries at full resolution
  int width = 0, height = 0;              // the structure's (the trace's viewport)
  FarOp op = FarOp::Max;
  bool primitives = false;
  bool fused_interpolation = true;
};

class AppsUnit : public sim::Unit, public cp::FrameProgram, public depth::DepthListener, private DrawTester {
 public:
  // `log`: when set, one line a draw (app_draws.csv's columns, header written here).
  AppsUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const AppsUnitConfig& config, const AppsCull& cull = {},
           std::ostream* log = nullptr);

  void run_frame(const std::shared_ptr<const scene::Frame>& f, cp::CommandProcessor& cp) override;

  // The depth unit's frame clears (its thread): the frame before has ended there.
  void depth_cleared(float depth) override;
  void depth_written(const cp::Work&, const DepthImage&, const Rect&) override {}
  void draw_finished(const cp::Work&, const depth::DrawResult&) override {}

 private:
  // DrawTester (from the core, on this thread).
  void rebuild(const DepthImage& depth) override;
  void cleared(const DepthImage& depth, float value) override;
  void changed(const DepthImage& depth, const Rect& dirty) override;
  void prepare(const DepthImage& depth) override;
  void query(const DepthImage& depth, std::span<const Rect> rects, std::span<const float> nearest, std::vector<query::Answer>& answers) override;

  AppsCull cull_;
  std::uint64_t begun_ = 0, cleared_ = 0;
  sc_core::sc_event cleared_event_;
  AppsUnitConfig config_;
  std::ostream* log_;
  AppsReplay replay_;
  stats::Counter &frames_, &draws_, &replayed_, &compared_, &matched_, &mismatched_, &after_stale_, &depth_changes_, &clears_, &triangles_,
      &fragments_, &depth_tests_, &samples_, &gl_samples_, &gl_samples_compared_, &frames_depth_compared_, &depth_pixels_, &depth_mismatches_,
      &unhandled_frames_, &may_discard_replayed_, &may_discard_equal_, &cycles_;
  std::array<stats::Counter*, kReasons> flagged_{};
  stats::Counter &gl_hidden_, &tested_, &tested_hidden_, &culled_, &false_culls_, &query_depth_tests_, &queries_, &update_texels_,
      &clear_texels_, &primitive_tests_, &primitives_culled_, &primitive_lookups_;
  std::array<stats::Counter*, kUntested> untested_{};
};

}  // namespace nbsim::apps

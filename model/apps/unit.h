// AppsUnit: the frame program of the apps technique: a recorded program's frames replayed by the
// plain core (replay.h), each replayed draw charged as the raster path would run it: its captured
// triangles through setup at setup_triangles_per_cycle and its depth tests at tests_per_cycle (the
// slower of the two), plus draw_overhead_cycles; a flagged draw costs the overhead only. Counters:
// per reason the draws flagged, the replayed draws compared with GL's samples passed (matched or
// not), the ones after a stale change, and the final depth compared with GL's. Its per-frame
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

  // Declares "apps.<field>".
  static void describe(config::Schema& s, AppsUnitConfig& c);
  void validate() const;
};

class AppsUnit : public sim::Unit, public cp::FrameProgram, public depth::DepthListener {
 public:
  // `log`: when set, one line a draw (app_draws.csv's columns, header written here).
  AppsUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const AppsUnitConfig& config, std::ostream* log = nullptr);

  void run_frame(const std::shared_ptr<const scene::Frame>& f, cp::CommandProcessor& cp) override;

  // The depth unit's frame clears (its thread): the frame before has ended there.
  void depth_cleared(float depth) override;
  void depth_written(const cp::Work&, const DepthImage&, const Rect&) override {}
  void draw_finished(const cp::Work&, const depth::DrawResult&) override {}

 private:
  std::uint64_t begun_ = 0, cleared_ = 0;
  sc_core::sc_event cleared_event_;
  AppsUnitConfig config_;
  std::ostream* log_;
  AppsReplay replay_;
  stats::Counter &frames_, &draws_, &replayed_, &compared_, &matched_, &mismatched_, &after_stale_, &depth_changes_, &clears_, &triangles_,
      &fragments_, &depth_tests_, &samples_, &gl_samples_, &gl_samples_compared_, &frames_depth_compared_, &depth_pixels_, &depth_mismatches_,
      &unhandled_frames_, &may_discard_replayed_, &may_discard_equal_, &cycles_;
  std::array<stats::Counter*, kReasons> flagged_{};
};

}  // namespace nbsim::apps

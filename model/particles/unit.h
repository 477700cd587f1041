// ParticlesUnit: the frame program of the particles technique (N-buffer paper 3.2/4.3). Per frame
// it issues the recorded Scene draws (their depth writes feed its query structure), brings the
// structure up to date once they have left the depth unit (the partial build: N-buffer levels
// 0..top level, or the Hi-Z pyramid's), then does the vertex-stage test of every particle itself
// as the trace's particle_mode says (sprite.h: the capture shader's rectangle and rules), from the
// particle's window position, size and depth in the PRTC record:
//   none     no test;
//   center   one depth-buffer lookup at the centre pixel (the baseline that pops);
//   nb       the N-buffer structure (query::Structure, built only up to the top level): one
//            lookup for a power-of-two sprite, at most four otherwise; kept when too large;
//   hiz      a Hi-Z pyramid of levels 0..top level (model/hiz/pyramid.h), at most 2x2 texels.
// Then it issues the particle draws as its own decisions say. Where they equal GL's (every draw of
// a replay in the capture's mode and design) those are GL's recorded draws, in which GL's culled
// particles were moved outside the clip volume, so fragments and passed samples stay comparable
// with GL's draw by draw. A draw with a particle decided otherwise is issued as the program's own
// (cp::Work::own, GL's counters zero): the particles the model culls are left out (`dropped`), and
// the ones it keeps that GL culled are drawn at the record's window position (`redrawn`: GL's
// clip position for them is gone; the window position is the shader's, which may differ from the
// geometry stage's by a rounding step). The model's decisions are compared with GL's
// (decision_mismatches), and checked against the reference pass (popping) and against the depth
// buffer (false_culls, the exact sprite test).
// Its statistics are the result (per frame: differences at frame ends).
#pragma once

#include <memory>
#include <string>
#include <vector>
#include <optional>

#include "model/config/schema.h"
#include "model/cp/unit.h"
#include "model/depth/unit.h"
#include "model/hiz/hiz_config.h"
#include "model/particles/sprite.h"
#include "model/query/structure.h"

namespace nbsim::particles {

struct ParticlesUnitConfig {
  double tests_per_cycle = 1.0;  // particles through the vertex-stage test a cycle (window position, rectangle); tunable
  int latency_cycles = 20;       // per frame's batch of tests; tunable
  double center_lookups_per_cycle = 4.0;  // mode center: depth-buffer texels read a cycle; tunable
  // The vertex-stage test the model makes: "trace" (the capture's particle_mode) or a mode name,
  // to replay a capture as another mode would have run (a `none` capture holds every sprite's own
  // clip position, so any mode replays it exactly).
  std::string mode = "trace";

  // Declares "particles.<field>".
  static void describe(config::Schema& s, ParticlesUnitConfig& c);
};

// What the program needs to know about the trace.
struct ParticlesSetup {
  int width_px = 0, height_px = 0;
  FarOp op = FarOp::Max;
  scene::DepthFunc depth_func = scene::DepthFunc::Less;
  Mode mode = Mode::None;
  int top_level = -1;         // highest level the test uses (the capture's levels_built - 1); -1: none
  float margin = 1e-6f;       // the capture's cull_margin
};

class ParticlesUnit : public sim::Unit, public cp::FrameProgram, public depth::DepthListener {
 public:
  // `structure`: the N-buffer for mode nb (null otherwise), built only up to setup.top_level;
  // `hiz`: the Hi-Z unit's config for mode hiz (format and timing). Throws InputError for a setup
  // the program cannot run.
  ParticlesUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const ParticlesUnitConfig& config,
                const ParticlesSetup& setup, const DepthImage& depth_buffer, query::Structure* structure,
                const HiZUnitConfig* hiz);

  void run_frame(const std::shared_ptr<const scene::Frame>& f, cp::CommandProcessor& cp) override;

  void depth_cleared(float depth) override;
  void depth_written(const cp::Work& w, const DepthImage& depth, const Rect& dirty) override;
  void draw_finished(const cp::Work& w, const depth::DrawResult& r) override;

 private:
  void issue(cp::CommandProcessor& cp, std::shared_ptr<cp::Work> w);
  void wait_all();
  void decide(const FrameParticles& fp);
  // Issues the frame's particle draws as decisions_ say (see the class comment).
  void issue_particle_draw(const std::shared_ptr<const scene::Frame>& f, std::uint32_t draw, const FrameParticles& fp,
                           std::size_t first, cp::CommandProcessor& cp);

  ParticlesUnitConfig config_;
  ParticlesSetup setup_;
  const DepthImage& depth_buffer_;
  query::Structure* structure_;
  std::optional<HiZUnitConfig> hiz_;

  std::uint64_t issued_ = 0, completed_ = 0, frames_begun_ = 0, clears_ = 0, heard_cycle_ = 0;
  std::uint64_t pending_build_ = 0;
  sc_core::sc_event completed_event_;

  stats::Counter &frames_, &particles_, &tested_, &culled_, &kept_too_large_, &offscreen_, &lookups_, &build_texels_,
      &particle_draws_, &particle_fragments_, &particle_passed_, &scene_depth_tests_, &decision_mismatches_,
      &lookup_mismatches_, &gl_culled_, &gl_lookups_, &popping_, &false_culls_, &exactly_hidden_, &hidden_kept_, &visible_reference_,
      &dropped_, &redrawn_, &own_draws_;

  std::vector<Decision> decisions_;  // the frame's, by particle

  std::vector<Rect> rects_;
  std::vector<float> nearest_;
  std::vector<std::size_t> index_;
  std::vector<query::Answer> answers_;
};

}  // namespace nbsim::particles

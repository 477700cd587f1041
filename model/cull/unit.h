// CullUnit: the cull stage of the replay model in a culling mode (cull.mode other than "trace").
// It is the command processor's frame program: per frame it issues the recorded Occluder draws,
// tests every candidate object's bounds (flat or over the BVH) with the mode's query, then issues
// the recorded geometry of the objects found visible. Queries:
//   oq, oq_hier      bounding boxes drawn through geometry -> raster -> depth, writes off; the
//                    stage waits for each batch's passed samples (the occlusion query's stall);
//   nb, nb_hier      the N-buffer unit, fed the depth unit's dirty rectangles of the occluder
//                    draws; four lookups at most per test;
//   hiz_tile         a single-level tile Hi-Z, fed the same way;
//   hiz_pyramid      a Hi-Z pyramid rebuilt from the depth after the occluders
// (the last three are query structures, model/query/units.h, with their own timing).
// With cull.granularity=primitive (nb, nb_hier and the hiz modes) it also tests, as the raster
// unit's PrimitiveTester (model/raster/primitive_tester.h), every triangle of the objects it draws
// as visible candidates, between setup and the tile walk, against the same structure: see
// test_primitives().
// It listens to the depth unit (clears, dirty rectangles, draw results) and passes the changes of
// the occluder draws on to its query structure. What it did is in its statistics (the only result
// channel: per frame, they are final when the frame's FrameEnd leaves the depth unit, because the
// next frame's tests wait for that) and, when asked, in a log of every bounds test (culls.csv).
// The query structure (model/query/structure.h) is a separate unit that the top level builds for
// the mode and hands over.
#pragma once

#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "model/config/schema.h"
#include "model/cp/unit.h"
#include "model/cull/false_cull_check.h"
#include "model/cull/primitive.h"
#include "model/cull/report.h"
#include "model/depth/unit.h"
#include "model/query/structure.h"
#include "model/raster/primitive_tester.h"

namespace nbsim::cull {

struct CullUnitConfig {
  std::string mode = "trace";            // see CullMode; "trace" replays the recorded draws
  std::string granularity = "object";    // see Granularity; "primitive" needs a depth-query mode
  double bounds_tests_per_cycle = 1.0;   // bounds (8 corner transforms, rectangle) a cycle; tunable
  int bounds_latency_cycles = 20;        // per batch of bounds tests; tunable

  // Declares "cull.<field>".
  static void describe(config::Schema& s, CullUnitConfig& c);
  CullMode parsed_mode() const;  // throws InputError for an unknown mode
  // Throws InputError for an unknown granularity, and for "primitive" with a mode that has no
  // depth-query structure (trace, none, oq, oq_hier): refused rather than silently run as object.
  Granularity parsed_granularity() const;
  // The kind of query structure the mode tests bounds against, or nothing (trace, none, oq, oq_hier).
  std::optional<query::Kind> structure_kind() const;
};

// What the cull stage needs to know about the trace and the render target.
struct CullSetup {
  int width_px = 0, height_px = 0;
  FarOp op = FarOp::Max;
  double near_m = 0.0, nearest_margin = 0.0;
  bool zero_to_one = false;
  scene::DepthFunc depth_func = scene::DepthFunc::Less;
  const scene::SceneObjects* scene = nullptr;  // must outlive the unit; required
  bool fused_interpolation = true;  // the depth unit's (depth.fused_interpolation): per-primitive depth bounds
};

class CullUnit : public sim::Unit,
                 public cp::FrameProgram,
                 public depth::DepthListener,
                 public raster::PrimitiveTester {
 public:
  // `depth_buffer` is the depth unit's buffer (the structure is brought up to date from it once
  // the occluders are done). `structure` is the query structure of config.structure_kind() (null
  // when that is nothing); it must outlive the unit. Throws InputError for a trace the mode cannot
  // cull (no scene).
  CullUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const CullUnitConfig& config,
           const CullSetup& setup, const DepthImage& depth_buffer, query::Structure* structure);
  ~CullUnit() override;

  CullMode mode() const noexcept { return mode_; }
  Granularity granularity() const noexcept { return granularity_; }
  const query::Structure* structure() const noexcept { return structure_; }

  // cp::FrameProgram (from the command processor's thread).
  void run_frame(const std::shared_ptr<const scene::Frame>& f, cp::CommandProcessor& cp) override;

  // Writes kBoundsTestLogHeader, then one row per bounds test (report.h) to `log` (null: none).
  void set_test_log(std::ostream* log);
  // Depth tests spent on visibility queries so far (the statistic query_depth_tests).
  std::uint64_t query_depth_tests() const noexcept;

  // depth::DepthListener (from the depth unit's thread).
  void depth_cleared(float depth) override;
  void depth_written(const cp::Work& w, const DepthImage& depth, const Rect& dirty) override;
  void draw_finished(const cp::Work& w, const depth::DrawResult& r) override;

  // raster::PrimitiveTester (from the raster unit's thread), cull.granularity=primitive. Tested:
  // the Visible draws this stage issues (its drawn candidates) whose depth test can be proved to
  // fail (LESS/LEQUAL, or GREATER/GEQUAL under reversed Z). Not tested: the occluders, whose depth
  // is what the structure holds (a triangle would mostly be tested against its own object's and
  // earlier occluders' depth, for lookups and little gain, and the answer would depend on how far
  // the depth unit lags behind), and the occlusion-query boxes.
  bool tests_primitives(const cp::Work& w) const override;
  // One query per triangle (model/cull/primitive.h), as one batch per draw through the
  // structure's query_batch (one latency per batch). The structure then holds exactly the
  // occluders' depth: every earlier frame has left the pipeline, and the visible draws do not feed
  // it. Each culled triangle is also checked, off the clock, against the occluders' depth
  // (FalseCullCheck, primitive_false_culls).
  void test_primitives(const cp::Work& w, std::span<const raster::SetupPrimitive> prims, std::vector<char>& hidden) override;

 private:
  struct Outcome {
    std::uint64_t depth_tests = 0, passed = 0;
  };
  std::uint64_t issue(cp::CommandProcessor& cp, std::shared_ptr<cp::Work> w, bool wants_result);
  void wait_all();  // until every issued draw and frame clear has left the depth unit
  void prepare();  // the structure the queries read is current
  void test_boxes(cp::CommandProcessor& cp, const std::shared_ptr<const scene::Frame>& f, const scene::FrameView& v,
                  const std::vector<scene::TestItem>& items, std::vector<scene::BoundsTest>& tests,
                  std::vector<std::uint64_t>& cost);
  void test_lookups(const std::vector<scene::TestItem>& items, std::vector<scene::BoundsTest>& tests,
                    std::vector<std::uint64_t>& cost);

  CullUnitConfig config_;
  CullMode mode_;
  Granularity granularity_;
  CullSetup setup_;
  const DepthImage& depth_buffer_;
  query::Structure* structure_;

  std::uint64_t issued_ = 0, completed_ = 0;
  std::uint64_t frames_begun_ = 0, clears_ = 0;
  sc_core::sc_event completed_event_;
  std::uint64_t heard_cycle_ = 0;  // the depth unit's local time of the last result heard of (model/sim/unit.h)
  std::unordered_map<std::uint64_t, Outcome> results_;
  // Work heard from the depth unit since the last frame's queries started.
  std::uint64_t pending_update_texels_ = 0, pending_clear_texels_ = 0;

  std::ostream* test_log_ = nullptr;

  stats::Counter &frames_, &in_frustum_, &occluders_, &candidates_, &bounds_tests_, &node_tests_, &crossing_near_,
      &found_visible_, &culled_, &undrawable_, &frames_with_truth_, &candidates_not_visible_, &false_culls_,
      &box_depth_tests_, &lookups_, &max_lookups_, &update_texels_, &clear_texels_;
  stats::Counter &primitive_tests_, &primitives_culled_, &primitive_lookups_, &primitive_fragments_culled_,
      &primitive_false_culls_;

  // cull.granularity=primitive: the check of dropped triangles against this frame's occluders'
  // depth; scratch of test_primitives().
  FalseCullCheck check_;
  std::vector<std::size_t> prim_index_;
  std::vector<Rect> prim_rects_;
  std::vector<float> prim_nearest_;
  std::vector<query::Answer> prim_answers_;
};

}  // namespace nbsim::cull

// CullUnit: the cull stage of the replay model in a culling mode (cull.mode other than "trace").
// It is the command processor's frame program: per frame it issues the recorded Occluder draws,
// tests every candidate object's bounds (flat or over the BVH) with the mode's query unit, then
// issues the recorded geometry of the objects found visible. Query units:
//   oq, oq_hier      bounding boxes drawn through geometry -> raster -> depth, writes off; the
//                    stage waits for each batch's passed samples (the occlusion query's stall);
//   nb, nb_hier      the N-buffer unit (model/nbuffer/unit.h), fed by the depth unit's dirty
//                    rectangles of the occluder draws; four lookups at most per test;
//   hiz_tile         a single-level tile Hi-Z (model/hiz/tile_hiz.h), fed the same way;
//   hiz_pyramid      a Hi-Z pyramid (model/hiz/pyramid.h) rebuilt from the depth after the occluders.
// It listens to the depth unit (clears, dirty rectangles, draw results) and reports per frame a
// CullReport (model/cull/bounds.h) that rides on the frame's FrameEnd work item.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <unordered_map>

#include "model/config/schema.h"
#include "model/cp/unit.h"
#include "model/cull/bounds.h"
#include "model/depth/unit.h"
#include "model/hiz/hiz_config.h"
#include "model/nbuffer/unit.h"

namespace nbsim::cull {

struct CullUnitConfig {
  std::string mode = "trace";            // see CullMode; "trace" replays the recorded draws
  double bounds_tests_per_cycle = 1.0;   // bounds (8 corner transforms, rectangle) a cycle; tunable
  int bounds_latency_cycles = 20;        // per batch of bounds tests; tunable
  double hiz_lookups_per_cycle = 4.0;    // Hi-Z texels compared a cycle (as the N-buffer's 4); tunable
  int hiz_lookup_latency_cycles = 8;     // per Hi-Z query; tunable
  double hiz_build_texels_per_cycle = 16.0;  // Hi-Z texels recomputed a cycle; tunable
  int hiz_build_latency_cycles = 16;         // per Hi-Z update or rebuild; tunable

  // Declares "cull.<field>".
  static void describe(config::Schema& s, CullUnitConfig& c);
  CullMode parsed_mode() const;  // throws InputError for an unknown mode
};

// What the cull stage needs to know about the trace and the render target.
struct CullSetup {
  int width_px = 0, height_px = 0;
  FarOp op = FarOp::Max;
  double near_m = 0.0, nearest_margin = 0.0;
  bool zero_to_one = false;
  trace::DepthFunc depth_func = trace::DepthFunc::Less;
  const trace::SceneObjects* scene = nullptr;  // must outlive the unit; required
};

class CullUnit : public sim::Unit, public cp::FrameProgram, public depth::DepthListener {
 public:
  // `depth_buffer` is the depth unit's buffer (read to rebuild the Hi-Z pyramid once the occluders
  // are done). Throws InputError for a trace the mode cannot cull (no scene).
  CullUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const CullUnitConfig& config,
           const nbuffer::NBufferUnitConfig& nbuffer, const HiZUnitConfig& hiz, const CullSetup& setup,
           memory::Channel& memory, const DepthImage& depth_buffer);
  ~CullUnit() override;

  CullMode mode() const noexcept { return mode_; }
  const nbuffer::NBufferUnit* nbuffer_unit() const noexcept { return nb_.get(); }
  // Bytes the mode's query structure occupies in memory: the N-buffer levels, the tile Hi-Z or the
  // Hi-Z pyramid; 0 for the occlusion-query modes, which query the depth buffer itself.
  long long structure_bytes() const noexcept {
    if (nb_) return nb_->core().levels().storage_bytes();
    if (tile_) return tile_->storage_bytes();
    if (pyramid_) return pyramid_->storage_bytes();
    return 0;
  }

  // cp::FrameProgram (from the command processor's thread).
  std::shared_ptr<const CullReport> run_frame(const std::shared_ptr<const trace::Frame>& f, cp::CommandProcessor& cp) override;

  // depth::DepthListener (from the depth unit's thread).
  void depth_cleared(float depth) override;
  void depth_written(const cp::Work& w, const DepthImage& depth, const Rect& dirty) override;
  void draw_finished(const cp::Work& w, const depth::DrawResult& r) override;

 private:
  struct Outcome {
    std::uint64_t depth_tests = 0, passed = 0;
  };
  std::uint64_t issue(cp::CommandProcessor& cp, std::shared_ptr<cp::Work> w, bool wants_result);
  void wait_all();  // until every issued draw and frame clear has left the depth unit
  void prepare(CullReport& r);  // the structure the queries read is current
  void test_boxes(cp::CommandProcessor& cp, const std::shared_ptr<const trace::Frame>& f, const FrameView& v,
                  const std::vector<TestItem>& items, std::vector<trace::BoundsTest>& tests,
                  std::vector<std::uint64_t>& cost, CullReport& r);
  void test_lookups(const std::vector<TestItem>& items, std::vector<trace::BoundsTest>& tests,
                  std::vector<std::uint64_t>& cost, CullReport& r);

  CullUnitConfig config_;
  CullMode mode_;
  CullSetup setup_;
  HiZUnitConfig hiz_;
  const DepthImage& depth_buffer_;
  std::unique_ptr<nbuffer::NBufferUnit> nb_;
  std::optional<TileHiZ> tile_;
  std::optional<HiZPyramid> pyramid_;

  std::uint64_t issued_ = 0, completed_ = 0;
  std::uint64_t frames_begun_ = 0, clears_ = 0;
  sc_core::sc_event completed_event_;
  std::unordered_map<std::uint64_t, Outcome> results_;
  // Work heard from the depth unit since the last frame's queries started.
  std::uint64_t pending_update_texels_ = 0, pending_clear_texels_ = 0;

  stats::Counter &frames_, &candidates_, &bounds_tests_, &node_tests_, &lookups_, &box_depth_tests_, &update_texels_,
      &culled_, &undrawable_, &false_culls_;
};

}  // namespace nbsim::cull

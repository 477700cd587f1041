// ShadowsUnit: the frame program of shadow volumes with litmaps (N-buffer paper 3.3/4.4). Per frame:
//  1. the recorded Scene draws (the observer's depth and, with DEPTH24_STENCIL8, its stencil);
//  2. the litmaps: with config shadows.litmaps = trace, the `litmap_min` and `litmap_max` depth
//     images as GL computed them, the pass's reprojections counted as the litmap draws' rasterized
//     fragments (GL's counter: one reprojection a fragment, reading up to 3x3 texels) and the
//     receiver splat's points (role ReceiverSplat, one observer texel read each); with
//     shadows.litmaps = model, the model draws both litmaps itself (litmap.h: the trace's object
//     meshes, SHDM, from the light, each fragment reprojected into its own observer depth, and the
//     splat), at the trace's litmap size (then compared texel by texel with GL's) or at
//     shadows.litmap_size, after the observer's depth is done and timed at
//     shadows.litmap_fragments_per_cycle;
//  3. a min N-buffer over litmap_min and a max N-buffer over litmap_max (two instances of the
//     N-buffer unit, "litmap_min" and "litmap_max", each with its own config), built from those
//     images (every texel of every level, timed by each unit's update engine);
//  4. per caster of the SHDC record with a rectangle: a query of each unit over it (four lookups
//     each), the model's z_min/z_max compared with GL's, and the capture's cull rule recomputed
//     (caster.h) on the model's values and on GL's; the record's outside/crossing casters are
//     taken as recorded (the rectangle comes from the capture's double-precision light camera);
//  5. the recorded ShadowVolume draws (clip positions from transform feedback, depth clamp,
//     two-sided z-fail stencil) through the pipeline: the fill and the stencil tests; or, with
//     config shadows.volumes = infinite, culled or clamped, the model's own volumes of that mode,
//     built from the trace's caster meshes (SHDG) and the capture's light (SHDC) with the model's
//     N-buffer answers and the paper's clamp rule (volume.h), transformed as llvmpipe's vertex
//     shader does: a capture in one mode replays as any mode, bit-exact with a capture of that mode;
//  6. at the end, the model's stencil buffer gives the shadow mask (STNC light_region AND
//     stencil != 0), compared pixel by pixel with GL's `shadow_mask` and `shadow_mask_infinite`.
// Another litmap size needs the model's litmaps and its own volumes (GL's rectangles, decisions
// and volumes belong to the captured size).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "model/config/schema.h"
#include "model/cp/unit.h"
#include "model/depth/unit.h"
#include "model/query/units.h"
#include "model/raster/raster_path.h"
#include "model/raster/stencil_test.h"
#include "model/shadows/caster.h"
#include "model/shadows/litmap.h"
#include "model/shadows/volume.h"

namespace nbsim::shadows {

struct ShadowsUnitConfig {
  double tests_per_cycle = 1.0;  // casters through the rectangle/decision stage a cycle; tunable
  int latency_cycles = 20;       // per frame's batch of caster decisions; tunable
  // Which shadow volumes go down the pipeline: "trace" (GL's, as the capture drew them) or the
  // volumes of mode "infinite", "culled" or "clamped" that the model builds itself from the trace's
  // caster meshes (SHDG) with its own decisions and planes.
  std::string volumes = "trace";
  // Whose litmaps the N-buffers are built over: "trace" (GL's images) or "model" (drawn by the
  // model from the trace's meshes, litmap.h), of side litmap_size (0: the trace's).
  std::string litmaps = "trace";
  int litmap_size = 0;
  double litmap_fragments_per_cycle = 4.0;  // the model's litmap passes: fragments and points a cycle; tunable
  // With the model's own culled or clamped volumes, also draw its own infinite volumes at the same
  // planes off the clock as their reference (own_mask_diff, mask_errors). Off skips the check (the
  // replay bench: GL's time leaves out its reference pass too).
  bool own_reference = true;

  // Declares "shadows.<field>".
  static void describe(config::Schema& s, ShadowsUnitConfig& c);
};

// What the program needs to know about the trace (its header).
struct ShadowsSetup {
  int width_px = 0, height_px = 0;
  int litmap_size = 0;        // the N-buffers' side: config litmap_size, or the trace's
  int trace_litmap_size = 0;  // the header's litmap_size
  ReprojectSettings reproject;  // the header's near, far and reproject_tolerance
  Mode mode = Mode::Clamped;
  ClampMargin margin;
  bool edge_rule = true;  // the trace's clamp_rule is the paper's ("edge")
  // The replay's raster settings (viewport, depth format, fused arithmetic), for the reference pass
  // of the model's own volumes.
  raster::RasterPathConfig reference_path;
};

// Where the volumes' fill goes: the casters of one class ("bird") kept for one reason (KeptBy),
// summed over the run.
struct FillShare {
  std::uint64_t casters = 0;        // caster-frames
  std::uint64_t volumes = 0;        // volumes drawn
  std::uint64_t fill = 0;           // the model's fill of their volumes
  std::uint64_t gl_fill = 0;        // GL's
  std::uint64_t fill_infinite = 0;  // GL's fill of their infinite volumes (SHDC fill_infinite)
};
using FillBreakdown = std::map<std::pair<std::string, std::string>, FillShare>;  // (class, kept)

class ShadowsUnit : public sim::Unit, public cp::FrameProgram, public depth::DepthListener {
 public:
  // `min_nb` (op min, over litmap_min) and `max_nb` (op max, over litmap_max), litmap_size square.
  ShadowsUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const ShadowsUnitConfig& config,
              const ShadowsSetup& setup, const DepthImage& depth, const raster::StencilImage& stencil,
              query::NBufferStructure& min_nb, query::NBufferStructure& max_nb);

  void run_frame(const std::shared_ptr<const scene::Frame>& f, cp::CommandProcessor& cp) override;

  void depth_cleared(float depth) override;
  void depth_written(const cp::Work&, const DepthImage&, const Rect&) override {}
  void draw_finished(const cp::Work& w, const depth::DrawResult& r) override;

  // The side of the litmaps and N-buffers this replay uses (config litmap_size or the trace's).
  int litmap_size() const noexcept { return setup_.litmap_size; }
  // The run's fill per caster class and reason kept.
  const FillBreakdown& breakdown() const noexcept { return breakdown_; }

 private:
  void issue_role(const std::shared_ptr<const scene::Frame>& f, scene::DrawRole role, cp::CommandProcessor& cp);
  void wait_all();
  // Builds one N-buffer from the frame's depth image `name`; returns the texels recomputed.
  std::uint64_t build(query::NBufferStructure& nb, const DepthImage& image);
  // Draws the model's litmaps of the frame (config litmaps = model) and compares them with GL's.
  void draw_own_litmaps(const scene::Frame& f, const FrameCasters& c);
  // Copies the frame's GL litmaps (config litmaps = trace), checking their size.
  void take_gl_litmaps(const scene::Frame& f);
  // The litmap the frame's N-buffers are built over: the model's or GL's.
  const DepthImage& litmap(bool max) const noexcept { return own_litmaps_ ? (max ? own_.max : own_.min) : (max ? gl_max_ : gl_min_); }
  bool other_size() const noexcept { return setup_.litmap_size != setup_.trace_litmap_size; }
  void query_casters(const scene::Frame& f, const FrameCasters& c, const LightDepth& light);
  void compare_masks(const scene::Frame& f);
  // Builds and issues the model's own volumes of mode `mode` (config volumes).
  void issue_model_volumes(const std::shared_ptr<const scene::Frame>& f, const FrameCasters& c, Mode mode, cp::CommandProcessor& cp);

  ShadowsUnitConfig config_;
  ShadowsSetup setup_;
  const DepthImage& depth_;
  const raster::StencilImage& stencil_;
  // The model's own infinite volumes at the planes of its own mode's (clip positions), drawn off
  // the clock into a scratch stencil at the frame's end: the reference its mask must equal.
  std::vector<geometry::ClipPosition> reference_clip_;
  query::NBufferStructure& min_nb_;
  query::NBufferStructure& max_nb_;

  std::uint64_t issued_ = 0, completed_ = 0, frames_begun_ = 0, clears_ = 0, heard_cycle_ = 0;
  sc_core::sc_event completed_event_;

  stats::Counter &frames_, &casters_, &measured_, &culled_, &gl_culled_, &outside_, &crossing_near_, &kept_by_slab_,
      &decision_mismatches_, &zmin_mismatches_, &zmax_mismatches_, &not_conservative_, &unsafe_culls_, &culls_lost_,
      &lookups_, &lookup_mismatches_, &build_texels_, &litmap_draws_, &litmap_reprojections_, &receiver_splats_, &scene_depth_tests_,
      &volume_draws_, &fill_, &gl_fill_, &reference_fill_, &reference_frames_, &stencil_tests_, &mask_pixels_, &gl_mask_pixels_, &mask_diff_, &mask_diff_infinite_,
      &gl_mask_diff_, &model_volumes_, &rect_mismatches_, &stencil_checksum_, &own_mask_diff_, &litmap_texel_diff_,
      &litmap_fragment_diff_, &litmap_discarded_, &model_litmap_frames_, &mask_errors_;

  FillBreakdown breakdown_;
  std::vector<FillShare*> volume_share_;  // this frame's draw index -> its caster's share (null: none)
  std::map<const scene::DrawRecord*, FillShare*> own_share_;  // the model's own volume draws' shares
  std::vector<float> model_zmin_, model_zmax_;  // this frame's answers per caster (1 and 0: not measured)
  std::optional<Mode> own_mode_;                 // config volumes, when the model builds them
  std::optional<CasterMeshes> meshes_;     // the trace's SHDG, from its first frame
  std::optional<LitmapMeshes> litmap_meshes_;  // its SHDM
  bool own_litmaps_ = false;                // config litmaps = model
  LitmapImages own_;                         // this frame's model litmaps
  DepthImage gl_min_, gl_max_;               // this frame's GL litmaps (config litmaps = trace)
  std::vector<Rect> rects_;
  std::vector<float> nearest_;
  std::vector<std::size_t> index_;
  std::vector<nbuffer::QueryAnswer> min_answers_, max_answers_;
};

}  // namespace nbsim::shadows

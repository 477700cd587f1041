// The shadows technique's declared results; its row of pipeline/techniques/results.h.
#include "pipeline/techniques/results.h"

namespace nbsim::techniques {

// Shadow volumes with litmaps (Décoret 2005, 3.3/4.4): the fill of the shadow volumes and the
// cycles per frame, the two N-buffers' build and lookups, against the shadow-mask pixels that
// differ from the reference of the volumes drawn (mask_errors: must be 0). With GL's volume draws
// the model's N-buffers (litmap_min.*, litmap_max.*) recompute every caster's z_min/z_max and the
// cull rule; with the model's own litmaps and volumes (shadows.litmaps, shadows.volumes,
// shadows.litmap_size) the fill itself follows the design, so a sweep shows what a design costs
// and whether it stays conservative (unsafe_culls: casters the design culls that the rule on the
// full-resolution values keeps). No TableSpec:
// `nbsim shadows` prints the per-mode table (one capture each).
TechniqueResults shadows_results() {
  TechniqueResults t;
  t.technique = "shadows";
  t.description = "Stencil shadow volumes culled and clamped with min/max litmaps and two N-buffers";
  const auto shd = [](const char* key) { return std::string("/summary/shadows/") + key; };
  using K = MetricKind;
  // GL's masks are the reference of GL's volumes; the model's own volumes (shadows.volumes, another
  // litmap size or N-buffer design) are cut at their own planes, so a few boundary pixels of theirs
  // may rasterize unlike GL's masks: mask_errors compares each with its own reference.
  Metric mask_errors = metric("mask_errors", "pixels",
                              "shadow-mask pixels unlike the reference of the volumes drawn (GL's mode and infinite masks for GL's "
                              "volumes, the model's own infinite volumes at the same planes for its own), over every frame; 0",
                              K::Error, shd("mask_errors"));
  mask_errors.must_be_zero = true;
  Metric mask_diff = metric("mask_diff", "pixels",
                            "shadow-mask pixels (light_region and stencil != 0) where the model's mask differs from GL's captured "
                            "mask, over every frame (0 with GL's volumes; the model's own may be cut elsewhere)",
                            K::Error, shd("mask_diff"));
  Metric mask_diff_infinite = metric("mask_diff_infinite", "pixels",
                                     "shadow-mask pixels where the model's mask differs from GL's infinite reference, over every "
                                     "frame (0 with GL's volumes: culling and clamping change no pixel)",
                                     K::Error, shd("mask_diff_infinite"));
  Metric own_mask_diff = metric("own_mask_diff", "pixels",
                                "with shadows.volumes culled or clamped: shadow-mask pixels where the model's mask differs from its own "
                                "infinite volumes' cut at the same planes, over every frame; 0",
                                K::Error, shd("own_mask_diff"));
  own_mask_diff.must_be_zero = true;
  Metric unsafe = metric("unsafe_culls", "casters",
                         "casters the design's N-buffers cull that the cull rule on GL's full-resolution values keeps; 0 for a "
                         "conservative design",
                         K::Error, shd("unsafe_culls"));
  unsafe.must_be_zero = true;
  Metric culled_lost = derived_error("culled_lost_per_frame", "casters",
                                     "casters the reference's cull rule culls per frame minus the point's (culled less than both "
                                     "N-buffers at full resolution, float32, every level)",
                                     shd("culled_per_frame"), Derivation::ReferenceMinusPoint, "reference_culled_per_frame");
  Metric culled_lost_fraction = derived_error("culled_lost_fraction", "fraction",
                                              "casters culled less than the reference, as a fraction of the reference's culls "
                                              "(culled_lost_per_frame / reference_culled_per_frame)",
                                              shd("culled_per_frame"), Derivation::LossRelativeToReference,
                                              "reference_culled_per_frame");
  Metric nbuffer_memory = metric("nbuffer_memory_bytes", "bytes", "memory of both N-buffers' levels", K::Cost,
                                 shd("nbuffer_memory_bytes"));
  nbuffer_memory.section = Section::Memory;
  t.metrics = {
      metric("fill_per_frame", "fragments", "rasterized fragments of the shadow-volume draws (the fill), per frame", K::Cost,
             shd("fill_per_frame")),
      metric("cycles_per_frame", "cycles", "model cycles per frame", K::Cost, shd("cycles_per_frame")),
      metric("build_texels_per_frame", "texels", "texels of both N-buffers built from the litmaps, per frame", K::Cost,
             shd("build_texels_per_frame")),
      metric("lookups_per_frame", "texels", "N-buffer texels the casters' queries read (both units), per frame", K::Cost,
             shd("lookups_per_frame")),
      metric("stencil_tests_per_frame", "tests", "stencil tests of the shadow-volume draws, per frame", K::Cost,
             shd("stencil_tests_per_frame")),
      mask_errors,
      mask_diff,
      mask_diff_infinite,
      own_mask_diff,
      unsafe,
      metric("not_conservative", "casters", "casters whose z_min is above GL's or z_max below GL's, over every frame", K::Error,
             shd("not_conservative")),
      metric("culls_lost", "casters", "casters GL culled that the design's N-buffers keep, over every frame", K::Error,
             shd("culls_lost")),
      culled_lost,
      culled_lost_fraction,
      metric("culled_per_frame", "casters", "casters the cull rule culls on the design's z_min/z_max, per frame", K::Outcome,
             shd("culled_per_frame")),
      metric("gl_culled_per_frame", "casters", "casters GL culled, per frame", K::Outcome, shd("gl_culled_per_frame")),
      metric("decision_mismatches", "casters", "casters GL culled that the cull rule on GL's own values keeps, over every frame",
             K::Outcome, shd("decision_mismatches")),
      nbuffer_memory,
  };
  ReferenceSetting r;
  r.column = "shadows_reference";
  r.description = "both N-buffers at full resolution, float32, every level (what the capture's GLSL N-buffers are)";
  r.settings = {{"litmap_min.resolution_divisor", 1}, {"litmap_min.format", "f32"}, {"litmap_min.level_cap", -1},
                {"litmap_max.resolution_divisor", 1}, {"litmap_max.format", "f32"}, {"litmap_max.level_cap", -1}};
  t.reference = std::move(r);
  t.headline_cost = "cycles_per_frame";
  // A fraction (the report plots it in points of %): the mask errors are 0 at every design, so what
  // a design loses is culls (and, with the model's own volumes, fill); mask_errors stays the
  // correctness count.
  t.headline_error = "culled_lost_fraction";
  t.memory_cost = "nbuffer_memory_bytes";
  ReportLabels& l = t.report;
  l.error_axis = "casters culled less than the full-resolution f32 N-buffers (% of their culls)";
  l.error_text = "casters the cull rule culls less than on both N-buffers at full resolution, float32, every level, in % of "
                 "the reference's culls (culled_lost_fraction); mask pixels differing are counted apart and must be 0";
  l.error_column = "culls lost (%)";
  l.cost_axis = "cycles per frame";
  l.cost_column = "cycles/frame";
  l.cost_pareto = "pareto_cycles";
  l.cost_short = "cycles";
  l.memory_axis = "N-buffer memory (KiB)";
  l.memory_pareto = "pareto_memory";
  l.memory_short = "memory";
  l.quality_column = "casters culled per frame";
  l.must_be_zero = "mask pixels differing";
  l.alike = "culls alike";
  return t;
}

}  // namespace nbsim::techniques

// The particles technique's declared results; its row of pipeline/techniques/results.h.
#include "pipeline/techniques/results.h"

namespace nbsim::techniques {

// Particles (Décoret 2005, 3.2/4.3; popping in docs/architecture.md, "Definitions"): the depth
// tests of the vertex-stage queries, the sprites' rasterization and the partial build per frame,
// against the sprites culled less than the exact sprite test would. The test is the trace's
// particle_mode (none, center, nb, hiz: one capture each) unless particles.mode names another, so
// a sweep varies the query structure (nbuffer.*, hiz.*) and the mode (exactly on a none capture). Popping and false culls must be 0 for the conservative modes nb
// and hiz; center pops by design (the paper's rejected baseline), and its points are flagged as
// breaking that rule, which is what the comparison shows, not a defect of the run. No TableSpec:
// `nbsim particles` prints the per-mode table (one trace each, or one none capture with --set
// particles.mode).
TechniqueResults particles_results() {
  TechniqueResults t;
  t.technique = "particles";
  t.description = "Point-sprite particles culled in the vertex stage: none, centre lookup, N-buffer, Hi-Z";
  const auto prt = [](const char* key) { return std::string("/summary/particles/") + key; };
  using K = MetricKind;
  Metric popping = metric("popping", "particles",
                          "sprites culled while GL's reference pass shows a passing sample, over every frame; 0 for nb and hiz "
                          "(center pops by design)",
                          K::Error, prt("popping"));
  popping.must_be_zero = true;
  Metric false_culls = metric("false_culls", "particles",
                              "sprites culled while a pixel of GL's square passes the depth test (the exact sprite test), over "
                              "every frame; 0 for nb and hiz",
                              K::Error, prt("false_culls"));
  false_culls.must_be_zero = true;
  Metric nbuffer_memory = metric("nbuffer_memory_bytes", "bytes", "memory of the N-buffer levels (0 outside mode nb)", K::Cost,
                                 prt("nbuffer_memory_bytes"));
  nbuffer_memory.section = Section::Memory;
  Metric efficiency_lost = derived_error("efficiency_lost", "fraction",
                                         "reference culling_efficiency - the point's (lost to the N-buffer's resolution, format or "
                                         "level cap, or the Hi-Z format)",
                                         prt("culling_efficiency"), Derivation::ReferenceMinusPoint, "reference_culling_efficiency");
  Metric culled_lost = derived_error("culled_lost_per_frame", "particles",
                                     "sprites the reference culled per frame minus the point's (culled less than the exact point)",
                                     prt("culled_per_frame"), Derivation::ReferenceMinusPoint, "reference_culled_per_frame");
  t.metrics = {
      metric("query_depth_tests_per_frame", "depth tests",
             "the paper's count: texels the vertex-stage queries read (N-buffer, Hi-Z or the centre pixel), per frame", K::Cost,
             prt("query_depth_tests_per_frame")),
      metric("raster_depth_tests_per_frame", "depth tests", "rasterized fragments of GL's particle draws as recorded, per frame",
             K::Cost, prt("raster_depth_tests_per_frame")),
      metric("build_texels_per_frame", "texels", "N-buffer or Hi-Z texels written by the partial build and its updates, per frame",
             K::Cost, prt("build_texels_per_frame")),
      metric("total_depth_tests_per_frame", "depth tests",
             "query depth tests + raster depth tests + build texels, per frame (the scene's own depth tests apart)", K::Cost,
             prt("total_depth_tests_per_frame")),
      popping,
      false_culls,
      metric("culling_efficiency", "fraction",
             "sprites culled / sprites the exact sprite test culls (every pixel fails the depth test); 1 when none is hidden",
             K::Error, prt("culling_efficiency")),
      metric("culled_below_exact_fraction", "fraction",
             "sprites the exact sprite test culls that the point kept, as a fraction of them (1 - culling_efficiency)", K::Error,
             prt("culled_below_exact_fraction")),
      metric("culled_below_exact", "particles", "sprites the exact sprite test culls that the point kept, over every frame",
             K::Error, prt("culled_below_exact")),
      metric("culled_per_frame", "particles", "sprites the vertex-stage test culled, per frame", K::Outcome, prt("culled_per_frame")),
      metric("exactly_hidden", "particles", "on-screen sprites whose every pixel fails the depth test, over every frame", K::Outcome,
             prt("exactly_hidden")),
      metric("kept_too_large_per_frame", "particles", "on-screen sprites larger than the levels built, kept untested, per frame",
             K::Outcome, prt("kept_too_large_per_frame")),
      metric("decision_mismatches", "particles",
             "decisions that differ from GL's recorded ones (GL's draws are replayed: their raster depth tests are GL's), over every "
             "frame",
             K::Outcome, prt("decision_mismatches")),
      nbuffer_memory,
      efficiency_lost,
      culled_lost,
  };
  ReferenceSetting r;
  r.column = "particles_reference";
  r.description =
      "the trace's particle_mode on the full-resolution float32 N-buffer built up to the capture's top level (nbuffer.level_cap "
      "-1) and the Hi-Z keys at their defaults; for modes none and center it is the point itself";
  r.settings = {{"nbuffer.resolution_divisor", 1}, {"nbuffer.format", "f32"}, {"nbuffer.level_cap", -1}};
  r.reset_prefixes = {"hiz."};
  t.reference = std::move(r);

  t.headline_cost = "total_depth_tests_per_frame";
  t.headline_error = "culled_below_exact_fraction";
  t.fallback_error = "culling_efficiency";
  t.memory_cost = "nbuffer_memory_bytes";
  ReportLabels& l = t.report;
  l.error_axis = "hidden sprites kept vs the exact sprite test (% of them)";
  l.error_text = "sprites culled less than the exact sprite test would, in % of the sprites it culls (culled_below_exact_fraction)";
  l.error_column = "hidden kept (%)";
  l.fallback_axis = "hidden sprites not culled (%, = 1 - culling efficiency)";
  l.fallback_text = "hidden sprites left unculled, 1 - culling efficiency (no culled_below_exact_fraction column)";
  l.fallback_column = "not culled (%)";
  depth_test_and_nbuffer_labels(l);
  l.quality_column = "sprite culling efficiency";
  l.must_be_zero = "popped sprites";
  l.alike = "culls alike";
  return t;
}

}  // namespace nbsim::techniques

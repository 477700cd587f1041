// The results each technique declares; see results.h. One row per technique.
#include "pipeline/techniques/results.h"

#include <algorithm>

namespace nbsim::techniques {

namespace {

Metric metric(const char* name, const char* unit, const char* description, MetricKind kind, std::string source) {
  Metric m;
  m.name = name;
  m.unit = unit;
  m.description = description;
  m.kind = kind;
  m.source = std::move(source);
  return m;
}

// An Error derived from `source` in the point and in its reference point (the reference's value
// shown in `reference_column`).
Metric derived_error(const char* name, const char* unit, const char* description, std::string source, Derivation derivation,
                     const char* reference_column) {
  Metric m = metric(name, unit, description, MetricKind::Error, std::move(source));
  m.derivation = derivation;
  m.reference_column = reference_column;
  return m;
}

// The labels of a technique whose headline cost is total depth tests per frame and whose memory
// cost is the N-buffer's (occlusion culling, particles).
void depth_test_and_nbuffer_labels(ReportLabels& l) {
  l.cost_axis = "total depth tests per frame";
  l.cost_column = "total depth tests/frame";
  l.cost_pareto = "pareto_depth_tests";
  l.cost_short = "tests";
  l.memory_axis = "N-buffer memory (KiB)";
  l.memory_pareto = "pareto_memory";
  l.memory_short = "memory";
}

// Occlusion culling (Décoret 2005, 4.2; docs/architecture.md, "Definitions"): depth tests per
// frame against culling efficiency, with false culls as the correctness count (must be 0).
TechniqueResults occlusion_culling() {
  TechniqueResults t;
  t.technique = "occlusion_culling";
  t.description = "Object (or primitive) culling by depth queries: occlusion queries, N-buffer, Hi-Z";
  const auto cull = [](const char* key) { return std::string("/summary/cull/") + key; };
  using K = MetricKind;
  Metric false_culls = metric("false_culls", "objects",
                              "objects culled while visible in the ground truth (ID buffer); 0 for a conservative query", K::Error,
                              cull("false_culls"));
  false_culls.must_be_zero = true;
  Metric nbuffer_memory = metric("nbuffer_memory_bytes", "bytes", "memory of the N-buffer levels", K::Cost, cull("nbuffer_memory_bytes"));
  nbuffer_memory.section = Section::Memory;
  Metric structure_memory = metric("structure_memory_bytes", "bytes", "memory of the query structure (N-buffer levels or Hi-Z)",
                                   K::Cost, cull("structure_memory_bytes"));
  structure_memory.section = Section::Memory;
  Metric efficiency_lost = derived_error(
      "efficiency_lost", "fraction", "reference culling_efficiency - the point's (lost to resolution, format, level cap or mode)",
      cull("culling_efficiency"), Derivation::ReferenceMinusPoint, "reference_culling_efficiency");
  t.metrics = {
      metric("query_depth_tests_per_frame", "depth tests",
             "the paper's count: box fragments, or N-buffer/Hi-Z texels compared, per frame", K::Cost,
             cull("query_depth_tests_per_frame")),
      metric("update_texels_per_frame", "texels", "N-buffer/Hi-Z texels written to keep the levels up to date, per frame", K::Cost,
             cull("update_texels_per_frame")),
      metric("total_depth_tests_per_frame", "depth tests",
             "query depth tests + update texels + depth tests of the drawn objects, per frame", K::Cost,
             cull("total_depth_tests_per_frame")),
      false_culls,
      metric("culling_efficiency", "fraction", "objects culled / objects not visible", K::Error, cull("culling_efficiency")),
      metric("culled", "objects", "objects (or primitives) culled, over every frame", K::Outcome, cull("culled")),
      metric("candidates_not_visible", "objects", "candidates not visible in the ground truth, over every frame", K::Outcome,
             cull("candidates_not_visible")),
      metric("max_lookups_per_test", "lookups", "most texel lookups one bounds test made", K::Cost, cull("max_lookups_per_test")),
      nbuffer_memory,
      structure_memory,
      efficiency_lost,
  };
  ReferenceSetting r;
  r.column = "culling_reference";
  r.description =
      "nb_hier on the full-resolution float32 N-buffer with every level (Hi-Z keys at their defaults), for a point in "
      "any culling mode; the trace and none modes cull nothing and have no culling reference";
  r.settings = {{"cull.mode", "nb_hier"}, {"nbuffer.resolution_divisor", 1}, {"nbuffer.format", "f32"}, {"nbuffer.level_cap", -1}};
  r.reset_prefixes = {"hiz."};
  r.skip_key = "cull.mode";
  r.skip_values = {"trace", "none"};
  t.reference = std::move(r);

  // Table 2 of Décoret 2005: average depth comparisons per frame, city walkthrough at 512x512 with
  // back-face culling. The paper's numbers are fixed by the paper; the Hi-Z baselines have none.
  TableSpec tab;
  tab.command = "table2";
  tab.title = "Table 2: average depth comparisons per frame";
  tab.row_key = "cull.mode";
  tab.row_column = "mode";
  tab.paper_label_column = "paper";
  tab.paper_value_column = "paper_depth_tests_per_frame";
  tab.section = "/summary/cull";
  for (const char* k : {"query_depth_tests_per_frame", "update_texels_per_frame", "total_depth_tests_per_frame", "cycles_per_frame",
                        "false_culls", "culling_efficiency", "frames", "bounds_tests", "candidates", "culled", "candidates_not_visible",
                        "undrawable", "max_lookups_per_test", "granularity"})
    tab.columns.emplace_back(k, cull(k));
  tab.columns.emplace_back("host_seconds", "/summary/host_seconds");
  // Occlusion queries cannot test per primitive (a query per triangle would rasterize it): with
  // cull.granularity=primitive their rows run per object, so one setting runs every row.
  const std::vector<TableRow::Override> object_only = {{"cull.granularity", "primitive", "object"}};
  tab.rows = {
      {"oq_hier", "occlusion queries with hierarchy", 1'100'000.0, object_only},
      {"oq", "occlusion queries", 200'000.0, object_only},
      {"nb_hier", "N-buffer with hierarchy", 350.0, {}},
      {"nb", "N-buffer", 500.0, {}},
      {"hiz_tile", "tile Hi-Z (baseline, not in the paper)", std::nullopt, {}},
      {"hiz_pyramid", "Hi-Z pyramid (baseline, not in the paper)", std::nullopt, {}},
  };
  tab.printed = {
      {"mode", "mode", 12, CellFormat::Text},
      {"paper", "paper_depth_tests_per_frame", 12, CellFormat::Paper},
      {"query tests", "query_depth_tests_per_frame", 14, CellFormat::Fixed1},
      {"update texels", "update_texels_per_frame", 14, CellFormat::Fixed1},
      {"total tests", "total_depth_tests_per_frame", 14, CellFormat::Fixed1},
      {"cycles", "cycles_per_frame", 12, CellFormat::Fixed0},
      {"false", "false_culls", 6, CellFormat::Count},
      {"culling", "culling_efficiency", 8, CellFormat::Percent},
      {"undraw", "undrawable", 7, CellFormat::Count},
  };
  tab.ratio = TableSpec::Ratio{"occlusion queries / N-buffer query depth tests", "oq", "nb", "query_depth_tests_per_frame", "400x"};
  tab.notes = {{"nb_hier", "granularity", "primitive",
                "cull.granularity=primitive in nb_hier, nb, hiz_tile and hiz_pyramid; oq_hier and oq test objects only"}};
  tab.must_be_zero = "false_culls";
  tab.footer =
      "Modes: oq_hier, oq, nb_hier, nb (the paper's rows), hiz_tile, hiz_pyramid. Query depth tests are the\n"
      "paper's count (box fragments, or N-buffer/Hi-Z texels compared); the total adds the N-buffer/Hi-Z\n"
      "update texels and the depth tests of the drawn objects. Exit 1 when any mode has a false cull.";
  t.table = std::move(tab);

  t.headline_cost = "total_depth_tests_per_frame";
  t.headline_error = "efficiency_lost";
  t.fallback_error = "culling_efficiency";
  t.memory_cost = "nbuffer_memory_bytes";
  ReportLabels& l = t.report;
  l.error_axis = "culling efficiency lost vs full-res f32 N-buffer (points of %)";
  l.error_text = "culling efficiency lost against the full-resolution float32 N-buffer (efficiency_lost)";
  l.error_column = "efficiency lost (points)";
  l.fallback_axis = "hidden objects not culled (%, = 1 - culling efficiency)";
  l.fallback_text = "hidden objects left unculled, 1 - culling efficiency (no efficiency_lost column)";
  l.fallback_column = "not culled (%)";
  depth_test_and_nbuffer_labels(l);
  l.quality_column = "culling efficiency";
  l.must_be_zero = "false culls";
  l.alike = "culls alike";
  return t;
}

// Particles (Décoret 2005, 3.2/4.3; popping in docs/architecture.md, "Definitions"): the depth
// tests of the vertex-stage queries, the sprites' rasterization and the partial build per frame,
// against the sprites culled less than the exact sprite test would. The test is the trace's
// particle_mode (none, center, nb, hiz: one capture each) unless particles.mode names another, so
// a sweep varies the query structure (nbuffer.*, hiz.*) and the mode (exactly on a none capture). Popping and false culls must be 0 for the conservative modes nb
// and hiz; center pops by design (the paper's rejected baseline), and its points are flagged as
// breaking that rule, which is what the comparison shows, not a defect of the run. No TableSpec:
// `nbsim particles` prints the per-mode table (one trace each, or one none capture with --set
// particles.mode).
TechniqueResults particles() {
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

// Shadow volumes with litmaps (Décoret 2005, 3.3/4.4): the fill of the shadow volumes and the
// cycles per frame, the two N-buffers' build and lookups, against the shadow-mask pixels that
// differ from GL's (the mode's mask and the infinite reference's: both must be 0). GL's volume
// draws are replayed (the trace holds the mode's geometry); the model's N-buffers (litmap_min.*,
// litmap_max.*) recompute every caster's z_min/z_max and the cull rule, so a sweep over their
// resolution, format and level cap shows what a design costs and whether it stays conservative
// (unsafe_culls: casters the design culls that the rule on GL's values keeps). No TableSpec:
// `nbsim shadows` prints the per-mode table (one capture each).
TechniqueResults shadows() {
  TechniqueResults t;
  t.technique = "shadows";
  t.description = "Stencil shadow volumes culled and clamped with min/max litmaps and two N-buffers";
  const auto shd = [](const char* key) { return std::string("/summary/shadows/") + key; };
  using K = MetricKind;
  Metric mask_diff = metric("mask_diff", "pixels",
                            "shadow-mask pixels (light_region and stencil != 0) where the model's mask differs from GL's, over every "
                            "frame; 0",
                            K::Error, shd("mask_diff"));
  mask_diff.must_be_zero = true;
  Metric mask_diff_infinite = metric("mask_diff_infinite", "pixels",
                                     "shadow-mask pixels where the model's mask differs from GL's infinite reference, over every "
                                     "frame; 0 (culling and clamping change no pixel)",
                                     K::Error, shd("mask_diff_infinite"));
  mask_diff_infinite.must_be_zero = true;
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
      mask_diff,
      mask_diff_infinite,
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
  // A fraction (the report plots it in points of %): the mask counts are 0 at every design (the
  // volumes are GL's), so what a design loses is culls; mask_diff stays the correctness count.
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

}  // namespace

// Layered depth images (Trapp & Doellner): the model replays GL's peel passes, crops, compresses and
// runs both parity tests on its own LDI. Its keys (ldi.*) set timing only, so every point of a sweep
// answers alike: the errors are correctness counts against GL (the peel's counters, the layers, the
// parity answers; all 0) and the misclassification against the exact reference, which the LDI's
// side (a capture option: one trace per side) and not the model sets. No reference setting; no
// TableSpec: `nbsim ldi table1` prints Table 1 from GL captures of each shape and side.
TechniqueResults ldi() {
  TechniqueResults t;
  t.technique = "ldi";
  t.description = "Layered depth images: depth peeling, crop, depth-range compression and the volumetric parity test";
  const auto l = [](const char* key) { return std::string("/summary/ldi/") + key; };
  using K = MetricKind;
  const auto zero = [](Metric m) {
    m.must_be_zero = true;
    return m;
  };
  Metric memory = metric("ldi_memory_bytes", "bytes", "LDI memory traffic: the peel's layer reads and writes and the parity tests' fetches",
                         K::Cost, l("memory_bytes"));
  memory.section = Section::Memory;
  t.metrics = {
      metric("ldi_cycles", "cycles", "model cycles of the peel passes and the parity tests, every frame", K::Cost, l("cycles")),
      metric("peel_cycles", "cycles", "model cycles of the peel passes", K::Cost, l("peel_cycles")),
      metric("vpt_cycles", "cycles", "model cycles of the parity tests", K::Cost, l("vpt_cycles")),
      metric("fetches_layers", "texels", "texels the uncompressed parity test read, every test point", K::Cost, l("fetches_layers")),
      metric("fetches_ranges", "texels", "texels the compressed parity test read, every test point", K::Cost, l("fetches_ranges")),
      zero(metric("peel_pass_mismatches", "passes", "peel passes whose fragments or samples passed differ from GL's; 0", K::Error,
                  l("peel_pass_mismatches"))),
      zero(metric("layer_texel_mismatches", "texels", "layer texels whose bits differ from GL's LDI; 0", K::Error,
                  l("layer_texel_mismatches"))),
      zero(metric("parity_mismatches_layers", "points", "test points where the model's uncompressed answer differs from GL's; 0",
                  K::Error, l("parity_mismatches_layers"))),
      zero(metric("parity_mismatches_ranges", "points", "test points where the model's compressed answer differs from GL's; 0",
                  K::Error, l("parity_mismatches_ranges"))),
      metric("misclassification_rate", "fraction",
             "test points the uncompressed parity test misclassifies against the exact reference, of those not within epsilon of "
             "a surface",
             K::Error, l("misclassification_rate_layers")),
      metric("misclassified", "points", "test points misclassified (uncompressed reader)", K::Outcome, l("misclassified_layers")),
      metric("classified_points", "points", "test points not within epsilon of a surface", K::Outcome, l("classified_points")),
      memory,
  };
  t.headline_cost = "ldi_cycles";
  t.headline_error = "misclassification_rate";
  t.memory_cost = "ldi_memory_bytes";
  ReportLabels& r = t.report;
  r.error_axis = "test points misclassified against the exact reference (%)";
  r.error_text = "test points the parity test misclassifies against the exact reference (misclassification_rate); the model's "
                 "mismatches against GL are counted apart and must be 0";
  r.error_column = "misclassified (%)";
  r.cost_axis = "LDI cycles";
  r.cost_column = "LDI cycles";
  r.cost_pareto = "pareto_cycles";
  r.cost_short = "cycles";
  r.memory_axis = "LDI memory traffic (KiB)";
  r.memory_pareto = "pareto_memory";
  r.memory_short = "memory";
  r.quality_column = "points classified";
  r.must_be_zero = "mismatches against GL";
  r.alike = "answers alike";
  return t;
}

TechniqueResults relief() {
  TechniqueResults t;
  t.technique = "relief";
  t.description = "Relief textures: binary, exact, robust (two zero-radius variants) and N-buffer ray walks against the exact reference";
  const auto l = [](const std::string& key) { return std::string("/summary/relief/") + key; };
  using K = MetricKind;
  const auto zero = [](Metric m) {
    m.must_be_zero = true;
    return m;
  };
  Metric memory = metric("relief_memory_bytes", "bytes", "texel cache line reads of the ray-walk unit (client relief)", K::Cost,
                         l("memory_bytes"));
  memory.section = Section::Memory;
  t.metrics = {
      metric("relief_cycles", "cycles", "model cycles of every box draw, every method and frame", K::Cost, l("cycles")),
      metric("lookups_per_fragment", "lookups", "texel lookups a fragment, over every method's draws", K::Cost, l("lookups_per_fragment")),
      metric("cache_misses", "lookups", "lookups that missed the heightfield texel cache", K::Cost, l("cache_misses")),
      zero(metric("walk_mismatches", "fragments", "fragments whose hit, t, lookups, steps or bisections differ from GL's; 0", K::Error,
                  l("walk_mismatches"))),
      zero(metric("pixel_mismatches", "fragments", "pixels walked by the model or GL but not both; 0", K::Error, l("pixel_mismatches"))),
      metric("error_rate", "fraction", "fragments with a hit error against the exact reference, over every method's draws", K::Error,
             l("error_rate")),
      metric("errors", "fragments", "hit errors (wrong hit, wrong miss or a hit beyond the tolerance)", K::Outcome, l("errors")),
      memory,
  };
  for (const char* m : {"binary", "exact", "robust", "robust_clamp", "nbuffer"}) {
    Metric c = metric("cycles", "cycles", "", K::Cost, l(std::string("methods/") + m + "/cycles"));
    c.name = std::string("cycles_") + m;
    c.description = std::string("model cycles of the ") + m + " box draws";
    t.metrics.push_back(c);
  }
  t.headline_cost = "relief_cycles";
  t.headline_error = "error_rate";
  t.memory_cost = "relief_memory_bytes";
  ReportLabels& r = t.report;
  r.error_axis = "fragments with a hit error (%)";
  r.error_text = "fragments whose hit or miss differs from the exact reference beyond the tolerance (error_rate); the model's "
                 "mismatches against GL are counted apart and must be 0";
  r.error_column = "hit error (%)";
  r.cost_axis = "relief cycles";
  r.cost_column = "relief cycles";
  r.cost_pareto = "pareto_cycles";
  r.cost_short = "cycles";
  r.memory_axis = "texel cache traffic (KiB)";
  r.memory_pareto = "pareto_memory";
  r.memory_short = "memory";
  r.quality_column = "fragments walked";
  r.must_be_zero = "mismatches against GL";
  r.alike = "answers alike";
  return t;
}

const std::vector<TechniqueResults>& technique_results() {
  static const std::vector<TechniqueResults> table = {occlusion_culling(), particles(), shadows(), ldi(), relief()};
  return table;
}

const TechniqueResults* find_technique_results(std::string_view technique) {
  for (const auto& t : technique_results())
    if (t.technique == technique) return &t;
  return nullptr;
}

const Metric* find_metric(const TechniqueResults& t, std::string_view name) {
  const auto it = std::find_if(t.metrics.begin(), t.metrics.end(), [name](const Metric& m) { return m.name == name; });
  return it == t.metrics.end() ? nullptr : &*it;
}

std::string_view name_of(MetricKind k) {
  switch (k) {
    case MetricKind::Cost: return "cost";
    case MetricKind::Error: return "error";
    case MetricKind::Outcome: return "outcome";
  }
  return "?";
}

std::string_view name_of(Section s) { return s == Section::Work ? "work" : "memory"; }

std::string_view name_of(Derivation d) {
  switch (d) {
    case Derivation::None: return "none";
    case Derivation::ReferenceMinusPoint: return "reference_minus_point";
    case Derivation::PointMinusReference: return "point_minus_reference";
    case Derivation::RelativeToReference: return "relative_to_reference";
    case Derivation::LossRelativeToReference: return "loss_relative_to_reference";
  }
  return "?";
}

nlohmann::ordered_json to_json(const TechniqueResults& t) {
  nlohmann::ordered_json j;
  j["technique"] = t.technique;
  j["description"] = t.description;
  j["metrics"] = nlohmann::ordered_json::array();
  for (const Metric& m : t.metrics) {
    nlohmann::ordered_json e = {{"name", m.name},     {"unit", m.unit},    {"description", m.description},
                                {"kind", name_of(m.kind)}, {"source", m.source}, {"section", name_of(m.section)},
                                {"derivation", name_of(m.derivation)}};
    if (!m.reference_column.empty()) e["reference_column"] = m.reference_column;
    e["must_be_zero"] = m.must_be_zero;
    j["metrics"].push_back(std::move(e));
  }
  if (t.reference) {
    j["reference"] = {{"column", t.reference->column},
                      {"description", t.reference->description},
                      {"settings", t.reference->settings},
                      {"reset_prefixes", t.reference->reset_prefixes},
                      {"skip_key", t.reference->skip_key},
                      {"skip_values", t.reference->skip_values}};
  } else {
    j["reference"] = nullptr;
  }
  j["table"] = t.table ? nlohmann::ordered_json(t.table->command) : nlohmann::ordered_json(nullptr);
  j["headline_cost"] = t.headline_cost;
  j["headline_error"] = t.headline_error;
  j["fallback_error"] = t.fallback_error;
  j["memory_cost"] = t.memory_cost;
  const ReportLabels& l = t.report;
  j["report"] = {{"error_axis", l.error_axis},         {"error_text", l.error_text},       {"error_column", l.error_column},
                 {"fallback_axis", l.fallback_axis},   {"fallback_text", l.fallback_text}, {"fallback_column", l.fallback_column},
                 {"cost_axis", l.cost_axis},           {"cost_column", l.cost_column},     {"cost_pareto", l.cost_pareto},
                 {"cost_short", l.cost_short},         {"memory_axis", l.memory_axis},     {"memory_pareto", l.memory_pareto},
                 {"memory_short", l.memory_short},     {"quality_column", l.quality_column}, {"must_be_zero", l.must_be_zero},
                 {"alike", l.alike}};
  return j;
}

const nlohmann::json* at_pointer(const nlohmann::json& j, const std::string& pointer) {
  try {
    const nlohmann::json::json_pointer p(pointer);
    if (!j.contains(p)) return nullptr;
    return &j.at(p);
  } catch (const nlohmann::json::exception&) {
    return nullptr;  // malformed pointer, or an array index that is not a number
  }
}

}  // namespace nbsim::techniques

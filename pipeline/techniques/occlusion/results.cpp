// The occlusion_culling technique's declared results; its row of pipeline/techniques/results.h.
#include "pipeline/techniques/results.h"

namespace nbsim::techniques {

// Occlusion culling (Décoret 2005, 4.2; docs/architecture.md, "Definitions"): depth tests per
// frame against culling efficiency, with false culls as the correctness count (must be 0).
TechniqueResults occlusion_results() {
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

}  // namespace nbsim::techniques

// The apps technique's declared results; its row of pipeline/techniques/results.h.
#include "pipeline/techniques/results.h"

namespace nbsim::techniques {

// A recorded program replayed draw by draw: its keys (apps.*) set timing only; the errors are
// correctness counts against GL (0 on every draw the model replays), the flagged share says how
// much of the program the model does not redo. Its table (`nbsim table2 APPS_TRACE`) culls the
// program's draw calls in every flat cull mode: Table 2's columns on a real program, with no
// paper number (the paper measured its own walkthrough).
TechniqueResults apps_results() {
  TechniqueResults t;
  t.technique = "apps";
  t.description = "A real program's draw calls recorded through apitrace, replayed and compared with GL draw by draw";
  const auto a = [](const char* key) { return std::string("/summary/apps/") + key; };
  using K = MetricKind;
  const auto zero = [](Metric m) {
    m.must_be_zero = true;
    return m;
  };
  t.metrics = {
      metric("apps_cycles", "cycles", "model cycles of every draw", K::Cost, a("cycles")),
      metric("apps_depth_tests", "tests", "the model's depth tests of the replayed draws", K::Cost, a("depth_tests")),
      zero(metric("apps_mismatched", "draws", "compared draws whose samples passed differ from GL's; 0", K::Error, a("mismatched"))),
      zero(metric("apps_mismatch_rate", "fraction", "of the compared draws, the share whose samples passed differ from GL's; 0", K::Error,
                  a("mismatch_rate"))),
      zero(metric("apps_depth_mismatches", "pixels", "final-depth pixels that differ from GL's; 0", K::Error, a("depth_mismatches"))),
      metric("apps_flagged_share", "fraction", "draws the model does not replay (flagged by reason)", K::Outcome, a("flagged_share")),
      metric("apps_compared", "draws", "draws compared with GL's samples passed", K::Outcome, a("compared")),
  };
  const auto c = [](const char* key) { return std::string("/summary/apps/cull/") + key; };
  TableSpec tab;
  tab.command = "table2";
  tab.title = "Culling a recorded program's draw calls: average depth comparisons per frame";
  tab.row_key = "cull.mode";
  tab.row_column = "mode";
  tab.paper_label_column = "paper";
  tab.paper_value_column = "paper_depth_tests_per_frame";
  tab.section = "/summary/apps/cull";
  for (const char* k : {"query_depth_tests_per_frame", "update_texels_per_frame", "drawn_depth_tests_per_frame", "total_depth_tests_per_frame",
                        "cycles_per_frame", "false_culls", "culling_efficiency", "frames", "draws_per_frame", "culled_per_frame", "tested",
                        "tested_hidden", "culled", "gl_hidden", "granularity"})
    tab.columns.emplace_back(k, c(k));
  tab.columns.emplace_back("mismatched", a("mismatched"));
  tab.columns.emplace_back("depth_mismatches", a("depth_mismatches"));
  tab.columns.emplace_back("host_seconds", "/summary/host_seconds");
  const std::vector<TableRow::Override> object_only = {{"cull.granularity", "primitive", "object"}};
  tab.rows = {
      {"none", "the program's own draws (no culling)", std::nullopt, object_only},
      {"oq", "an occlusion query per draw call", std::nullopt, object_only},
      {"nb", "N-buffer", std::nullopt, {}},
      {"hiz_tile", "tile Hi-Z", std::nullopt, {}},
      {"hiz_pyramid", "Hi-Z pyramid", std::nullopt, {}},
  };
  tab.printed = {
      {"mode", "mode", 12, CellFormat::Text},
      {"query tests", "query_depth_tests_per_frame", 13, CellFormat::Fixed1},
      {"update texels", "update_texels_per_frame", 14, CellFormat::Fixed1},
      {"drawn tests", "drawn_depth_tests_per_frame", 13, CellFormat::Fixed1},
      {"total tests", "total_depth_tests_per_frame", 13, CellFormat::Fixed1},
      {"cycles", "cycles_per_frame", 11, CellFormat::Fixed0},
      {"culled", "culled_per_frame", 8, CellFormat::Fixed1},
      {"false", "false_culls", 6, CellFormat::Count},
      {"culling", "culling_efficiency", 8, CellFormat::Percent},
  };
  tab.ratio = TableSpec::Ratio{"occlusion queries / N-buffer query depth tests", "oq", "nb", "query_depth_tests_per_frame", "-"};
  tab.must_be_zero = "false_culls";
  tab.footer =
      "Rows: none (every draw), oq (an occlusion query per draw call, full resolution), nb, hiz_tile, hiz_pyramid. A draw call is\n"
      "tested when the model replays it into the frame's main target with a depth test that fails behind; culling efficiency is\n"
      "the culled share of the tested draws GL passed no sample of. Exit 1 when any mode culls a draw GL drew.";
  t.table = std::move(tab);
  t.headline_cost = "apps_cycles";
  t.headline_error = "apps_mismatch_rate";
  ReportLabels& r = t.report;
  r.error_axis = "compared draws differing from GL (%)";
  r.error_text = "compared draws whose samples passed differ from GL's (must be 0)";
  r.error_column = "differing draws (%)";
  r.cost_axis = "cycles";
  r.cost_column = "cycles";
  r.cost_pareto = "pareto_cycles";
  r.cost_short = "cycles";
  r.quality_column = "draws compared";
  r.must_be_zero = "mismatches against GL";
  r.alike = "answers alike";
  return t;
}

}  // namespace nbsim::techniques

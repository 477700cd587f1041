// The apps technique's declared results; its row of pipeline/techniques/results.h.
#include "pipeline/techniques/results.h"

namespace nbsim::techniques {

// A recorded program replayed draw by draw: its keys (apps.*) set timing only; the errors are
// correctness counts against GL (0 on every draw the model replays), the flagged share says how
// much of the program the model does not redo. No reference setting and no table yet: culling a
// program's draw calls is the next step.
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

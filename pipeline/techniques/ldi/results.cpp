// The ldi technique's declared results; its row of pipeline/techniques/results.h.
#include "pipeline/techniques/results.h"

namespace nbsim::techniques {

// Layered depth images (Trapp & Doellner): the model replays GL's peel passes, crops, compresses and
// runs the parity tests on its own LDI; in clipping and lens traces it runs the volume test on every
// scene fragment (model/ldi/clip.h), where the ldi.clip_* keys (test costs, texel cache) matter. Its keys (ldi.*) set timing only, so every point of a sweep
// answers alike: the errors are correctness counts against GL (the peel's counters, the layers, the
// parity answers; all 0) and the misclassification against the exact reference, which the LDI's
// side (a capture option: one trace per side) and not the model sets. No reference setting; no
// TableSpec: `nbsim ldi table1` prints Table 1 from GL captures of each shape and side.
TechniqueResults ldi_results() {
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
      metric("fetches_all", "texels", "texels the paper's parity test (every layer read) read, every test point", K::Cost, l("fetches_all")),
      zero(metric("parity_mismatches_all", "points", "test points where the model's paper's-reader answer differs from GL's; 0", K::Error,
                  l("parity_mismatches_all"))),
      zero(metric("parity_mismatches_ranges", "points", "test points where the model's compressed answer differs from GL's; 0",
                  K::Error, l("parity_mismatches_ranges"))),
      metric("misclassification_rate", "fraction",
             "test points the uncompressed parity test misclassifies against the exact reference, of those not within epsilon of "
             "a surface",
             K::Error, l("misclassification_rate_layers")),
      metric("misclassified", "points", "test points misclassified (uncompressed reader)", K::Outcome, l("misclassified_layers")),
      metric("classified_points", "points", "test points not within epsilon of a surface", K::Outcome, l("classified_points")),
      metric("clip_cycles", "cycles", "model cycles of the clipping and lens draws (their volume tests, depth tests and cache fills)", K::Cost,
             l("clip_cycles")),
      metric("clip_fetches", "texels", "texels the clipping and lens draws' reader fetched", K::Cost, l("clip_fetches")),
      metric("clip_discarded", "fragments", "fragments the volume test discarded (their depth tests saved)", K::Outcome, l("clip_discarded")),
      metric("clip_misclassified", "fragments", "clipping and lens fragments misclassified against the exact reference", K::Outcome,
             l("clip_misclassified")),
      zero(metric("clip_draw_mismatches", "draws", "clipping and lens draws whose counters or discarded fragments differ from GL's; 0",
                  K::Error, l("clip_draw_mismatches"))),
      zero(metric("clip_depth_mismatches", "frames", "clipping and lens frames whose final depth buffer differs from GL's; 0", K::Error,
                  l("clip_depth_mismatches"))),
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

}  // namespace nbsim::techniques

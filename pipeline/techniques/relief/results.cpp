// The relief technique's declared results; its row of pipeline/techniques/results.h.
#include "pipeline/techniques/results.h"

namespace nbsim::techniques {

TechniqueResults relief_results() {
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
      zero(metric("depth_mismatches", "draws", "box draws after which the depth buffer differs from GL's (relief_box_depth box or exact); 0",
                  K::Error, l("depth_mismatches"))),
      zero(metric("scene_mismatches", "draws", "scene draws (placement city) whose samples passed differ from GL's; 0", K::Error,
                  l("scene_mismatches"))),
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

}  // namespace nbsim::techniques

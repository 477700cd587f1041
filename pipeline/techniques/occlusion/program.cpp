// The occlusion_culling technique's frame program; see program.h.
#include "pipeline/techniques/occlusion/program.h"

#include <fmt/format.h>

#include <fstream>

#include "model/common/error.h"
#include "model/cull/unit.h"
#include "pipeline/sim/gpu.h"

namespace nbsim::pipeline {

namespace {

// Occlusion culling (the N-buffer paper, 3.1/4.2): cull.mode picks the query; "trace" replays.
Program build(const ProgramContext& c) {
  Program p;
  c.config.cull.parsed_granularity();  // refuses cull.granularity=primitive with nothing to test against
  if (c.config.cull.parsed_mode() == cull::CullMode::Trace) return p;
  // The mode's query structure: the N-buffer unit, or the Hi-Z baselines.
  if (const std::optional<query::Kind> kind = c.config.cull.structure_kind())
    p.structures.push_back(c.structure(*kind == query::Kind::NBuffer ? "nbuffer" : "hiz", *kind, c.setup.op));
  auto unit = std::make_unique<cull::CullUnit>("cull", c.registry, c.config.cull, c.setup, c.depth_buffer,
                                               p.structures.empty() ? nullptr : p.structures.front().get());
  if (c.out) {  // every bounds test with its decision, cost and ground truth
    auto log = std::make_unique<std::ofstream>(*c.out / "culls.csv");
    if (!*log) throw InputError(fmt::format("cannot write into '{}'", c.out->string()));
    unit->set_test_log(log.get());
    p.logs.push_back(std::move(log));
  }
  p.frames = unit.get();
  p.depth_listener = unit.get();
  if (unit->granularity() == cull::Granularity::Primitive) p.primitive_tester = unit.get();
  p.unit = std::move(unit);
  return p;
}

}  // namespace

ProgramRow occlusion_culling_program() {
  return {"occlusion_culling",
          "occlusion culling of a scene's objects (cull.mode: trace replays the recorded draws; none, oq, oq_hier, nb, "
          "nb_hier, hiz_tile, hiz_pyramid cull every candidate again)",
          build};
}

}  // namespace nbsim::pipeline

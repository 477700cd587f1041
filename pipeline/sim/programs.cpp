// The frame-program and structure-instance tables; see programs.h.
#include "pipeline/sim/programs.h"

#include <fmt/format.h>

#include <array>
#include <fstream>
#include <string>

#include "model/common/error.h"
#include "pipeline/sim/gpu.h"

namespace nbsim::pipeline {

namespace {

// Occlusion culling (the N-buffer paper, 3.1/4.2): cull.mode picks the query; "trace" replays.
Program occlusion_culling(const ProgramContext& c) {
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

constexpr std::array<ProgramRow, 2> kPrograms = {{
    {"occlusion_culling",
     "occlusion culling of a scene's objects (cull.mode: trace replays the recorded draws; none, oq, oq_hier, nb, "
     "nb_hier, hiz_tile, hiz_pyramid cull every candidate again)",
     occlusion_culling},
    // Captured (traces/capture/particles/), not modelled yet: its point sprites cannot be replayed as
    // recorded draws either, so every replay is refused (the build is null).
    {"particles", "point-sprite particles culled in the vertex stage (not modelled yet)", nullptr},
}};

constexpr std::array<StructureInstance, 2> kInstances = {{
    {"nbuffer", InstanceKind::NBuffer, "occlusion culling's N-buffer unit (cull.mode nb, nb_hier)"},
    {"hiz", InstanceKind::HiZ, "occlusion culling's Hi-Z baselines (cull.mode hiz_tile, hiz_pyramid)"},
}};

std::string technique_list() {
  std::string s;
  for (const ProgramRow& r : kPrograms)
    if (r.build) s += (s.empty() ? "" : ", ") + std::string(r.technique);
  return s;
}

}  // namespace

std::span<const ProgramRow> program_table() { return kPrograms; }
std::span<const StructureInstance> structure_instances() { return kInstances; }

std::unique_ptr<query::Structure> ProgramContext::structure(std::string_view instance, query::Kind kind, FarOp op) const {
  const std::string name(instance);
  const int w = setup.width_px, h = setup.height_px;
  const auto nb = config.nbuffers.find(instance);
  if (nb != config.nbuffers.end() && kind == query::Kind::NBuffer)
    return std::make_unique<query::NBufferStructure>(name.c_str(), registry, nb->second, w, h, op, &memory);
  const auto hiz = config.hiz.find(instance);
  if (hiz != config.hiz.end() && kind == query::Kind::TileHiZ)
    return std::make_unique<query::TileHiZUnit>(name.c_str(), registry, hiz->second, w, h, op);
  if (hiz != config.hiz.end() && kind == query::Kind::HiZPyramid)
    return std::make_unique<query::HiZPyramidUnit>(name.c_str(), registry, hiz->second, op);
  throw InputError(fmt::format("no query structure instance '{}' of kind {}", instance, query::to_string(kind)));
}

Program build_program(std::string_view technique, const ProgramContext& context) {
  for (const ProgramRow& r : kPrograms) {
    if (r.technique != technique) continue;
    if (!r.build)
      throw InputError(fmt::format("no model program for technique '{}' yet: its traces can be read (nbsim trace info, "
                                   "dump) but not replayed (programs exist for: {})",
                                   technique, technique_list()));
    return r.build(context);
  }
  if (context.config.cull.parsed_mode() != cull::CullMode::Trace)
    throw InputError(fmt::format(
        "cull.mode={} culls with occlusion culling's program, but the trace's technique is '{}' (programs exist for: "
        "{}); cull.mode=trace replays the recorded draws of any technique",
        context.config.cull.mode, technique.empty() ? "(none)" : std::string(technique), technique_list()));
  context.config.cull.parsed_granularity();
  return {};
}

}  // namespace nbsim::pipeline

// The frame-program and structure-instance tables; see programs.h.
#include "pipeline/sim/programs.h"

#include <fmt/format.h>

#include <array>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "pipeline/sim/gpu.h"
#include "pipeline/techniques/ldi/program.h"
#include "pipeline/techniques/occlusion/program.h"
#include "pipeline/techniques/particles/program.h"
#include "pipeline/techniques/relief/program.h"
#include "pipeline/techniques/shadows/program.h"

namespace nbsim::pipeline {

namespace {

// The registration list: one row per technique with a program (pipeline/techniques/<name>/).
const std::vector<ProgramRow>& programs() {
  static const std::vector<ProgramRow> rows = {occlusion_culling_program(), particles_program(), shadows_program(), ldi_program(),
                                               relief_program()};
  return rows;
}

constexpr std::array<StructureInstance, 4> kInstances = {{
    {"nbuffer", InstanceKind::NBuffer,
     "occlusion culling's N-buffer unit (cull.mode nb, nb_hier); the particles' max N-buffer (particle_mode nb, level_cap -1: "
     "the capture's levels)"},
    {"hiz", InstanceKind::HiZ,
     "occlusion culling's Hi-Z baselines (cull.mode hiz_tile, hiz_pyramid); the particles' Hi-Z pyramid format and timing "
     "(particle_mode hiz)"},
    {"litmap_min", InstanceKind::NBuffer,
     "shadows: the min N-buffer over the min litmap (litmap_size square), queried for each caster's z_min"},
    {"litmap_max", InstanceKind::NBuffer,
     "shadows: the max N-buffer over the max litmap (litmap_size square), queried for each caster's z_max"},
}};

std::string technique_list() {
  std::string s;
  for (const ProgramRow& r : programs())
    if (r.build) s += (s.empty() ? "" : ", ") + std::string(r.technique);
  return s;
}

}  // namespace

std::span<const ProgramRow> program_table() { return programs(); }

const ProgramRow* find_program(std::string_view technique) {
  for (const ProgramRow& r : programs())
    if (r.technique == technique) return &r;
  return nullptr;
}
std::span<const StructureInstance> structure_instances() { return kInstances; }

std::unique_ptr<query::Structure> ProgramContext::structure(std::string_view instance, query::Kind kind, FarOp op) const {
  const std::string name(instance);
  const int w = view.width_px, h = view.height_px;
  const auto nb = config.nbuffers.find(instance);
  if (nb != config.nbuffers.end() && kind == query::Kind::NBuffer)
    return std::make_unique<query::NBufferStructure>(name.c_str(), registry, nbuffer_config(instance), w, h, op, &memory);
  const auto hiz = config.hiz.find(instance);
  if (hiz != config.hiz.end() && kind == query::Kind::TileHiZ)
    return std::make_unique<query::TileHiZUnit>(name.c_str(), registry, hiz->second, w, h, op);
  if (hiz != config.hiz.end() && kind == query::Kind::HiZPyramid)
    return std::make_unique<query::HiZPyramidUnit>(name.c_str(), registry, hiz->second, op);
  throw InputError(fmt::format("no query structure instance '{}' of kind {}", instance, query::to_string(kind)));
}

void ProgramContext::require_no_cull_mode(std::string_view how) const {
  if (config.cull.parsed_mode() != cull::CullMode::Trace)
    throw InputError(fmt::format("cull.mode={} is occlusion culling's; {} (leave cull.mode at trace)", config.cull.mode, how));
  config.cull.parsed_granularity();
}

CoveringSpec ProgramContext::capture_covering() const {
  return header.covering.value_or(CoveringSpec{CoveringKind::Corners, CoveringAlign::Bottom});
}

nbuffer::NBufferUnitConfig ProgramContext::nbuffer_config(std::string_view instance) const {
  nbuffer::NBufferUnitConfig nb = config.nbuffers.at(std::string(instance));
  nb.validate();
  const CoveringSpec spec = nb.covering_spec(capture_covering());
  nb.covering = std::string(to_string(spec.kind));
  nb.align = std::string(to_string(spec.align));
  return nb;
}

Program build_program(std::string_view technique, const ProgramContext& context) {
  if (context.config.program == "off") {
    if (context.config.cull.parsed_mode() != cull::CullMode::Trace)
      throw InputError(fmt::format("gpu.program=off runs no program, but cull.mode={} asks a program to cull "
                                   "(leave cull.mode at trace, or gpu.program at auto)",
                                   context.config.cull.mode));
    return {};
  }
  for (const ProgramRow& r : programs()) {
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

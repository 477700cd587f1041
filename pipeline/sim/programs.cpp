// The frame-program and structure-instance tables; see programs.h.
#include "pipeline/sim/programs.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "pipeline/sim/gpu.h"

namespace nbsim::pipeline {

namespace {

// One row per technique of the registration list (pipeline/techniques/<name>/program.cpp).
const std::vector<ProgramRow>& programs() {
#define NBSIM_TECHNIQUE_PROGRAM(name) name##_program(),
  static const std::vector<ProgramRow> rows = {NBSIM_EACH_TECHNIQUE(NBSIM_TECHNIQUE_PROGRAM)};
#undef NBSIM_TECHNIQUE_PROGRAM
  return rows;
}

std::string technique_list() {
  std::string s;
  for (const ProgramRow& r : programs())
    if (r.build) s += (s.empty() ? "" : ", ") + std::string(r.technique);
  return s;
}

// The programs a cull.mode other than trace runs, as messages name them.
std::string cull_mode_owner() {
  std::vector<std::string> names;
  for (const ProgramRow& r : programs())
    if (r.runs_cull_mode) names.emplace_back(r.technique);
  if (names.empty()) return "no program";
  std::string s = names.size() == 1 ? "the " + names.front() + " program" : "the programs ";
  for (std::size_t i = 0; names.size() > 1 && i < names.size(); ++i) s += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + names[i];
  return s;
}

}  // namespace

std::span<const ProgramRow> program_table() { return programs(); }

const ProgramRow* find_program(std::string_view technique) {
  for (const ProgramRow& r : programs())
    if (r.technique == technique) return &r;
  return nullptr;
}

std::span<const StructureInstance> structure_instances() {
  static const std::vector<StructureInstance> instances = [] {
    std::vector<StructureInstance> all;
    for (const ProgramRow& r : programs())
      for (const StructureInstance& i : r.instances) {
        const std::string what = fmt::format("{}: {}", r.technique, i.description);
        const auto it = std::find_if(all.begin(), all.end(), [&](const StructureInstance& a) { return a.name == i.name; });
        if (it == all.end()) {
          all.push_back({i.name, i.kind, what});
        } else if (it->kind != i.kind) {
          throw std::logic_error(fmt::format("structure instance '{}' declared with two kinds (technique {})", i.name, r.technique));
        } else {
          it->description += "; " + what;
        }
      }
    return all;
  }();
  return instances;
}

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
    throw InputError(fmt::format("cull.mode={} culls with {}; {} (leave cull.mode at trace)", config.cull.mode, cull_mode_owner(), how));
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
        "cull.mode={} culls with {}, but the trace's technique is '{}' (programs exist for: "
        "{}); cull.mode=trace replays the recorded draws of any technique",
        context.config.cull.mode, cull_mode_owner(), technique.empty() ? "(none)" : std::string(technique), technique_list()));
  context.config.cull.parsed_granularity();
  return {};
}

}  // namespace nbsim::pipeline

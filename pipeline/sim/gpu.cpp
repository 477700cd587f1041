// The replay model's top level; see gpu.h.
#include "pipeline/sim/gpu.h"

#include <stdexcept>
#include <string>

#include "model/common/error.h"
#include "model/sim/quantum.h"

namespace nbsim::pipeline {

void GpuConfig::describe(config::Schema& s, GpuConfig& c) {
  cp::CommandProcessorConfig::describe(s, c.cp);
  geometry::GeometryUnitConfig::describe(s, c.geometry);
  raster::RasterUnitConfig::describe(s, c.raster);
  depth::DepthUnitConfig::describe(s, c.depth);
  s.add("memory.bandwidth_bytes_per_cycle", c.memory.bandwidth_bytes_per_cycle, "bytes/cycle",
        "sustained bandwidth shared by every client", 0.01, 1e6);
  s.add("memory.latency_cycles", c.memory.latency_cycles, "cycles", "from request to data", 0, 100000);
  cull::CullUnitConfig::describe(s, c.cull);
  for (const ProgramRow& row : program_table())
    if (row.config.describe) row.config.describe(s, c.groups.find(row.config.name)->second);
  for (auto& [name, config] : c.nbuffers) nbuffer::NBufferUnitConfig::describe(s, config, name);
  for (auto& [name, config] : c.hiz) HiZUnitConfig::describe(s, config, name);
  s.add("gpu.fifo_depth", c.fifo_depth, "work items", "depth of the fifos between units", 1, 4096);
  s.add("gpu.quantum_cycles", c.quantum_cycles, "cycles",
        "temporal decoupling quantum: a unit runs ahead of simulated time by up to this many cycles before it "
        "synchronises (0: every work item synchronises, the most detailed timing)",
        0, 10'000'000);
  s.add("gpu.program", c.program,
        "whether the trace's technique program runs: auto (the program its technique and this config ask for) or off "
        "(none: the recorded draws replay through the generic units only, so what a program models, such as a "
        "shader's discards or a second depth buffer, is not, and compare shows it)",
        {"auto", "off"});
}

GpuConfig::GpuConfig() {
  for (const ProgramRow& row : program_table())
    if (row.config.defaults) groups.emplace(std::string(row.config.name), row.config.defaults());
  for (const StructureInstance& i : structure_instances()) {
    if (i.kind == InstanceKind::NBuffer) nbuffers[std::string(i.name)].key_prefix = i.name;
    if (i.kind == InstanceKind::HiZ) hiz[std::string(i.name)].key_prefix = i.name;
  }
}

void GpuConfig::validate() const {
  for (const auto& [name, config] : nbuffers) config.validate();
  for (const auto& [name, config] : hiz) config.validate();
  for (const ProgramRow& row : program_table())
    if (row.config.validate) row.config.validate(find_group(row.config.name));
}

const std::any& GpuConfig::find_group(std::string_view name) const {
  const auto it = groups.find(name);
  if (it == groups.end()) throw std::logic_error("no program declares the config group '" + std::string(name) + "'");
  return it->second;
}

Gpu::Gpu(const sc_core::sc_module_name& name, stats::Registry& registry, const GpuConfig& c, int width_px, int height_px,
         cp::FrameSource source, float clear_depth, depth::ResultSink& sink, const trace::Header& header,
         const TraceView& view, const std::filesystem::path* out)
    : sc_core::sc_module(name),
      memory_(c.memory),
      cp_to_geometry_("cp_to_geometry", c.fifo_depth),
      geometry_to_raster_("geometry_to_raster", c.fifo_depth),
      raster_to_depth_("raster_to_depth", c.fifo_depth),
      cp_("cp", registry, c.cp, std::move(source), clear_depth),
      geometry_("geometry", registry, c.geometry, width_px, height_px),
      raster_("raster", registry, c.raster, width_px, height_px),
      depth_("depth", registry, c.depth, width_px, height_px, memory_, sink) {
  sim::set_quantum_cycles(static_cast<std::uint64_t>(c.quantum_cycles));  // before sc_start; 0: no decoupling
  cp_.out(cp_to_geometry_);
  geometry_.in(cp_to_geometry_);
  geometry_.out(geometry_to_raster_);
  raster_.in(geometry_to_raster_);
  raster_.out(raster_to_depth_);
  depth_.in(raster_to_depth_);
  program_ = build_program(header.technique, ProgramContext{registry, c, header, view, depth_.buffer(), depth_.stencil(), memory_, out});
  if (program_.frames) cp_.set_program(program_.frames);
  if (program_.depth_listener) depth_.set_listener(program_.depth_listener);
  // Per-primitive culling: the program tests the raster unit's triangles between setup and the tile walk.
  if (program_.primitive_tester) raster_.set_primitive_tester(program_.primitive_tester);
  // The shared memory channel: bytes per client (every client has registered by now) and busy cycles.
  stats::Group& mem = registry.group(std::string(this->name()) + ".memory");
  for (std::size_t i = 0; i < memory_.clients().size(); ++i) {
    const std::string& client = memory_.clients()[i];  // "depth", or a module's full name
    mem.formula("bytes_" + client.substr(client.rfind('.') + 1), "bytes", "bytes moved for " + client,
                [this, i] { return static_cast<double>(memory_.bytes(static_cast<int>(i))); });
  }
  mem.formula("transfer_cycles", "cycles", "cycles the channel spent transferring (not a unit's busy_cycles)",
              [this] { return static_cast<double>(memory_.busy_cycles()); });
}

}  // namespace nbsim::pipeline

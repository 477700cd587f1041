// The configurable top level of the replay model: it wires the units (command processor ->
// geometry -> raster -> depth, with the shared memory channel) with SystemC fifos, like the
// *_top.cpp of the SystemC TLM examples. It only wires; the units do the work.
//
//   trace frames --> [cp] --fifo--> [geometry] --fifo--> [raster] --fifo--> [depth] --> ResultSink
//                     ^                                                        |
//                     |  frame program                 clears, dirty rects,    +- [memory channel]
//               [program] <------------------------ draw results -----------+        |
//                     +-- [query structures: nbuffer / hiz] -----------------------------+
// The frame program comes from the trace's technique and the config (programs.h); with
// gpu.program=off there is none for any technique and the command processor replays the
// recorded draws.
#pragma once

#include <any>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <string_view>

#include "model/config/schema.h"
#include "model/cp/unit.h"
#include "model/cull/unit.h"
#include "model/depth/unit.h"
#include "model/geometry/unit.h"
#include "model/memory/memory.h"
#include "model/query/units.h"
#include "model/raster/unit.h"
#include "pipeline/sim/programs.h"

namespace nbsim::pipeline {

struct GpuConfig {
  cp::CommandProcessorConfig cp;
  geometry::GeometryUnitConfig geometry;
  raster::RasterUnitConfig raster;
  depth::DepthUnitConfig depth;
  memory::ChannelConfig memory;
  cull::CullUnitConfig cull;
  // The programs' own config groups (programs.h ProgramRow::config) by name, each the unit config
  // type its program declared; read with group<T>(name).
  std::map<std::string, std::any, std::less<>> groups;
  // The query-structure instances (programs.h structure_instances()) by name, one config each
  // (keys "<name>.<field>").
  std::map<std::string, nbuffer::NBufferUnitConfig, std::less<>> nbuffers;
  std::map<std::string, HiZUnitConfig, std::less<>> hiz;
  int fifo_depth = 4;  // work items between two units; tunable
  // Timing granularity, a fidelity knob: how many cycles a unit's thread may run ahead of SystemC
  // time before it synchronises (TLM-2.0 temporal decoupling, model/sim/unit.h). 0: every work
  // item synchronises (the most detailed timing). Counts never depend on it; cycles do.
  int quantum_cycles = 0;
  // Whether the trace's technique program runs (programs.h): "auto" builds the program the trace's
  // technique and this config ask for; "off" builds none, whatever the technique, and the recorded
  // draws replay through the pipeline as the generic raster and depth units see them.
  std::string program = "auto";

  // Declares every key of every unit ("cp.", "geometry.", "raster.", "depth.", "memory.", "cull."),
  // of every program's group and every structure instance, and "gpu.".
  static void describe(config::Schema& s, GpuConfig& c);
  // Throws InputError naming the key when a unit's value is out of its limits or inconsistent
  // (the checks the units make when they are built, for a config checked before any run).
  void validate() const;

  GpuConfig();  // every program group and structure instance at its defaults

  // The config group `name` of a program (ProgramRow::config), as the type it declared; throws
  // std::logic_error when no program declared that group (a programming error, not an input's).
  template <class T>
  const T& group(std::string_view name) const {
    return std::any_cast<const T&>(find_group(name));
  }

 private:
  const std::any& find_group(std::string_view name) const;
};

class Gpu : public sc_core::sc_module {
 public:
  // The trace's `header` (its technique and the keys the technique declares) and `view` (viewport,
  // depth convention, scene) choose and feed the frame program (programs.h); both must outlive the
  // construction.
  Gpu(const sc_core::sc_module_name& name, stats::Registry& registry, const GpuConfig& config, int width_px, int height_px,
      cp::FrameSource source, float clear_depth, depth::ResultSink& sink, const trace::Header& header,
      const TraceView& view, const std::filesystem::path* out = nullptr);

  const memory::Channel& memory() const noexcept { return memory_; }
  const Program& program() const noexcept { return program_; }
  // The depth unit: its depth and stencil buffers as the last work item left them.
  const depth::DepthUnit& depth() const noexcept { return depth_; }
  // The depth buffer's format (the trace header's depth_format); before sc_start.
  void set_depth_format(raster::DepthFormat format) noexcept { depth_.set_depth_format(format); }

 private:
  memory::Channel memory_;
  sc_core::sc_fifo<cp::WorkPtr> cp_to_geometry_;
  sc_core::sc_fifo<geometry::TriangleBatchPtr> geometry_to_raster_;
  sc_core::sc_fifo<raster::BlockBatchPtr> raster_to_depth_;
  cp::CommandProcessor cp_;
  geometry::GeometryUnit geometry_;
  raster::RasterUnit raster_;
  depth::DepthUnit depth_;
  Program program_;
};

}  // namespace nbsim::pipeline

// CommandProcessor: the head of the replay pipeline. It streams a trace's frames (from a source
// the pipeline gives it) and issues, per frame: a clear, every draw with geometry in the recorded
// order, the depth snapshots where GL took them, and the end of the frame. A draw costs
// draw_overhead_cycles of command processing.
#pragma once

#include <functional>
#include <optional>

#include "model/config/schema.h"
#include "model/cp/work.h"
#include "model/sim/unit.h"

namespace nbsim::cp {

struct CommandProcessorConfig {
  int draw_overhead_cycles = 8;  // decoding a draw's state and launching it; tunable

  static void describe(config::Schema& s, CommandProcessorConfig& c);
};

class CommandProcessor;

// A frame program: what the command processor issues for one frame between FrameBegin and
// FrameEnd when a technique's program replays the trace (pipeline/sim/programs.h picks it by the
// trace's technique; model/cull/unit.h is occlusion culling's). Without one the command processor
// issues the recorded draws as they are. What a program did is in its statistics.
class FrameProgram {
 public:
  virtual ~FrameProgram() = default;
  virtual void run_frame(const std::shared_ptr<const scene::Frame>& frame, CommandProcessor& cp) = 0;
};

// Hands out the trace's frames one at a time (memory stays bounded by a frame); nullopt at the end.
using FrameSource = std::function<std::optional<scene::Frame>()>;

class CommandProcessor : public sim::Unit {
 public:
  sc_core::sc_fifo_out<WorkPtr> out;

  CommandProcessor(const sc_core::sc_module_name& name, stats::Registry& registry, const CommandProcessorConfig& config,
                   FrameSource source, float clear_depth);

  // Culling modes: the program that issues each frame's draws (null: the recorded draws).
  void set_program(FrameProgram* program) noexcept { program_ = program; }
  // Issues one draw (command processing costs draw_overhead_cycles); from the CP's thread only.
  void issue_draw(std::shared_ptr<Work> w);
  // Issues a depth snapshot marker.
  void issue_snapshot(const std::shared_ptr<const scene::Frame>& f, scene::DepthWhich which);

 private:
  void run();
  void issue();
  void send(WorkKind kind, const std::shared_ptr<const scene::Frame>& f, std::uint32_t draw = 0,
            scene::DepthWhich which = scene::DepthWhich::Final);
  FrameProgram* program_ = nullptr;
  CommandProcessorConfig config_;
  FrameSource source_;
  float clear_depth_;
  stats::Counter &frames_, &draws_, &skipped_;
};

}  // namespace nbsim::cp

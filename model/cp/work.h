// The work the command processor hands to the geometry unit, and on down the pipeline: draws of
// one frame, and markers that open and close frames and take depth snapshots. Packets are shared
// pointers so that SystemC fifos move a pointer, never a draw's geometry.
#pragma once

#include <cstdint>
#include <memory>
#include <ostream>
#include <string>

#include <fmt/format.h>

#include "model/scene/frame.h"

namespace nbsim::cp {

enum class WorkKind : std::uint8_t {
  FrameBegin = 0,  // clear the depth buffer to `clear_depth`
  Draw = 1,        // one draw with geometry
  Snapshot = 2,    // the depth buffer as it is now is the frame's `which` snapshot
  FrameEnd = 3,    // the frame is done; the replay may compare and move on
  Stop = 4,        // the trace is done
};

struct Work {
  WorkKind kind = WorkKind::Draw;
  std::shared_ptr<const scene::Frame> frame;  // the frame this work belongs to
  std::uint32_t draw = 0;                     // index into frame->draws (Draw)
  scene::DepthWhich which = scene::DepthWhich::Final;  // (Snapshot)
  float clear_depth = 1.0f;                            // (FrameBegin)
  // Frame programs (unit.h): a draw the program made itself (a bounding box), used instead of
  // frame->draws[draw]; whether its depth writes feed the program's query structures; and a ticket
  // the program waits on. What a program did is in its statistics.
  std::shared_ptr<const scene::DrawRecord> own;
  bool feeds_cull = false;
  std::uint64_t ticket = 0;

  const scene::DrawRecord& record() const { return own ? *own : frame->draws[draw]; }
};

using WorkPtr = std::shared_ptr<const Work>;

// The name of a unit's span on a timeline (model/sim/timeline.h): "frame 3 draw 12 (occluder)".
inline std::string timeline_label(const Work& w) {
  const std::uint64_t frame = w.frame ? w.frame->begin.frame : 0;
  switch (w.kind) {
    case WorkKind::FrameBegin: return fmt::format("frame {} clear", frame);
    case WorkKind::Draw:
      return fmt::format("frame {} draw {} ({})", frame, w.record().index, scene::to_string(w.record().role));
    case WorkKind::Snapshot: return fmt::format("frame {} snapshot", frame);
    case WorkKind::FrameEnd: return fmt::format("frame {} end", frame);
    case WorkKind::Stop: return "stop";
  }
  return "?";
}

// sc_fifo needs to print what it carries.
inline std::ostream& operator<<(std::ostream& os, const WorkPtr& w) {
  return os << "work(" << static_cast<int>(w ? w->kind : WorkKind::Stop) << ")";
}

}  // namespace nbsim::cp

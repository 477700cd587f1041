// CommandProcessor; see unit.h.
#include "model/cp/unit.h"

namespace nbsim::cp {

void CommandProcessorConfig::describe(config::Schema& s, CommandProcessorConfig& c) {
  s.add("cp.draw_overhead_cycles", c.draw_overhead_cycles, "cycles", "command processing per draw", 0, 100000);
}

CommandProcessor::CommandProcessor(const sc_core::sc_module_name& name, stats::Registry& registry,
                                   const CommandProcessorConfig& config, FrameSource source, float clear_depth)
    : sim::Unit(name, registry),
      config_(config),
      source_(std::move(source)),
      clear_depth_(clear_depth),
      frames_(stats().counter("frames", "frames", "frames issued")),
      draws_(stats().counter("draws", "draws", "draws with geometry issued")),
      skipped_(stats().counter("passes_not_replayed", "draws",
                               "recorded GL passes without geometry (GLSL N-buffer passes and lookups), not replayed")) {
  SC_HAS_PROCESS(CommandProcessor);
  SC_THREAD(run);
}

void CommandProcessor::send(WorkKind kind, const std::shared_ptr<const scene::Frame>& f, std::uint32_t draw,
                            scene::DepthWhich which) {
  auto w = std::make_shared<Work>();
  w->kind = kind;
  w->frame = f;
  w->draw = draw;
  w->which = which;
  w->clear_depth = clear_depth_;
  sim::blocking([&] { out.write(w); });
}

void CommandProcessor::issue_draw(std::shared_ptr<Work> w) {
  ++draws_;
  label_with([&] { return timeline_label(*w); });
  work(static_cast<std::uint64_t>(config_.draw_overhead_cycles));
  w->kind = WorkKind::Draw;
  w->clear_depth = clear_depth_;
  sim::blocking([&] { out.write(std::move(w)); });
}

void CommandProcessor::issue_snapshot(const std::shared_ptr<const scene::Frame>& f, scene::DepthWhich which) {
  send(WorkKind::Snapshot, f, 0, which);
}

void CommandProcessor::run() {
  sim::guard_thread([this] { issue(); });
}

void CommandProcessor::issue() {
  while (std::optional<scene::Frame> next = source_()) {
    const auto f = std::make_shared<const scene::Frame>(std::move(*next));
    ++frames_;
    send(WorkKind::FrameBegin, f);
    if (program_) {
      program_->run_frame(f, *this);
      send(WorkKind::FrameEnd, f);
      continue;
    }
    // GL read the "after occluders" depth right after the last occluder draw.
    std::int64_t last_occluder = -1;
    for (std::size_t i = 0; i < f->draws.size(); ++i)
      if (f->draws[i].role == scene::DrawRole::Occluder) last_occluder = static_cast<std::int64_t>(i);
    if (last_occluder < 0) send(WorkKind::Snapshot, f, 0, scene::DepthWhich::AfterOccluders);
    for (std::size_t i = 0; i < f->draws.size(); ++i) {
      const scene::DrawRecord& d = f->draws[i];
      if (d.clip_positions.empty()) {
        ++skipped_;
      } else {
        ++draws_;
        label_with([&] { return fmt::format("frame {} draw {} ({})", f->begin.frame, d.index, scene::to_string(d.role)); });
        work(static_cast<std::uint64_t>(config_.draw_overhead_cycles));
        send(WorkKind::Draw, f, static_cast<std::uint32_t>(i));
      }
      if (static_cast<std::int64_t>(i) == last_occluder) send(WorkKind::Snapshot, f, 0, scene::DepthWhich::AfterOccluders);
    }
    send(WorkKind::Snapshot, f, 0, scene::DepthWhich::Final);
    send(WorkKind::FrameEnd, f);
  }
  send(WorkKind::Stop, nullptr);
}

}  // namespace nbsim::cp

// CommandProcessorTest: the head of the replay pipeline (model/cp/unit.h) without a program: per
// frame a clear, every draw with geometry in the recorded order (a pass without geometry skipped
// and counted), the "after occluders" snapshot right after the last occluder, the final snapshot,
// the frame's end, and a stop after the last frame; a draw costs draw_overhead_cycles.
// One elaboration per process: ctest runs each TEST in its own process.
#include "model/cp/unit.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

extern "C" int sc_main(int, char*[]) { return 1; }  // libsystemc's main() needs one; gtest's main runs

namespace nbsim::cp {
namespace {

// Reads the command processor's work until the stop, one line per item, and notes when it came.
struct Sink : sc_core::sc_module {
  sc_core::sc_fifo_in<WorkPtr> in;
  std::vector<std::string> seen;
  std::vector<std::uint64_t> cycles;
  SC_HAS_PROCESS(Sink);
  explicit Sink(const sc_core::sc_module_name& n) : sc_core::sc_module(n) { SC_THREAD(run); }
  void run() {
    for (;;) {
      const WorkPtr w = in.read();
      cycles.push_back(sim::now_cycles());
      if (w->kind == WorkKind::Stop) {
        seen.push_back("stop");
        return;
      }
      const std::string frame = std::to_string(w->frame->begin.frame);
      switch (w->kind) {
        case WorkKind::FrameBegin: seen.push_back(frame + " clear " + std::to_string(w->clear_depth)); break;
        case WorkKind::Draw: seen.push_back(frame + " draw " + std::to_string(w->record().index)); break;
        case WorkKind::Snapshot:
          seen.push_back(frame + (w->which == scene::DepthWhich::AfterOccluders ? " after_occluders" : " final"));
          break;
        case WorkKind::FrameEnd: seen.push_back(frame + " end"); break;
        case WorkKind::Stop: break;
      }
    }
  }
};

scene::DrawRecord draw(std::uint32_t index, scene::DrawRole role, bool geometry) {
  scene::DrawRecord d;
  d.index = index;
  d.role = role;
  if (geometry) d.clip_positions = {{0, 0, 0, 1}, {1, 0, 0, 1}, {0, 1, 0, 1}};
  return d;
}

TEST(CommandProcessorTest, IssuesEachFrameInTheRecordedOrder) {
  sim::install_report_handler();
  std::vector<scene::Frame> frames(2);
  frames[0].begin.frame = 0;  // an occluder, a GLSL N-buffer pass (no geometry) last among the occluders, a visible draw
  frames[0].draws = {draw(0, scene::DrawRole::Occluder, true), draw(1, scene::DrawRole::Occluder, false),
                     draw(2, scene::DrawRole::Visible, true)};
  frames[1].begin.frame = 1;  // no occluder: the "after occluders" depth is the cleared one
  frames[1].draws = {draw(0, scene::DrawRole::Visible, true)};
  std::size_t next = 0;
  const FrameSource source = [&]() -> std::optional<scene::Frame> {
    if (next == frames.size()) return std::nullopt;
    return frames[next++];
  };
  stats::Registry reg;
  CommandProcessorConfig config;
  config.draw_overhead_cycles = 5;
  CommandProcessor cp("cp", reg, config, source, 0.25f);
  Sink sink("sink");
  sc_core::sc_fifo<WorkPtr> fifo(16);
  cp.out(fifo);
  sink.in(fifo);
  sc_core::sc_start();

  const std::string clear = std::to_string(0.25f);
  EXPECT_EQ(sink.seen, (std::vector<std::string>{"0 clear " + clear, "0 draw 0", "0 after_occluders", "0 draw 2", "0 final",
                                                 "0 end", "1 clear " + clear, "1 after_occluders", "1 draw 0", "1 final",
                                                 "1 end", "stop"}));
  ASSERT_EQ(sink.cycles.size(), sink.seen.size());
  EXPECT_EQ(sink.cycles[1], 5u) << "the first draw leaves after its command processing";
  EXPECT_EQ(sink.cycles.back(), 15u) << "three draws with geometry at 5 cycles each, markers cost nothing";
  const auto v = reg.values()["cp"];
  EXPECT_EQ(v["frames"], 2);
  EXPECT_EQ(v["draws"], 3);
  EXPECT_EQ(v["passes_not_replayed"], 1);
  EXPECT_EQ(v["busy_cycles"], 15);
}

}  // namespace
}  // namespace nbsim::cp

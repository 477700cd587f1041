// The N-buffer unit as a SystemC module: a thin wrapper around NBufferUnitCore (unit_core.h) that
// turns the core's work into cycles. Other units call its blocking methods from their SC_THREADs.
//
// Timing (cycle-approximate):
// - query(): waits until the update engine has finished the work handed to it before the query
//   arrived (answers see every change applied to the core), then takes, one query at a time, batch_cycles(lookups,
//   lookups_per_cycle, lookup_latency_cycles), plus, under the lazy policy, the update work applied for it. Cache
//   misses go to the memory channel when the lookups start; the query ends when both are done.
// - depth_changed(), depth_cleared(), end_of_pass(), end_of_frame(): apply the change to the core
//   at once and hand the update work to the unit's update engine (its own thread), which spends
//   batch_cycles(texels, update_texels_per_cycle, update_latency_cycles) per batch it takes and
//   streams the batch's bytes over the memory channel. The caller does not wait.
// busy_cycles counts the query port and the update engine (they may overlap in time).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "model/memory/memory.h"
#include "model/nbuffer/unit_core.h"
#include "model/sim/unit.h"

namespace nbsim::nbuffer {

class NBufferUnit : public sim::Unit {
 public:
  SC_HAS_PROCESS(NBufferUnit);
  // `channel` may be null (no memory timing; bytes are still counted by the core). The unit
  // registers itself as a client of the channel under its full name.
  NBufferUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const NBufferUnitConfig& config,
              int width_px, int height_px, FarOp op, memory::Channel* channel);

  // Blocking calls: only from an SC_THREAD.
  QueryAnswer query(const Rect& r, float nearest_depth);
  // A batch of queries (rects[i] with nearest[i]) through the query port as one pipelined stream:
  // the same waits as query(), then batch_cycles(total lookups, lookups_per_cycle,
  // lookup_latency_cycles) plus any lazy update work, one latency for the whole batch (the
  // per-triangle queries of one draw, model/cull/primitive.h). Answers in order into `answers`.
  void query_batch(std::span<const Rect> rects, std::span<const float> nearest, std::vector<QueryAnswer>& answers);
  // Waits until the update engine is idle.
  void drain();

  // Non-blocking notifications from the depth unit and the command processor. Each returns the
  // update work it handed to the engine (for counters; the engine turns it into cycles).
  UpdateWork depth_changed(const DepthImage& depth, const Rect& dirty);
  UpdateWork depth_changed(std::span<const PixelWrite> writes);
  UpdateWork depth_cleared(float depth);
  UpdateWork end_of_pass();
  UpdateWork end_of_frame();

  const NBufferUnitCore& core() const noexcept { return core_; }
  NBufferUnitCore& core() noexcept { return core_; }
  bool engine_idle() const noexcept { return done_seq_ == posted_seq_; }

 private:
  // Waits until the engine has done the work posted before the caller arrived and the query port
  // is free, then takes the port; returns the arrival cycle (the wait is counted).
  std::uint64_t acquire_port();
  void engine();  // SC_THREAD: the update engine, update_loop() under sim::guard_thread
  void update_loop();
  UpdateWork post(UpdateWork w);
  // Waits until `done` (a cycle), counting the wait in `counter`.
  void wait_until(std::uint64_t done, stats::Counter& counter);

  NBufferUnitCore core_;
  memory::Channel* channel_;
  int client_ = -1;
  std::uint64_t queued_texels_ = 0, queued_bytes_ = 0;
  std::uint64_t posted_seq_ = 0, done_seq_ = 0;  // work handed to the engine, and finished, by count
  std::uint64_t posted_cycle_ = 0, done_cycle_ = 0;  // local times of the last post and the last batch done
  bool port_busy_ = false;
  sc_core::sc_event posted_, batch_done_, port_free_;

  stats::Counter& query_cycles_;
  stats::Counter& query_wait_cycles_;
  stats::Counter& update_cycles_;
  stats::Counter& memory_stall_cycles_;
  stats::Counter& update_batches_;
};

}  // namespace nbsim::nbuffer

// The N-buffer unit's SystemC wrapper: cycles for queries and for the update engine; see unit.h.
#include "model/nbuffer/unit.h"

#include <fmt/format.h>

#include <algorithm>

#include "model/common/error.h"

namespace nbsim::nbuffer {

NBufferUnit::NBufferUnit(const sc_core::sc_module_name& name, stats::Registry& registry,
                         const NBufferUnitConfig& config, int width_px, int height_px, FarOp op,
                         memory::Channel* channel)
    : sim::Unit(name, registry),
      core_(config, width_px, height_px, op, stats()),
      channel_(channel),
      query_cycles_(stats().counter("query_cycles", "cycles", "cycles from a query's start to its answer, summed")),
      query_wait_cycles_(stats().counter("query_wait_cycles", "cycles",
                                         "cycles queries waited for the update engine or for an earlier query")),
      update_cycles_(stats().counter("update_cycles", "cycles",
                                     "cycles of update work: the engine's batches and lazy updates inside queries")),
      memory_stall_cycles_(stats().counter("memory_stall_cycles", "cycles",
                                           "cycles spent waiting for memory after the unit's own work was done")),
      update_batches_(stats().counter("update_batches", "batches", "batches the update engine took")) {
  if (channel_) client_ = channel_->add_client(this->name());
  SC_THREAD(engine);
}

void NBufferUnit::wait_until(std::uint64_t done, stats::Counter& counter) { counter += sim::spend_until(done); }

UpdateWork NBufferUnit::post(UpdateWork w) {
  const NBufferUnitConfig& c = core_.config();
  const std::uint64_t texels = w.engine_texels(c.update_texels_per_cycle, c.invalidations_per_cycle);
  const std::uint64_t bytes = w.bytes_read + w.bytes_written;
  if (texels == 0 && bytes == 0) return w;
  queued_texels_ += texels;
  queued_bytes_ += bytes;
  ++posted_seq_;
  posted_cycle_ = std::max(posted_cycle_, sim::local_cycles());
  posted_.notify();
  return w;
}

void NBufferUnit::engine() {
  sim::guard_thread([this] { update_loop(); });
}

void NBufferUnit::update_loop() {
  const NBufferUnitConfig& c = core_.config();
  for (;;) {
    sim::blocking([&] {
      while (done_seq_ == posted_seq_) wait(posted_);
    });
    sim::catch_up(posted_cycle_);  // not before the work was posted (model/sim/unit.h)
    // Everything queued so far is one batch: its texels stream through the engine's pipeline.
    const std::uint64_t seq = posted_seq_, texels = queued_texels_, bytes = queued_bytes_;
    queued_texels_ = queued_bytes_ = 0;
    ++update_batches_;
    const std::uint64_t start = sim::local_cycles();
    const std::uint64_t mem_done = channel_ && bytes ? channel_->transfer(start, bytes, client_) : start;
    const std::uint64_t n = sim::batch_cycles(texels, c.update_texels_per_cycle, c.update_latency_cycles);
    label_with([&] { return fmt::format("update batch, {} texels", texels); });
    work(n);
    wait_until(mem_done, memory_stall_cycles_);
    update_cycles_ += sim::local_cycles() - start;
    done_seq_ = seq;
    done_cycle_ = sim::local_cycles();
    batch_done_.notify();
  }
}

void NBufferUnit::drain() {
  sim::blocking([&] {
    while (!engine_idle()) wait(batch_done_);
  });
  sim::catch_up(done_cycle_);
}

std::uint64_t NBufferUnit::acquire_port() {
  const std::uint64_t arrived = sim::local_cycles();
  // Only once the engine has done the work posted before this query arrived (later work does not
  // hold it up), and one query (or batch) at a time.
  const std::uint64_t needed = posted_seq_;
  sim::blocking([&] {
    while (done_seq_ < needed) wait(batch_done_);
    while (port_busy_) wait(port_free_);
  });
  sim::catch_up(done_cycle_);  // the engine's work it waited for is done by then
  port_busy_ = true;
  query_wait_cycles_ += sim::local_cycles() - arrived;
  return arrived;
}

QueryAnswer NBufferUnit::query(const Rect& r, float nearest_depth) {
  const std::uint64_t arrived = acquire_port();

  const NBufferUnitConfig& c = core_.config();
  QueryAnswer a = core_.query(r, nearest_depth);
  const std::uint64_t start = sim::local_cycles();
  const std::uint64_t update_texels = a.update.recomputed();
  const std::uint64_t update_n = sim::batch_cycles(update_texels, c.update_texels_per_cycle, c.update_latency_cycles);
  const std::uint64_t bytes = a.bytes_read + a.update.bytes_read + a.update.bytes_written;
  const std::uint64_t mem_done = channel_ && bytes ? channel_->transfer(start, bytes, client_) : start;
  label_with([&] { return fmt::format("query, {} lookups, {} texels updated", a.lookups, update_texels); });
  work(update_n +
       sim::batch_cycles(static_cast<std::uint64_t>(a.lookups), c.lookups_per_cycle, c.lookup_latency_cycles));
  wait_until(mem_done, memory_stall_cycles_);
  update_cycles_ += update_n;
  query_cycles_ += sim::local_cycles() - arrived;

  port_busy_ = false;
  port_free_.notify();
  return a;
}

void NBufferUnit::query_batch(std::span<const Rect> rects, std::span<const float> nearest,
                              std::vector<QueryAnswer>& answers) {
  NBSIM_CHECK(rects.size() == nearest.size(), "a query batch needs one nearest depth per rectangle");
  answers.clear();
  if (rects.empty()) return;
  const std::uint64_t arrived = acquire_port();

  const NBufferUnitConfig& c = core_.config();
  std::uint64_t lookups = 0, update_texels = 0, bytes = 0;
  for (std::size_t i = 0; i < rects.size(); ++i) {
    answers.push_back(core_.query(rects[i], nearest[i]));
    const QueryAnswer& a = answers.back();
    lookups += static_cast<std::uint64_t>(a.lookups);
    update_texels += a.update.recomputed();
    bytes += a.bytes_read + a.update.bytes_read + a.update.bytes_written;
  }
  const std::uint64_t start = sim::local_cycles();
  const std::uint64_t update_n = sim::batch_cycles(update_texels, c.update_texels_per_cycle, c.update_latency_cycles);
  const std::uint64_t mem_done = channel_ && bytes ? channel_->transfer(start, bytes, client_) : start;
  label_with([&] { return fmt::format("{} queries, {} lookups, {} texels updated", rects.size(), lookups, update_texels); });
  work(update_n + sim::batch_cycles(lookups, c.lookups_per_cycle, c.lookup_latency_cycles));
  wait_until(mem_done, memory_stall_cycles_);
  update_cycles_ += update_n;
  query_cycles_ += sim::local_cycles() - arrived;

  port_busy_ = false;
  port_free_.notify();
}

UpdateWork NBufferUnit::depth_changed(const DepthImage& depth, const Rect& dirty) {
  return post(core_.depth_changed(depth, dirty));
}

UpdateWork NBufferUnit::depth_changed(std::span<const PixelWrite> writes) { return post(core_.depth_changed(writes)); }

UpdateWork NBufferUnit::depth_cleared(float depth) { return post(core_.depth_cleared(depth)); }

UpdateWork NBufferUnit::end_of_pass() { return post(core_.end_of_pass()); }

UpdateWork NBufferUnit::end_of_frame() { return post(core_.end_of_frame()); }

}  // namespace nbsim::nbuffer

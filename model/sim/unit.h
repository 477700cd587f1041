// The base of every SystemC unit wrapper: a module with a statistics group named after its place
// in the hierarchy ("gpu.depth") that counts the cycles it spends working. A unit's thread calls
// work(n) to spend n cycles; busy cycles and total cycles give its utilisation. When a run records a
// timeline (model/sim/timeline.h), each work(n) is one span on the unit's track.
//
// Timing granularity (config key gpu.quantum_cycles; model/sim/quantum.h). TLM-2.0 temporal
// decoupling: a global quantum and one tlm_utils::tlm_quantumkeeper per SystemC THREAD, not per
// unit, because the local time belongs to the thread that runs the work (the cull stage and the
// N-buffer unit's query port work on the command processor's thread, in primitive granularity on
// the raster unit's; the N-buffer update engine and each DelayLine have threads of their own).
// - Quantum 0 (the default): every helper below is the plain SystemC call; every work item waits.
// - work(n) adds n cycles to the thread's local time (SystemC time + the keeper's offset) and
//   waits only when the keeper says the local time reached the end of the quantum (the next
//   multiple of the quantum).
// - Every cycle the model computes is local time, sim::local_cycles(), never now_cycles():
//   memory request starts, completion and done cycles, DelayLine timestamps, timeline spans.
//   Waiting for such a completion (memory, a DelayLine's latency) is sim::spend_until().
// - A call that may block (a fifo read or write, a wait on an event) goes through sim::blocking():
//   the thread does not synchronise first; it resumes at the later of its local time and the time
//   the call returned. A fifo that has data (or room) does not block: no context switch at all.
// - A thread that waited for another thread's result moves its local time up to the producer's
//   local time of the result (sim::catch_up): the cull stage to the last draw or clear it heard
//   of, a query to the update engine's last batch, the engine to the last work posted to it.
// - Nothing functional depends on time: the units see the same work in the same order whatever
//   the quantum (fifos, and the cull stage waits for every result before it reads one), so every
//   count is the same and only cycles change (and the N-buffer engine's update_batches: a batch
//   is whatever was queued when the engine got free, a matter of timing). The cycle error: a
//   consumer may take a fifo item before the producer's local time of sending it, and the shared
//   memory channel serves requests in the order threads make them, not in local-time order; each
//   such error is below a quantum.
// - Timeline JSON spans are in local time; the VCD busy bits follow SystemC time, so they mean
//   little when decoupled.
// Quantum 1 goes through the keepers but synchronises after every work item: the same cycles as 0.
#pragma once

#include <deque>
#include <ostream>
#include <string>
#include <string_view>
#include <utility>

#include "model/sim/kernel.h"
#include "model/sim/quantum.h"
#include "model/sim/timeline.h"
#include "model/stats/stats.h"

namespace nbsim::sim {

class Unit : public sc_core::sc_module {
 public:
  Unit(const sc_core::sc_module_name& name, stats::Registry& registry)
      : sc_core::sc_module(name),
        stats_(registry.group(std::string(this->name()))),
        busy_(stats_.counter("busy_cycles", "cycles", "cycles this unit spent working")) {}

  // Reports this unit's spans to `timeline` on `track` (Timeline::attach_units calls it); null: none.
  void attach_timeline(Timeline* timeline, int track) noexcept { timeline_ = timeline, track_ = track; }

 protected:
  // Spends n cycles of work: advances the calling thread (its local time when decoupled) and
  // counts them as busy.
  void work(std::uint64_t n) {
    if (n == 0) {
      label_.clear();  // a label names the work it was set for, not the next one
      return;
    }
    busy_ += n;
    if (!timeline_) {
      spend(n);
      return;
    }
    const Timeline::Span span = timeline_->begin(track_, n);
    const std::string span_label = std::move(label_);  // taken now: another thread of the unit may set the next
    label_.clear();
    spend(n);
    timeline_->end(span, span_label);
  }
  // Names the next work() span on the timeline ("draw 12"); kept only when a timeline records.
  void label(std::string_view text) {
    if (timeline_) label_.assign(text);
  }
  // The same with a name built only when a timeline records: label_with([&] { return fmt::format(...); }).
  template <class MakeLabel>
  void label_with(MakeLabel&& make) {
    if (timeline_) label_ = make();
  }
  stats::Group& stats() noexcept { return stats_; }

 private:
  stats::Group& stats_;
  stats::Counter& busy_;
  Timeline* timeline_ = nullptr;
  int track_ = 0;
  std::string label_;  // of the next span; empty when no timeline records
};

// Cycles for `items` of work at `per_cycle` items a cycle after a fixed latency: the time a
// pipelined unit takes for one batch. Rounds up; 0 items cost nothing.
inline std::uint64_t batch_cycles(std::uint64_t items, double per_cycle, int latency_cycles) {
  if (items == 0) return 0;
  const double c = static_cast<double>(items) / per_cycle;
  auto whole = static_cast<std::uint64_t>(c);
  if (static_cast<double>(whole) < c) ++whole;
  return whole + static_cast<std::uint64_t>(latency_cycles);
}

// The output side of a pipelined unit: what the unit's thread sends leaves `latency` cycles later,
// while the thread goes on with the next item (latency overlaps; throughput is the unit's work()).
// Holds at most `capacity` items in flight; a full line stalls the sender (back-pressure).
template <class T>
class DelayLine : public sc_core::sc_module {
 public:
  sc_core::sc_fifo_out<T> out;

  DelayLine(const sc_core::sc_module_name& name, int capacity) : sc_core::sc_module(name), queue_("queue", capacity) {
    SC_HAS_PROCESS(DelayLine);
    SC_THREAD(run);
  }
  // Sends v so that it leaves `latency_cycles` from now (the sending thread's local time).
  void send(const T& v, std::uint64_t latency_cycles) {
    const Item item{v, local_cycles() + latency_cycles};
    blocking([&] { queue_.write(item); });
  }

 private:
  void run() {
    guard_thread([this] {
      for (;;) {
        const auto item = blocking([&] { return queue_.read(); });
        spend_until(item.second);
        blocking([&] { out.write(item.first); });
      }
    });
  }
  struct Item : std::pair<T, std::uint64_t> {
    using std::pair<T, std::uint64_t>::pair;
    friend std::ostream& operator<<(std::ostream& os, const Item&) { return os << "delayed item"; }
  };
  sc_core::sc_fifo<Item> queue_;
};

}  // namespace nbsim::sim

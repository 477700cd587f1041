// The base of every SystemC unit wrapper: a module with a statistics group named after its place
// in the hierarchy ("gpu.depth") that counts the cycles it spends working. A unit's thread calls
// work(n) to spend n cycles; busy cycles and total cycles give its utilisation. When a run records a
// timeline (model/sim/timeline.h), each work(n) is one span on the unit's track.
#pragma once

#include <deque>
#include <ostream>
#include <string>
#include <string_view>
#include <utility>

#include "model/sim/kernel.h"
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
  // Spends n cycles of work: advances this unit's thread and counts them as busy.
  void work(std::uint64_t n) {
    if (n == 0) {
      label_.clear();  // a label names the work it was set for, not the next one
      return;
    }
    busy_ += n;
    if (!timeline_) {
      wait(cycles(n));
      return;
    }
    const Timeline::Span span = timeline_->begin(track_, n);
    const std::string span_label = std::move(label_);  // taken now: another thread of the unit may set the next
    label_.clear();
    wait(cycles(n));
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
  // Sends v so that it leaves `latency_cycles` from now.
  void send(const T& v, std::uint64_t latency_cycles) { queue_.write({v, now_cycles() + latency_cycles}); }

 private:
  void run() {
    for (;;) {
      const auto item = queue_.read();
      const std::uint64_t now = now_cycles();
      if (item.second > now) wait(cycles(item.second - now));
      out.write(item.first);
    }
  }
  struct Item : std::pair<T, std::uint64_t> {
    using std::pair<T, std::uint64_t>::pair;
    friend std::ostream& operator<<(std::ostream& os, const Item&) { return os << "delayed item"; }
  };
  sc_core::sc_fifo<Item> queue_;
};

}  // namespace nbsim::sim

// The base of every SystemC unit wrapper: a module with a statistics group named after its place
// in the hierarchy ("gpu.depth") that counts the cycles it spends working. A unit's thread calls
// work(n) to spend n cycles; busy cycles and total cycles give its utilisation.
#pragma once

#include <deque>
#include <ostream>
#include <string>
#include <utility>

#include "model/sim/kernel.h"
#include "model/stats/stats.h"

namespace nbsim::sim {

class Unit : public sc_core::sc_module {
 public:
  Unit(const sc_core::sc_module_name& name, stats::Registry& registry)
      : sc_core::sc_module(name),
        stats_(registry.group(std::string(this->name()))),
        busy_(stats_.counter("busy_cycles", "cycles", "cycles this unit spent working")) {}

 protected:
  // Spends n cycles of work: advances this unit's thread and counts them as busy.
  void work(std::uint64_t n) {
    if (n == 0) return;
    busy_ += n;
    wait(cycles(n));
  }
  stats::Group& stats() noexcept { return stats_; }

 private:
  stats::Group& stats_;
  stats::Counter& busy_;
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

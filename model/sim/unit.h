// The base of every SystemC unit wrapper: a module with a statistics group named after its place
// in the hierarchy ("gpu.depth") that counts the cycles it spends working. A unit's thread calls
// work(n) to spend n cycles; busy cycles and total cycles give its utilisation.
#pragma once

#include <string>

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

}  // namespace nbsim::sim

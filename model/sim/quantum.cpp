// Temporal decoupling: the global quantum and the per-thread quantum keepers; see quantum.h.
#include "model/sim/quantum.h"

#include <unordered_map>

namespace nbsim::sim {

namespace detail {
bool decoupled = false;
}  // namespace detail

namespace {

struct Keepers {
  std::uint64_t quantum = 0;
  // One keeper per SystemC thread (its process object), made on first use. The model's threads
  // are all static (made at elaboration), so an entry never outlives its thread.
  std::unordered_map<const sc_core::sc_object*, tlm_utils::tlm_quantumkeeper> by_thread;
  const sc_core::sc_object* last_thread = nullptr;  // the thread asked last, and its keeper:
  tlm_utils::tlm_quantumkeeper* last_keeper = nullptr;  // a thread asks many times in a row
};

Keepers& keepers() {
  static Keepers k;
  return k;
}

std::uint64_t to_cycles(const sc_core::sc_time& t) { return static_cast<std::uint64_t>(t.to_seconds() * 1e9 + 0.5); }

}  // namespace

void set_quantum_cycles(std::uint64_t quantum) {
  Keepers& k = keepers();
  k.quantum = quantum;
  k.by_thread.clear();
  k.last_thread = nullptr, k.last_keeper = nullptr;
  detail::decoupled = quantum > 0;
  tlm_utils::tlm_quantumkeeper::set_global_quantum(quantum > 0 ? cycles(quantum) : sc_core::SC_ZERO_TIME);
}

std::uint64_t quantum_cycles() noexcept { return keepers().quantum; }

tlm_utils::tlm_quantumkeeper& keeper() {
  Keepers& k = keepers();
  const sc_core::sc_object* thread = sc_core::sc_get_current_process_handle().get_process_object();
  if (thread == k.last_thread && k.last_keeper) return *k.last_keeper;
  const auto [it, made] = k.by_thread.try_emplace(thread);
  if (made) it->second.reset();  // its first quantum ends at the next multiple of the global quantum
  k.last_thread = thread, k.last_keeper = &it->second;
  return it->second;
}

std::uint64_t local_cycles() {
  if (!decoupled()) return now_cycles();
  return now_cycles() + to_cycles(keeper().get_local_time());
}

void spend(std::uint64_t n) {
  if (!decoupled()) {
    sc_core::wait(cycles(n));
    return;
  }
  tlm_utils::tlm_quantumkeeper& k = keeper();
  k.inc(cycles(n));
  if (k.need_sync()) k.sync();
}

std::uint64_t spend_until(std::uint64_t cycle) {
  const std::uint64_t now = local_cycles();
  if (cycle <= now) return 0;
  spend(cycle - now);
  return cycle - now;
}

void catch_up(std::uint64_t cycle) {
  if (!decoupled()) return;
  const std::uint64_t now = local_cycles();
  if (cycle > now) spend(cycle - now);
}

void resumed(std::uint64_t before) {
  tlm_utils::tlm_quantumkeeper& k = keeper();
  const std::uint64_t now = now_cycles();
  k.reset();  // SystemC time may have moved on while the call blocked: the quantum ends later
  if (before > now) k.set(cycles(before - now));
  if (k.need_sync()) k.sync();
}

}  // namespace nbsim::sim

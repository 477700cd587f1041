// Temporal decoupling for the units' SystemC threads, as in TLM-2.0 loosely-timed models: a global
// quantum (tlm::tlm_global_quantum) and one tlm_utils::tlm_quantumkeeper per SystemC thread. The
// rules every unit follows are stated once, at the top of model/sim/unit.h. Without a quantum
// (gpu.quantum_cycles = 0, the default) every helper here is exactly the plain SystemC call it
// replaces, so the model's timing is the fully synchronised one.
#pragma once

#include <cstdint>
#include <type_traits>

#include "model/sim/kernel.h"  // <systemc> first: the keeper's header does not include it

#include <tlm_utils/tlm_quantumkeeper.h>

namespace nbsim::sim {

// Sets the global quantum in cycles; 0 turns decoupling off. Call before sc_start (the replay's
// top level does, from gpu.quantum_cycles). Forgets every thread's keeper.
void set_quantum_cycles(std::uint64_t quantum);
std::uint64_t quantum_cycles() noexcept;

namespace detail {
extern bool decoupled;  // quantum_cycles() > 0; read on every work item, so a plain flag
}  // namespace detail
inline bool decoupled() noexcept { return detail::decoupled; }

// The calling SystemC thread's quantum keeper, made on its first call. Decoupled runs only.
tlm_utils::tlm_quantumkeeper& keeper();

// The calling thread's local time in cycles: SystemC time plus how far the thread runs ahead of
// it. now_cycles() when not decoupled. Completion times are computed from it.
std::uint64_t local_cycles();

// Spends n cycles on the calling thread. Not decoupled: wait(n). Decoupled: the local time moves
// on by n, and the thread synchronises (waits its offset) once the keeper says the quantum is used.
void spend(std::uint64_t n);

// Spends the cycles from local_cycles() up to `cycle` (a completion time, say of a memory
// transfer); returns them, 0 when the thread is there already.
std::uint64_t spend_until(std::uint64_t cycle);

// Decoupled only: a result another thread produced at its local time `cycle` is not seen before
// that time, so the calling thread's local time moves up to `cycle`. Not decoupled it does nothing:
// the thread has waited for the event that brought the result, so its time is already there.
void catch_up(std::uint64_t cycle);

// After a call that may have blocked: the thread's local time is the later of the local time it
// had before the call (`before`) and the SystemC time it resumed at. Used by blocking().
void resumed(std::uint64_t before);

// Runs `call`, which may block (a fifo read or write, a wait on an event). Not decoupled: just the
// call. Decoupled: the thread does not synchronise first; it blocks with its offset kept aside and
// resumes at the later of its local time and the time the call returned (resumed()). A call that
// does not block (the fifo had data or room) costs no context switch at all.
template <class Call>
auto blocking(Call&& call) -> decltype(call()) {
  if (!decoupled()) return call();
  const std::uint64_t before = local_cycles();
  if constexpr (std::is_void_v<decltype(call())>) {
    call();
    resumed(before);
  } else {
    auto result = call();
    resumed(before);
    return result;
  }
}

}  // namespace nbsim::sim

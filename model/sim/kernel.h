// SystemC basics shared by every unit wrapper: the model's cycle, the current cycle, and a report
// handler that makes SystemC warnings and errors loud (they fail tests: docs/architecture.md, "Code
// conventions"). Only the thin wrappers include this header; the algorithm cores never include
// SystemC.
#pragma once

#include <systemc>

#include <cstdint>
#include <exception>

namespace nbsim::sim {

// One cycle of the model's clock is one nanosecond of SystemC time (a 1 GHz clock). Units count in
// cycles; nothing depends on the absolute frequency.
inline sc_core::sc_time cycles(std::uint64_t n) { return sc_core::sc_time(static_cast<double>(n), sc_core::SC_NS); }

// SystemC's time in cycles. Units compute with sim::local_cycles() (model/sim/quantum.h), which is
// this plus how far the calling thread runs ahead when gpu.quantum_cycles decouples it.
inline std::uint64_t now_cycles() {
  return static_cast<std::uint64_t>(sc_core::sc_time_stamp().to_seconds() * 1e9 + 0.5);
}

// SystemC warnings, errors and fatals throw std::runtime_error with SystemC's message instead of
// printing and carrying on; info messages are dropped. Call once before elaboration.
void install_report_handler();

// An exception escaping a unit's thread (a damaged trace read mid-run, say) would reach SystemC
// as an uncaught-exception error. Threads catch it and call thread_failed(), which keeps the first
// one and stops the simulation; the driver calls rethrow_thread_failure() right after sc_start
// returns, on the main thread (in sanitizer builds it also tells ASan that this is the main stack).
void thread_failed(std::exception_ptr e);
void rethrow_thread_failure();

// Runs the body of a unit's SC_THREAD so that an exception escaping it (a trace record the model
// cannot replay, a SystemC error) ends the run cleanly through thread_failed() instead of reaching
// SystemC, which terminates the process. Every unit thread's body goes through it. SystemC's own
// unwinding of a killed or reset thread passes through untouched.
template <class Body>
void guard_thread(Body&& body) {
  try {
    body();
  } catch (const sc_core::sc_unwind_exception&) {
    throw;
  } catch (...) {
    thread_failed(std::current_exception());
  }
}

}  // namespace nbsim::sim

// SystemC report handling; see kernel.h.
#include "model/sim/kernel.h"

#include <stdexcept>
#include <string>
#include <vector>

#if defined(__SANITIZE_ADDRESS__)
#include <pthread.h>
#include <sanitizer/common_interface_defs.h>
#endif

namespace nbsim::sim {

namespace {

void handler(const sc_core::sc_report& r, const sc_core::sc_actions&) {
  if (r.get_severity() == sc_core::SC_INFO) return;
  throw std::runtime_error(std::string("SystemC ") +
                           (r.get_severity() == sc_core::SC_WARNING ? "warning" : "error") + " " + r.get_msg_type() +
                           ": " + r.get_msg());
}

}  // namespace

void install_report_handler() { sc_core::sc_report_handler::set_handler(handler); }

namespace {
std::exception_ptr& failure() {
  static std::exception_ptr first;
  return first;
}

// Every thread process below `o` that is still alive, except the caller.
void collect_threads(sc_core::sc_object* o, std::vector<sc_core::sc_process_handle>& out) {
  const sc_core::sc_process_handle h(o);
  if (h.valid() && !h.terminated() && h != sc_core::sc_get_current_process_handle() &&
      (h.proc_kind() == sc_core::SC_THREAD_PROC_ || h.proc_kind() == sc_core::SC_CTHREAD_PROC_))
    out.push_back(h);
  for (sc_core::sc_object* child : o->get_child_objects()) collect_threads(child, out);
}

}  // namespace

void thread_failed(std::exception_ptr e) {
  const bool first = !failure();
  if (first) failure() = e;
  sc_core::sc_stop();
  if (!first || !sc_core::sc_is_running()) return;
  // The other units' threads wait in the middle of their work, holding batches and frames on their
  // own stacks, and SystemC never unwinds a suspended thread when the simulation ends: kill them
  // now, from this thread, so that their stacks unwind (sc_unwind_exception, which guard_thread
  // passes through) and free what they hold instead of leaking it at exit.
  std::vector<sc_core::sc_process_handle> alive;
  for (sc_core::sc_object* top : sc_core::sc_get_top_level_objects()) collect_threads(top, alive);
  for (auto& h : alive)
    if (!h.terminated()) h.kill();
}

namespace {
// Sanitizer builds only (docs/testing.md, "Sanitizers"). Debian's SystemC 2.3.4 tells AddressSanitizer about
// its coroutine switches in yield() but not in abort(), the switch a finishing thread makes, and
// never learns the main stack's bounds; after sc_start returns, ASan may still believe the main
// thread runs on a coroutine's stack. An exception thrown then (the rethrow below) is not given its
// stack clean-up ("ASan is ignoring requested __asan_handle_no_return", google/sanitizers#189),
// and the poisoned frames it unwound later read as false stack-use-after-scope reports. This
// declares one switch to the main thread's own stack, which is where the caller runs.
void main_stack_to_sanitizer() {
#if defined(__SANITIZE_ADDRESS__)
  pthread_attr_t attr;
  if (pthread_getattr_np(pthread_self(), &attr) != 0) return;
  void* bottom = nullptr;
  std::size_t size = 0;
  const bool known = pthread_attr_getstack(&attr, &bottom, &size) == 0;
  pthread_attr_destroy(&attr);
  if (!known) return;
  __sanitizer_start_switch_fiber(nullptr, bottom, size);
  __sanitizer_finish_switch_fiber(nullptr, nullptr, nullptr);
#endif
}
}  // namespace

void rethrow_thread_failure() {
  main_stack_to_sanitizer();
  if (std::exception_ptr e = failure()) {
    failure() = nullptr;
    std::rethrow_exception(e);
  }
}

}  // namespace nbsim::sim

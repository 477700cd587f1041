// SystemC report handling; see kernel.h.
#include "model/sim/kernel.h"

#include <stdexcept>
#include <string>

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
}  // namespace

void thread_failed(std::exception_ptr e) {
  if (!failure()) failure() = e;
  sc_core::sc_stop();
}

namespace {
// Sanitizer builds only (README "Sanitizers"). Debian's SystemC 2.3.4 tells AddressSanitizer about
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

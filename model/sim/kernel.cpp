// SystemC report handling; see kernel.h.
#include "model/sim/kernel.h"

#include <stdexcept>
#include <string>

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

void rethrow_thread_failure() {
  if (std::exception_ptr e = failure()) {
    failure() = nullptr;
    std::rethrow_exception(e);
  }
}

}  // namespace nbsim::sim

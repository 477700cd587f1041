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

}  // namespace nbsim::sim

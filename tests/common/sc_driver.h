// A SystemC thread that runs a script: the caller of a unit under test (a cull stage, a depth
// unit), for the unit suites that elaborate once per process.
#pragma once

#include <systemc>

#include <functional>
#include <utility>

namespace nbsim::testing {

struct ScriptDriver : sc_core::sc_module {
  std::function<void()> script;
  SC_HAS_PROCESS(ScriptDriver);
  ScriptDriver(const sc_core::sc_module_name& n, std::function<void()> s) : sc_core::sc_module(n), script(std::move(s)) {
    SC_THREAD(run);
  }
  void run() { script(); }
};

}  // namespace nbsim::testing

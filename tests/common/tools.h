// Whether a program the tests drive is installed (on PATH): tests that need a tool scripts/setup
// installs skip, naming the package, when it is missing, instead of failing for a reason that is
// not nbsim's.
#pragma once

#include <cstdlib>
#include <string>

namespace nbsim::testing {

inline bool have_program(const std::string& name) { return std::system(("command -v " + name + " > /dev/null 2>&1").c_str()) == 0; }

// apitrace's replayer for EGL contexts (Debian's apitrace package), which `nbsim capture apitrace` runs.
inline bool have_eglretrace() { return have_program("eglretrace"); }
// apitrace's recorder (the same package).
inline bool have_apitrace() { return have_program("apitrace"); }

}  // namespace nbsim::testing

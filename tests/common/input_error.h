// The message of the InputError a callable throws, for tests that check what a refusal says
// (ldi_test.cpp, registry_test.cpp and the config tests still carry their own copies).
#pragma once

#include <string>

#include "model/common/error.h"

namespace nbsim::testing {

// The message of the InputError that `f` throws ("" when it throws none).
template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return {};
}

}  // namespace nbsim::testing

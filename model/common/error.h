// The two kinds of failure in nbsim (gem5's fatal vs panic):
// - InputError: the user's fault (bad file, bad argument, bad config). Commands catch it, print its
//   message and exit with status 2.
// - NBSIM_CHECK: a broken internal invariant. That is a bug: print where and abort.
#pragma once

#include <stdexcept>
#include <string>

namespace nbsim {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

[[noreturn]] void panic(const char* file, int line, const char* condition, const std::string& message);

}  // namespace nbsim

#define NBSIM_CHECK(cond, msg)                               \
  do {                                                       \
    if (!(cond)) ::nbsim::panic(__FILE__, __LINE__, #cond, (msg)); \
  } while (false)

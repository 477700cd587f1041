// The command-line tests' table of refused arguments: each case runs `nbsim <prefix> <args>
// <suffix>` and must exit 2 with stderr naming the problem, print nothing on stdout and leave no
// file at `out` (when given). One loop for every command's table (capture, particles, shadows,
// bench), so a new check on refused input applies to all of them.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <initializer_list>
#include <string>

#include "tests/common/run_nbsim.h"

namespace nbsim::testing {

struct RefusedCase {
  const char* args;
  const char* message;  // a part of stderr
};

inline void expect_refused(const std::string& prefix, std::initializer_list<RefusedCase> cases, const std::string& suffix = "",
                           const std::filesystem::path& out = {}) {
  for (const RefusedCase& c : cases) {
    const CliResult r = run_nbsim(prefix + c.args + suffix);
    EXPECT_EQ(r.status, 2) << c.args << ": " << r.err;
    EXPECT_TRUE(has(r.err, c.message)) << c.args << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << c.args << " printed " << r.out;
    if (!out.empty()) {
      EXPECT_FALSE(std::filesystem::exists(out)) << c.args << " wrote a file";
      EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial")) << c.args << " left a partial file";
    }
  }
}

}  // namespace nbsim::testing

// GlContextSuite: a GoogleTest fixture base for tests that draw on llvmpipe: one headless GL
// context (traces/gl/context.h), made current before a suite's first test and destroyed after its
// last. A suite derives from it and adds nothing else it does not need.
#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "traces/gl/context.h"

namespace nbsim::testing {

class GlContextSuite : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { context_ = std::make_unique<gl::Context>(); }
  static void TearDownTestSuite() { context_.reset(); }
  static inline std::unique_ptr<gl::Context> context_;
};

}  // namespace nbsim::testing

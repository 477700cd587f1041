// GlSuite: a GoogleTest fixture for the comparisons against llvmpipe, one headless GL context and
// one `Gl` object (the test's programs and framebuffers) per suite; and Rng, the cases' numbers.
#pragma once

#include <gtest/gtest.h>

#include <random>

#include "traces/gl/context.h"

namespace nbsim::raster::testing {

// `Gl` has a default constructor (run with the context current) and `bool complete() const`.
template <class Gl>
class GlSuite : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    context_ = new gl::Context();
    gl_ = new Gl();
  }
  static void TearDownTestSuite() {
    delete gl_;
    delete context_;
    gl_ = nullptr;
    context_ = nullptr;
  }
  void SetUp() override { ASSERT_TRUE(gl_->complete()) << "the suite's framebuffers must be complete"; }
  static inline gl::Context* context_ = nullptr;
  static inline Gl* gl_ = nullptr;
};

// Deterministic numbers from a fixed-seed engine (its output is specified by the standard).
struct Rng {
  std::mt19937 e;
  explicit Rng(unsigned seed) : e(seed) {}
  float unit() { return static_cast<float>(e() >> 8) * (1.0f / 16777216.0f); }
  float range(float a, float b) { return a + (b - a) * unit(); }
  unsigned below(unsigned n) { return static_cast<unsigned>(e() % n); }
};

}  // namespace nbsim::raster::testing

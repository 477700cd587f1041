// glsl_active_text (traces/apitrace/glsl_active.h): the lines the GLSL preprocessor keeps, so that
// a discard in a dropped branch does not flag a draw, and every condition it cannot decide keeps
// its branches (never clearing a flag by a guess).
#include <gtest/gtest.h>

#include <string>

#include "traces/apitrace/glsl_active.h"

namespace nbsim::apitrace {
namespace {

bool keeps(const std::string& source, const std::string& token) { return glsl_active_text(source).find(token) != std::string::npos; }

TEST(GlslActiveTest, DroppedBranchesAreBlank) {
  const std::string alpha_test = "#version 150\n#if defined(USE_ALPHA_TEST)\n  if (a < 0.5) discard;\n#endif\nvoid main() {}\n";
  EXPECT_FALSE(keeps(alpha_test, "discard"));
  EXPECT_TRUE(keeps("#define USE_ALPHA_TEST\n" + alpha_test, "discard"));
  // #ifdef / #ifndef / #else / #elif with values, nested groups, #undef.
  const std::string nested =
      "#define MODE 2\n#ifdef A\nA_ONLY\n#elif MODE == 2\n#ifndef B\nMODE_TWO\n#else\nB_DEFINED\n#endif\n#else\nOTHER\n#endif\n";
  EXPECT_TRUE(keeps(nested, "MODE_TWO"));
  EXPECT_FALSE(keeps(nested, "A_ONLY"));
  EXPECT_FALSE(keeps(nested, "B_DEFINED"));
  EXPECT_FALSE(keeps(nested, "OTHER"));
  EXPECT_TRUE(keeps("#define A\n" + nested, "A_ONLY"));
  EXPECT_FALSE(keeps("#define A\n" + nested, "MODE_TWO"));
  EXPECT_FALSE(keeps("#define X 1\n#undef X\n#if X\nGONE\n#endif\n", "GONE"));
  // Arithmetic, logic and comparison.
  EXPECT_TRUE(keeps("#define N 3\n#if (N * 2 + 1) % 4 == 3 && !(N < 2) || 0\nYES\n#endif\n", "YES"));
  EXPECT_FALSE(keeps("#define N 3\n#if N >= 4 || N != 3\nNO\n#endif\n", "NO"));
  // A directive inside a dropped group changes nothing.
  EXPECT_TRUE(keeps("#if 0\n#define HIDE\n#endif\n#ifndef HIDE\nSHOWN\n#endif\n", "SHOWN"));
  // Comments and line continuations.
  EXPECT_FALSE(keeps("/* discard */ // discard\nvoid main() {}\n", "discard"));
  EXPECT_FALSE(keeps("#if 1 && \\\n 0\ndiscard;\n#endif\n", "discard"));
}

TEST(GlslActiveTest, UndecidableConditionsKeepEveryBranch) {
  // The compiler's own names (__VERSION__, GL_ES, extension macros), a function-like macro, an
  // unknown operator: both branches kept.
  for (const std::string cond : {"__VERSION__ >= 130", "defined(GL_ES)", "GL_ARB_gpu_shader5", "F(1)", "1 << 2"}) {
    SCOPED_TRACE(cond);
    const std::string s = "#define F(x) x\n#if " + cond + "\nFIRST\n#else\nSECOND\n#endif\n";
    EXPECT_TRUE(keeps(s, "FIRST"));
    EXPECT_TRUE(keeps(s, "SECOND"));
  }
  EXPECT_TRUE(keeps("#ifdef GL_ES\nES\n#endif\n", "ES"));
  EXPECT_TRUE(keeps("#ifndef GL_ES\nDESKTOP\n#endif\n", "DESKTOP"));
  // A decided branch after an undecided one is still dropped only when false.
  const std::string s = "#if __VERSION__ > 100\nA\n#elif 1\nB\n#elif 0\nC\n#else\nD\n#endif\n";
  EXPECT_TRUE(keeps(s, "A"));
  EXPECT_TRUE(keeps(s, "B"));
  EXPECT_FALSE(keeps(s, "C"));
  EXPECT_FALSE(keeps(s, "D")) << "#elif 1 was taken for certain";
  // What the source defines itself is known.
  EXPECT_FALSE(keeps("#define GL_MINE 0\n#if GL_MINE\nX\n#endif\n", "X"));
}

}  // namespace
}  // namespace nbsim::apitrace

// GlContextTest: the headless GL context (traces/gl/context.h) every capture and GL test opens:
// OpenGL 4.5 core on Mesa's llvmpipe through EGL's surfaceless platform, current on this thread,
// and closed cleanly, so that a process can open one after another.
#include "traces/gl/context.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace nbsim::gl {
namespace {

TEST(GlContextTest, OpensOpenGl45CoreOnLlvmpipeOneAfterAnother) {
  for (int i = 0; i < 2; ++i) {
    SCOPED_TRACE("context " + std::to_string(i));
    const Context context;
    const ContextInfo& info = context.info();
    int major = 0, minor = 0;
    ASSERT_EQ(std::sscanf(info.version.c_str(), "%d.%d", &major, &minor), 2) << info.version;
    EXPECT_GE(major * 10 + minor, 45) << "GL_VERSION " << info.version;
    EXPECT_NE(info.version.find("Core Profile"), std::string::npos) << info.version;
    EXPECT_NE(info.renderer.find("llvmpipe"), std::string::npos) << "the bit-exact comparisons assume llvmpipe: " << info.renderer;
    EXPECT_EQ(info.glsl_version.rfind("4.", 0), 0u) << info.glsl_version;
    EXPECT_FALSE(info.egl_version.empty());
    EXPECT_FALSE(info.vendor.empty());
  }
}

}  // namespace
}  // namespace nbsim::gl

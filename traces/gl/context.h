// A headless OpenGL 4.5 core context on Mesa (EGL surfaceless platform, llvmpipe), the base of the
// capture renderer. No display and no /dev/dri are needed; rendering goes to framebuffer objects.
#pragma once

#include <memory>
#include <string>

namespace nbsim::gl {

struct ContextInfo {
  std::string vendor, renderer, version, glsl_version, egl_version;
};

class Context {
 public:
  // Creates the context and makes it current on this thread. Throws std::runtime_error naming the
  // step (and the Debian package to install) when EGL or GL is missing.
  Context();
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  const ContextInfo& info() const noexcept { return info_; }

 private:
  struct Egl;
  std::unique_ptr<Egl> egl_;
  ContextInfo info_;
};

}  // namespace nbsim::gl

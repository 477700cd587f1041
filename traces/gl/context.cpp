// Headless EGL + OpenGL 4.5 core context on Mesa; see context.h.
#include "traces/gl/context.h"

#define EGL_EGLEXT_PROTOTYPES
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <fmt/format.h>

#include <stdexcept>

#if defined(__SANITIZE_ADDRESS__)
#include <dlfcn.h>
#include <link.h>

#include <cstring>
#endif

namespace nbsim::gl {

struct Context::Egl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
};

namespace {

[[noreturn]] void fail(const char* step) {
  throw std::runtime_error(fmt::format(
      "headless OpenGL is not available: {} failed (EGL error 0x{:04x}). nbsim needs Mesa's EGL and llvmpipe: "
      "apt-get install libegl-mesa0 libgl1-mesa-dri libegl1 libopengl0 (scripts/setup installs them)",
      step, static_cast<unsigned>(eglGetError())));
}

std::string gl_string(GLenum name) {
  const auto* s = reinterpret_cast<const char*>(glGetString(name));
  return s ? s : "";
}

#if defined(__SANITIZE_ADDRESS__)
// Sanitizer builds only: keeps Mesa's DRI driver (swrast_dri.so, llvmpipe) mapped to the end of the
// process. eglTerminate unloads it, and LeakSanitizer, which runs at exit, then shows the few
// hundred bytes the driver leaks as frames of "<unknown module>" that no suppression can name;
// pinned, they show the driver's frames and tests/sanitize/lsan.supp suppresses them by name.
void pin_dri_driver() {
  dl_iterate_phdr(
      [](dl_phdr_info* info, std::size_t, void*) {
        if (info->dlpi_name && std::strstr(info->dlpi_name, "_dri.so"))
          dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
        return 0;
      },
      nullptr);
}
#endif

}  // namespace

Context::Context() : egl_(std::make_unique<Egl>()) {
  auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!get_platform_display) fail("eglGetProcAddress(eglGetPlatformDisplayEXT)");
  egl_->display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (egl_->display == EGL_NO_DISPLAY) fail("eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA)");
  EGLint major = 0, minor = 0;
  if (!eglInitialize(egl_->display, &major, &minor)) fail("eglInitialize");
  if (!eglBindAPI(EGL_OPENGL_API)) fail("eglBindAPI(EGL_OPENGL_API)");
  const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                               EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  egl_->context = eglCreateContext(egl_->display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
  if (egl_->context == EGL_NO_CONTEXT) fail("eglCreateContext(OpenGL 4.5 core)");
  if (!eglMakeCurrent(egl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, egl_->context)) fail("eglMakeCurrent");
#if defined(__SANITIZE_ADDRESS__)
  pin_dri_driver();
#endif
  info_ = {gl_string(GL_VENDOR), gl_string(GL_RENDERER), gl_string(GL_VERSION),
           gl_string(0x8B8C /* GL_SHADING_LANGUAGE_VERSION */), fmt::format("{}.{}", major, minor)};
}

Context::~Context() {
  if (egl_->display != EGL_NO_DISPLAY) {
    eglMakeCurrent(egl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (egl_->context != EGL_NO_CONTEXT) eglDestroyContext(egl_->display, egl_->context);
    eglTerminate(egl_->display);
  }
}

}  // namespace nbsim::gl

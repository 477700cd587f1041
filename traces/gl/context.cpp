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

#include <sanitizer/asan_interface.h>

#include <cstring>

// Sanitizer builds only, in every program that opens a GL context: LeakSanitizer must not take the
// main thread's dynamic TLS blocks from its `__tls_get_addr` interceptor. Mesa's llvmpipe pulls in
// libLLVM-15 with dlopen, so its thread_locals live in a dynamic TLS block that glibc (>= 2.25)
// allocates with malloc, i.e. with ASan's allocator. GCC 12's runtime still guesses that block's
// bounds with a glibc 2.19 heuristic: a block that starts 16 bytes into a page is taken to follow a
// {size, start} header, so when ASan's heap happens to put it there the 16 bytes of ASan's own chunk
// header before it become the bounds, and the exit-time leak scan reads them as an address range and
// crashes ("Tracer caught signal 11", "DTLS 10 at 0x...207b-0x...317d" with
// LSAN_OPTIONS=verbosity=1:log_threads=1). Whether it happens depends only on the heap layout (the
// particles capture with --level-cap 3 hit it every time, and only at some output paths).
// google/sanitizers#1322; LLVM fixed it in 2023 (the allocator is asked for the block's bounds), GCC 12
// does not have the fix. With the interceptor off, the blocks are ordinary heap chunks that
// LeakSanitizer reaches through glibc's DTV, so what they point to still counts as reachable and
// leaks are still reported. The ASAN_OPTIONS environment variable is read after this.
extern "C" __attribute__((visibility("default"), used)) const char* __asan_default_options() {
  return "intercept_tls_get_addr=0";
}
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

// libnbsim_interpose.so: loaded with LD_PRELOAD into `eglretrace --headless` while it replays an
// apitrace trace, it records every draw's clip-space positions, GL state and samples passed, every
// depth clear, and each frame's depth image, into the raw recording of raw.h.
//
// How it sees GL: eglretrace dlopens libEGL and resolves every entry point by name, through dlsym
// or eglGetProcAddress, so the library defines dlsym and wraps what either returns for the names
// below; nothing else is touched. Its own GL calls go through pointers resolved the same way.
//
// How it captures a draw (the program's own draw, run once, unchanged):
// - every program is linked with transform feedback of gl_Position (glTransformFeedbackVaryings
//   before each glLinkProgram; when that link fails, the program is linked again without it and its
//   draws are recorded as Skip::NoPosition); a program that declares varyings of its own is left as
//   it is (Skip::OwnFeedback), unless gl_Position is its only one, which is what the library records;
// - around the draw: the library's own transform feedback object and buffer bound, queries of
//   samples passed, primitives generated and primitives written begun, transform feedback begun with
//   the primitive the last vertex stage emits, and everything restored after it;
// - the draw's state is read with glGet* just before it (viewport, scissor, depth range, depth,
//   cull, polygon offset and mode, stencil, clip control, the render target and its size).
// A draw it cannot capture is still run inside a samples-passed query when the program has none of
// its own open, and recorded with the reason (raw.h Skip). Features it does not handle (immediate
// mode, display lists, depth blits) are recorded by name once a frame (RawType::Unhandled).
//
// Frames end at eglSwapBuffers, or at the frame marker of a program without a window
// (raw.h kFrameMarker, a glDebugMessageInsert).
// Environment: NBSIM_IP_OUT (the recording's path, required), NBSIM_IP_FRAMES ("A:B", the frames
// recorded, inclusive; after B the library ends the recording and exits the process with status 0).
// One GL context at a time is assumed current per thread; the library's GL objects are made per
// context.
#include <EGL/egl.h>
#include <GL/glcorearb.h>
#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "traces/apitrace/glsl_active.h"
#include "traces/apitrace/raw.h"

// The compatibility profile's alpha test (not in the core profile's header).
#ifndef GL_ALPHA_TEST
#define GL_ALPHA_TEST 0x0BC0
#endif

namespace nbsim::apitrace {
namespace {

// ---- The real dlsym and eglGetProcAddress ------------------------------------------------------

using DlsymFn = void* (*)(void*, const char*);
using GetProcFn = void* (*)(const char*);

DlsymFn real_dlsym() {
  static DlsymFn f = [] {
    auto fn = reinterpret_cast<DlsymFn>(dlvsym(RTLD_NEXT, "dlsym", "GLIBC_2.34"));
    if (!fn) fn = reinterpret_cast<DlsymFn>(dlvsym(RTLD_NEXT, "dlsym", "GLIBC_2.2.5"));
    return fn;
  }();
  return f;
}

GetProcFn g_real_get_proc = nullptr;  // eglGetProcAddress, as the program resolved it

void* real_proc(const char* name) {
  if (g_real_get_proc) {
    if (void* p = g_real_get_proc(name)) return p;
  }
  return real_dlsym() ? real_dlsym()(RTLD_DEFAULT, name) : nullptr;
}

// ---- The recording -----------------------------------------------------------------------------

class Recording {
 public:
  Recording() {
    if (const char* frames = std::getenv("NBSIM_IP_FRAMES")) {
      unsigned a = 0, b = 0;
      if (std::sscanf(frames, "%u:%u", &a, &b) == 2 && a <= b) first_ = a, last_ = b, limited_ = true;
    }
    const char* out = std::getenv("NBSIM_IP_OUT");
    if (!out || !*out) return;
    file_ = std::fopen(out, "wb");
    if (!file_) return;
    std::setvbuf(file_, nullptr, _IOFBF, 1 << 20);
    FileHead h{};
    std::memcpy(h.magic, kRawMagic, sizeof h.magic);
    h.version = kRawVersion;
    h.first_frame = first_;
    h.last_frame = last_;
    std::fwrite(&h, sizeof h, 1, file_);
  }
  ~Recording() { finish(); }

  bool on() const noexcept { return file_ != nullptr; }
  bool recording() const noexcept { return file_ && frame_ >= first_ && frame_ <= last_; }
  std::uint32_t frame() const noexcept { return frame_; }
  std::uint32_t next_draw() noexcept { return draws_++; }
  std::uint32_t draws() const noexcept { return draws_; }

  void put(RawType type, const void* head, std::size_t head_bytes, const void* tail = nullptr, std::size_t tail_bytes = 0) {
    if (!file_) return;
    const RecordHead r{static_cast<std::uint32_t>(type), static_cast<std::uint32_t>(head_bytes + tail_bytes)};
    std::fwrite(&r, sizeof r, 1, file_);
    if (head_bytes) std::fwrite(head, 1, head_bytes, file_);
    if (tail_bytes) std::fwrite(tail, 1, tail_bytes, file_);
  }
  void unhandled(const char* name) {
    if (!recording()) return;
    auto [it, added] = unhandled_.try_emplace(name, 0u);
    if (added) unhandled_first_[name] = draws_;
    ++it->second;
  }
  // The frame's end: its unhandled features, then the frame record; the recording ends after the last.
  void end_frame(const FrameHead& f, const float* depth) {
    if (recording()) {
      for (const auto& [name, count] : unhandled_) {
        const UnhandledHead u{frame_, unhandled_first_[name], count, static_cast<std::uint32_t>(name.size())};
        put(RawType::Unhandled, &u, sizeof u, name.data(), name.size());
      }
      const std::size_t n = f.has_depth ? static_cast<std::size_t>(f.width) * static_cast<std::size_t>(f.height) : 0;
      put(RawType::Frame, &f, sizeof f, depth, n * sizeof(float));
      std::fflush(file_);
    }
    unhandled_.clear();
    unhandled_first_.clear();
    draws_ = 0;
    ++frame_;
    if (limited_ && frame_ > last_) {
      finish();
      _exit(0);  // the frames asked for are replayed: the rest of the trace is not
    }
  }
  void finish() {
    if (!file_) return;
    put(RawType::End, nullptr, 0);
    std::fclose(file_);
    file_ = nullptr;
  }

 private:
  std::FILE* file_ = nullptr;
  std::uint32_t first_ = 0, last_ = 0xFFFFFFFFu;
  bool limited_ = false;  // NBSIM_IP_FRAMES given: the process ends after frame last_
  std::uint32_t frame_ = 0, draws_ = 0;
  std::map<std::string, std::uint32_t> unhandled_, unhandled_first_;
};

Recording& recording() {
  static Recording r;
  return r;
}

// ---- GL entry points the library calls itself --------------------------------------------------

#define NBSIM_GL_FUNCTIONS(X)                                                                          \
  X(PFNGLGETINTEGERVPROC, glGetIntegerv)                                                               \
  X(PFNGLGETBOOLEANVPROC, glGetBooleanv)                                                               \
  X(PFNGLGETFLOATVPROC, glGetFloatv)                                                                   \
  X(PFNGLGETDOUBLEVPROC, glGetDoublev)                                                                 \
  X(PFNGLISENABLEDPROC, glIsEnabled)                                                                   \
  X(PFNGLGETERRORPROC, glGetError)                                                                     \
  X(PFNGLGETSTRINGPROC, glGetString)                                                                   \
  X(PFNGLGETQUERYIVPROC, glGetQueryiv)                                                                 \
  X(PFNGLGENQUERIESPROC, glGenQueries)                                                                 \
  X(PFNGLBEGINQUERYPROC, glBeginQuery)                                                                 \
  X(PFNGLENDQUERYPROC, glEndQuery)                                                                     \
  X(PFNGLGETQUERYOBJECTUI64VPROC, glGetQueryObjectui64v)                                               \
  X(PFNGLGENTRANSFORMFEEDBACKSPROC, glGenTransformFeedbacks)                                           \
  X(PFNGLBINDTRANSFORMFEEDBACKPROC, glBindTransformFeedback)                                           \
  X(PFNGLBEGINTRANSFORMFEEDBACKPROC, glBeginTransformFeedback)                                         \
  X(PFNGLENDTRANSFORMFEEDBACKPROC, glEndTransformFeedback)                                             \
  X(PFNGLCREATEBUFFERSPROC, glCreateBuffers)                                                           \
  X(PFNGLNAMEDBUFFERDATAPROC, glNamedBufferData)                                                       \
  X(PFNGLGETNAMEDBUFFERSUBDATAPROC, glGetNamedBufferSubData)                                           \
  X(PFNGLBINDBUFFERPROC, glBindBuffer)                                                                 \
  X(PFNGLBINDBUFFERBASEPROC, glBindBufferBase)                                                         \
  X(PFNGLTRANSFORMFEEDBACKVARYINGSPROC, glTransformFeedbackVaryings)                                   \
  X(PFNGLGETPROGRAMIVPROC, glGetProgramiv)                                                             \
  X(PFNGLGETATTACHEDSHADERSPROC, glGetAttachedShaders)                                                 \
  X(PFNGLGETSHADERIVPROC, glGetShaderiv)                                                               \
  X(PFNGLBINDFRAMEBUFFERPROC, glBindFramebuffer)                                                       \
  X(PFNGLGETNAMEDFRAMEBUFFERATTACHMENTPARAMETERIVPROC, glGetNamedFramebufferAttachmentParameteriv)     \
  X(PFNGLGETNAMEDFRAMEBUFFERPARAMETERIVPROC, glGetNamedFramebufferParameteriv)                         \
  X(PFNGLGETTEXTURELEVELPARAMETERIVPROC, glGetTextureLevelParameteriv)                                 \
  X(PFNGLGETNAMEDRENDERBUFFERPARAMETERIVPROC, glGetNamedRenderbufferParameteriv)                       \
  X(PFNGLREADPIXELSPROC, glReadPixels)                                                                 \
  X(PFNGLPIXELSTOREIPROC, glPixelStorei)                                                               \
  X(PFNGLCREATESHADERPROC, glCreateShader)                                                             \
  X(PFNGLSHADERSOURCEPROC, glShaderSource)                                                             \
  X(PFNGLCOMPILESHADERPROC, glCompileShader)                                                           \
  X(PFNGLCREATEPROGRAMPROC, glCreateProgram)                                                           \
  X(PFNGLATTACHSHADERPROC, glAttachShader)                                                             \
  X(PFNGLDELETESHADERPROC, glDeleteShader)                                                             \
  X(PFNGLLINKPROGRAMPROC, glLinkProgram)                                                               \
  X(PFNGLUSEPROGRAMPROC, glUseProgram)                                                                 \
  X(PFNGLENABLEPROC, glEnable)                                                                         \
  X(PFNGLDISABLEPROC, glDisable)

struct Gl {
#define NBSIM_GL_MEMBER(type, name) type name = nullptr;
  NBSIM_GL_FUNCTIONS(NBSIM_GL_MEMBER)
#undef NBSIM_GL_MEMBER
  bool loaded = false, complete = false;
  void load() {
    if (loaded) return;
    loaded = true;
    complete = true;
#define NBSIM_GL_LOAD(type, name)                      \
  name = reinterpret_cast<type>(real_proc(#name));     \
  if (!name) complete = false;
    NBSIM_GL_FUNCTIONS(NBSIM_GL_LOAD)
#undef NBSIM_GL_LOAD
  }
};

Gl& gl() {
  static Gl g;
  g.load();
  return g;
}

// The context's GL strings, recorded once as notes; an OpenGL ES context (no samples-passed query)
// turns capture off, and the note says why.
void note_context() {
  static bool noted = false;
  Gl& g = gl();
  if (noted || !g.glGetString) return;
  const auto text = [&](GLenum e) {
    const GLubyte* s = g.glGetString(e);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string();
  };
  const std::string version = text(GL_VERSION);
  if (version.empty()) return;  // no context current yet
  noted = true;
  for (const auto& [key, value] : {std::pair{"GL_RENDERER", text(GL_RENDERER)}, std::pair{"GL_VERSION", version}, std::pair{"GL_VENDOR", text(GL_VENDOR)}}) {
    const std::string note = std::string(key) + "=" + value;
    recording().put(RawType::Note, note.data(), note.size());
  }
  if (version.rfind("OpenGL ES", 0) == 0) g.complete = false;
}

using GetCurrentContextFn = EGLContext (*)();
using GetCurrentSurfaceFn = EGLSurface (*)(EGLint);
using GetCurrentDisplayFn = EGLDisplay (*)();
using QuerySurfaceFn = EGLBoolean (*)(EGLDisplay, EGLSurface, EGLint, EGLint*);

// ---- What the library knows of programs and shaders ----------------------------------------------

struct ProgramInfo {
  bool position = false;       // linked with transform feedback of gl_Position
  bool own_varyings = false;   // the program declared varyings itself
  bool discards = false, writes_depth = false;
  GLenum primitive = 0;        // 0: from the draw mode; else what the geometry or tessellation stage emits
  GLint gs_vertices = 0;       // the geometry stage's most vertices out an invocation (times its invocations)
  bool tessellation = false;
};

struct ContextObjects {
  GLuint feedback = 0, buffer = 0, samples = 0, generated = 0, written = 0;
  std::size_t capacity = 0;
  // The fixed-function capture pass's program (gl_Position = ftransform(), its only varying), made
  // once per context when it is a compatibility one; tried: made or found impossible.
  GLuint ftransform = 0;
  bool ftransform_tried = false;
};

std::mutex g_mutex;
std::map<GLuint, std::string> g_shader_source;   // fragment and other shaders' source, as given
std::map<GLuint, ProgramInfo> g_programs;
std::set<GLuint> g_own_varyings;                 // programs given varyings by the program itself
std::map<void*, ContextObjects> g_contexts;
std::map<GLuint, std::uint64_t> g_frame_samples;  // samples passed per framebuffer this frame

bool has_token(const std::string& s, std::string_view token) {
  const auto word = [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_'; };
  for (std::size_t at = s.find(token); at != std::string::npos; at = s.find(token, at + 1)) {
    const bool before = at == 0 || !word(s[at - 1]);
    const bool after = at + token.size() >= s.size() || !word(s[at + token.size()]);
    if (before && after) return true;
  }
  return false;
}

ContextObjects& context_objects() {
  static GetCurrentContextFn current = reinterpret_cast<GetCurrentContextFn>(real_proc("eglGetCurrentContext"));
  void* key = current ? current() : nullptr;
  ContextObjects& o = g_contexts[key];
  if (o.feedback == 0) {
    Gl& g = gl();
    g.glGenTransformFeedbacks(1, &o.feedback);
    g.glCreateBuffers(1, &o.buffer);
    g.glGenQueries(1, &o.samples);
    g.glGenQueries(1, &o.generated);
    g.glGenQueries(1, &o.written);
  }
  return o;
}

GLint get_int(GLenum e) {
  GLint v[4] = {};
  gl().glGetIntegerv(e, v);
  return v[0];
}

bool compatibility_profile() {
  GLint mask = 0;
  gl().glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &mask);
  return (mask & GL_CONTEXT_COMPATIBILITY_PROFILE_BIT) != 0 || (mask & GL_CONTEXT_CORE_PROFILE_BIT) == 0;
}

// The fixed-function capture pass's program of the current context, or 0 (a core context, or a
// compile or link that failed). ftransform() is invariant with the fixed-function transform, so the
// positions it feeds back are the ones the fixed-function draw rasterizes.
GLuint ftransform_program(ContextObjects& o) {
  if (o.ftransform_tried) return o.ftransform;
  o.ftransform_tried = true;
  if (!compatibility_profile()) return 0;
  Gl& g = gl();
  static const char* kSource = "#version 120\nvoid main() { gl_Position = ftransform(); }\n";
  const GLuint vs = g.glCreateShader(GL_VERTEX_SHADER);
  g.glShaderSource(vs, 1, &kSource, nullptr);
  g.glCompileShader(vs);
  GLint ok = 0;
  g.glGetShaderiv(vs, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    g.glDeleteShader(vs);
    return 0;
  }
  const GLuint program = g.glCreateProgram();
  g.glAttachShader(program, vs);
  const GLchar* position = "gl_Position";
  g.glTransformFeedbackVaryings(program, 1, &position, GL_INTERLEAVED_ATTRIBS);
  g.glLinkProgram(program);
  g.glDeleteShader(vs);
  g.glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok) o.ftransform = program;
  return o.ftransform;
}

// A render target as the library reads it: its size (the depth attachment's, else the first colour
// one's, or the surface's) and its depth buffer's bits and component type.
struct Target {
  std::int32_t width = 0, height = 0;
  std::uint32_t depth_bits = 0;
  bool depth_float = false;
};

Target target_of(GLuint fb) {
  Gl& g = gl();
  Target t;
  GLint bits = 0, component = 0;
  if (fb == 0) {
    static auto surface = reinterpret_cast<GetCurrentSurfaceFn>(real_proc("eglGetCurrentSurface"));
    static auto display = reinterpret_cast<GetCurrentDisplayFn>(real_proc("eglGetCurrentDisplay"));
    static auto query = reinterpret_cast<QuerySurfaceFn>(real_proc("eglQuerySurface"));
    EGLint ew = 0, eh = 0;
    if (surface && display && query && surface(EGL_DRAW) != EGL_NO_SURFACE) {
      query(display(), surface(EGL_DRAW), EGL_WIDTH, &ew);
      query(display(), surface(EGL_DRAW), EGL_HEIGHT, &eh);
    }
    t.width = ew, t.height = eh;
    g.glGetNamedFramebufferAttachmentParameteriv(0, GL_DEPTH, GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE, &bits);
    if (bits > 0) g.glGetNamedFramebufferAttachmentParameteriv(0, GL_DEPTH, GL_FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE, &component);
  } else {
    for (const GLenum attachment : {GLenum(GL_DEPTH_ATTACHMENT), GLenum(GL_COLOR_ATTACHMENT0)}) {
      GLint type = GL_NONE, name = 0, level = 0;
      g.glGetNamedFramebufferAttachmentParameteriv(fb, attachment, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &type);
      if (type == GL_NONE) continue;
      g.glGetNamedFramebufferAttachmentParameteriv(fb, attachment, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME, &name);
      if (type == GL_TEXTURE) {
        g.glGetNamedFramebufferAttachmentParameteriv(fb, attachment, GL_FRAMEBUFFER_ATTACHMENT_TEXTURE_LEVEL, &level);
        g.glGetTextureLevelParameteriv(static_cast<GLuint>(name), level, GL_TEXTURE_WIDTH, &t.width);
        g.glGetTextureLevelParameteriv(static_cast<GLuint>(name), level, GL_TEXTURE_HEIGHT, &t.height);
      } else if (type == GL_RENDERBUFFER) {
        g.glGetNamedRenderbufferParameteriv(static_cast<GLuint>(name), GL_RENDERBUFFER_WIDTH, &t.width);
        g.glGetNamedRenderbufferParameteriv(static_cast<GLuint>(name), GL_RENDERBUFFER_HEIGHT, &t.height);
      }
      if (attachment == GL_DEPTH_ATTACHMENT) {
        g.glGetNamedFramebufferAttachmentParameteriv(fb, attachment, GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE, &bits);
        g.glGetNamedFramebufferAttachmentParameteriv(fb, attachment, GL_FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE, &component);
      }
      break;
    }
  }
  t.depth_bits = static_cast<std::uint32_t>(std::max(bits, 0));
  t.depth_float = component == GL_FLOAT;
  return t;
}

// Reads the depth of framebuffer `fb` (width x height, y up) into `out`, the program's read state
// restored; false when GL refused.
bool read_depth(GLuint fb, const Target& t, std::vector<float>& out) {
  Gl& g = gl();
  if (t.depth_bits == 0 || t.width <= 0 || t.height <= 0) return false;
  const GLint read_fb = get_int(GL_READ_FRAMEBUFFER_BINDING), pack_buffer = get_int(GL_PIXEL_PACK_BUFFER_BINDING);
  const GLint alignment = get_int(GL_PACK_ALIGNMENT), row = get_int(GL_PACK_ROW_LENGTH);
  const GLint skip_rows = get_int(GL_PACK_SKIP_ROWS), skip_pixels = get_int(GL_PACK_SKIP_PIXELS);
  g.glBindFramebuffer(GL_READ_FRAMEBUFFER, fb);
  g.glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  g.glPixelStorei(GL_PACK_ALIGNMENT, 4);
  g.glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  g.glPixelStorei(GL_PACK_SKIP_ROWS, 0);
  g.glPixelStorei(GL_PACK_SKIP_PIXELS, 0);
  while (g.glGetError() != GL_NO_ERROR) {
  }
  out.resize(static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height));
  g.glReadPixels(0, 0, t.width, t.height, GL_DEPTH_COMPONENT, GL_FLOAT, out.data());
  const bool ok = g.glGetError() == GL_NO_ERROR;
  g.glBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<GLuint>(read_fb));
  g.glBindBuffer(GL_PIXEL_PACK_BUFFER, static_cast<GLuint>(pack_buffer));
  g.glPixelStorei(GL_PACK_ALIGNMENT, alignment);
  g.glPixelStorei(GL_PACK_ROW_LENGTH, row);
  g.glPixelStorei(GL_PACK_SKIP_ROWS, skip_rows);
  g.glPixelStorei(GL_PACK_SKIP_PIXELS, skip_pixels);
  return ok;
}

void read_state(DrawHead& d) {
  Gl& g = gl();
  const auto on = [&](GLenum e, std::uint32_t flag) {
    if (g.glIsEnabled(e)) d.flags |= flag;
  };
  on(GL_DEPTH_TEST, kDepthTest);
  on(GL_CULL_FACE, kCullFace);
  on(GL_POLYGON_OFFSET_FILL, kPolygonOffsetFill);
  on(GL_SCISSOR_TEST, kScissor);
  on(GL_STENCIL_TEST, kStencilTest);
  on(GL_DEPTH_CLAMP, kDepthClamp);
  on(GL_RASTERIZER_DISCARD, kRasterizerDiscard);
  const bool compat = compatibility_profile();
  if (compat) on(GL_ALPHA_TEST, kAlphaTest);
  GLboolean b[4] = {};
  g.glGetBooleanv(GL_DEPTH_WRITEMASK, b);
  if (b[0]) d.flags |= kDepthMask;
  g.glGetBooleanv(GL_COLOR_WRITEMASK, b);
  if (b[0] || b[1] || b[2] || b[3]) d.flags |= kColorWrite;
  if (get_int(GL_FRONT_FACE) == GL_CCW) d.flags |= kFrontCcw;
  if (get_int(GL_CLIP_DEPTH_MODE) == GL_ZERO_TO_ONE) d.flags |= kClipZeroToOne;
  GLint poly[2] = {GL_FILL, GL_FILL};
  g.glGetIntegerv(GL_POLYGON_MODE, poly);
  d.polygon_mode = static_cast<std::uint32_t>(poly[0]);
  if (poly[0] != GL_FILL || (compat && poly[1] != GL_FILL)) d.flags |= kPolygonModeNotFill;
  g.glGetIntegerv(GL_VIEWPORT, d.viewport);
  g.glGetIntegerv(GL_SCISSOR_BOX, d.scissor);
  g.glGetDoublev(GL_DEPTH_RANGE, d.depth_range);
  d.depth_func = static_cast<std::uint32_t>(get_int(GL_DEPTH_FUNC));
  d.cull_mode = static_cast<std::uint32_t>(get_int(GL_CULL_FACE_MODE));
  g.glGetFloatv(GL_POLYGON_OFFSET_FACTOR, &d.offset_factor);
  g.glGetFloatv(GL_POLYGON_OFFSET_UNITS, &d.offset_units);
  d.offset_clamp = 0.0f;
  g.glGetFloatv(GL_POINT_SIZE, &d.point_size);
  d.program = static_cast<std::uint32_t>(get_int(GL_CURRENT_PROGRAM));
  const GLenum names[2][7] = {{GL_STENCIL_FUNC, GL_STENCIL_VALUE_MASK, GL_STENCIL_WRITEMASK, GL_STENCIL_FAIL, GL_STENCIL_PASS_DEPTH_FAIL,
                               GL_STENCIL_PASS_DEPTH_PASS, GL_STENCIL_REF},
                              {GL_STENCIL_BACK_FUNC, GL_STENCIL_BACK_VALUE_MASK, GL_STENCIL_BACK_WRITEMASK, GL_STENCIL_BACK_FAIL,
                               GL_STENCIL_BACK_PASS_DEPTH_FAIL, GL_STENCIL_BACK_PASS_DEPTH_PASS, GL_STENCIL_BACK_REF}};
  for (int f = 0; f < 2; ++f) {
    StencilFaceRaw& s = d.stencil[f];
    s.func = static_cast<std::uint32_t>(get_int(names[f][0]));
    s.value_mask = static_cast<std::uint32_t>(get_int(names[f][1]));
    s.write_mask = static_cast<std::uint32_t>(get_int(names[f][2]));
    s.fail = static_cast<std::uint32_t>(get_int(names[f][3]));
    s.depth_fail = static_cast<std::uint32_t>(get_int(names[f][4]));
    s.pass = static_cast<std::uint32_t>(get_int(names[f][5]));
    s.ref = get_int(names[f][6]);
  }
  d.framebuffer = static_cast<std::uint32_t>(get_int(GL_DRAW_FRAMEBUFFER_BINDING));
  const Target t = target_of(d.framebuffer);
  d.target_width = t.width, d.target_height = t.height;
  d.depth_bits = t.depth_bits;
  d.depth_float = t.depth_float ? 1 : 0;
  if (get_int(GL_SAMPLES) > 1) d.flags |= kMultisample;
  static const GLint clip_distances = std::min(get_int(GL_MAX_CLIP_DISTANCES), 32);
  for (GLint i = 0; i < clip_distances; ++i)
    if (g.glIsEnabled(static_cast<GLenum>(GL_CLIP_DISTANCE0 + i))) {
      d.flags |= kClipDistance;
      break;
    }
}

// The primitive transform feedback records for a draw of `mode` by the program.
GLenum feedback_primitive(GLenum mode, const ProgramInfo* p) {
  if (p && p->primitive != 0) return p->primitive;
  switch (mode) {
    case GL_POINTS: return GL_POINTS;
    case GL_LINES:
    case GL_LINE_STRIP:
    case GL_LINE_LOOP:
    case GL_LINES_ADJACENCY:
    case GL_LINE_STRIP_ADJACENCY: return GL_LINES;
    default: return GL_TRIANGLES;
  }
}

// At most how many vertices transform feedback writes for `vertices` in, of `mode`.
std::size_t vertices_bound(GLenum primitive, std::size_t vertices, const ProgramInfo* p) {
  std::size_t out = primitive == GL_POINTS ? vertices : primitive == GL_LINES ? 2 * vertices : 3 * vertices;
  if (p && p->gs_vertices > 0) out = vertices * static_cast<std::size_t>(p->gs_vertices) * 3;
  if (p && p->tessellation) out = vertices * 64 * 3;
  return std::max<std::size_t>(out, 3);
}

// Whether a model that rasterizes triangles with the render target's viewport, depth range and
// depth format can be expected to redo the draw's depth exactly: a captured triangle draw with no
// discard, alpha test, written depth, polygon offset, line or point fill, multisampling, partial
// viewport or depth range, or scissor inside the target. Any other draw that may write depth gets
// its depth change recorded (RawType::Delta), so that the draws after it can still be compared.
bool plain_draw(const DrawHead& d, Skip skip, GLenum primitive) {
  if (skip != Skip::None || primitive != GL_TRIANGLES) return false;
  if (d.flags & (kDiscards | kWritesDepth | kAlphaTest | kPolygonModeNotFill | kMultisample | kClipDistance)) return false;
  if ((d.flags & kPolygonOffsetFill) && (d.offset_factor != 0.0f || d.offset_units != 0.0f)) return false;
  if (d.viewport[0] != 0 || d.viewport[1] != 0 || d.viewport[2] != d.target_width || d.viewport[3] != d.target_height) return false;
  if (d.depth_range[0] != 0.0 || d.depth_range[1] != 1.0) return false;
  if ((d.flags & kScissor) &&
      (d.scissor[0] > 0 || d.scissor[1] > 0 || d.scissor[0] + d.scissor[2] < d.target_width || d.scissor[1] + d.scissor[3] < d.target_height))
    return false;
  return d.depth_bits == 24 || (d.depth_bits == 32 && d.depth_float);
}

bool own_query_open() {
  Gl& g = gl();
  for (const GLenum t : {GLenum(GL_SAMPLES_PASSED), GLenum(GL_ANY_SAMPLES_PASSED), GLenum(GL_ANY_SAMPLES_PASSED_CONSERVATIVE),
                         GLenum(GL_PRIMITIVES_GENERATED), GLenum(GL_TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN)}) {
    GLint id = 0;
    g.glGetQueryiv(t, GL_CURRENT_QUERY, &id);
    if (id != 0) return true;
  }
  return false;
}

// Runs one draw call (`run`) with `vertices` vertices in (times instances) and records it.
template <class Run>
void record_draw(DrawCall call, GLenum mode, std::size_t vertices, bool indirect, Run&& run) {
  Recording& rec = recording();
  if (rec.recording()) note_context();
  if (!rec.recording() || !gl().complete) {
    run();
    return;
  }
  std::lock_guard lock(g_mutex);
  Gl& g = gl();
  DrawHead d{};
  d.frame = rec.frame();
  d.index = rec.next_draw();
  d.call = static_cast<std::uint32_t>(call);
  d.mode = mode;
  read_state(d);
  const ProgramInfo* p = nullptr;
  if (d.program != 0) {
    const auto it = g_programs.find(d.program);
    if (it != g_programs.end()) p = &it->second;
  }
  if (p && p->discards) d.flags |= kDiscards;
  if (p && p->writes_depth) d.flags |= kWritesDepth;
  Skip skip = Skip::None;
  GLboolean feedback_active = GL_FALSE;
  g.glGetBooleanv(GL_TRANSFORM_FEEDBACK_ACTIVE, &feedback_active);
  const bool query_open = own_query_open();
  if (d.program == 0) skip = get_int(GL_PROGRAM_PIPELINE_BINDING) != 0 ? Skip::SeparablePipeline : Skip::FixedFunction;
  else if (!p) skip = Skip::SeparablePipeline;
  else if (p->own_varyings || feedback_active) skip = Skip::OwnFeedback;
  else if (!p->position) skip = Skip::NoPosition;
  if (skip == Skip::None && query_open) skip = Skip::OwnQuery;
  if (skip == Skip::None && indirect) skip = Skip::Indirect;
  ContextObjects& o = context_objects();
  // A fixed-function draw is captured by a pass of its own before it: the same draw with the
  // ftransform program, its rasterization discarded, under transform feedback.
  GLuint fixed_function = 0;
  if (skip == Skip::FixedFunction && !query_open && !feedback_active && !indirect) {
    fixed_function = ftransform_program(o);
    if (fixed_function != 0) skip = Skip::None;
  }
  d.skipped = static_cast<std::uint32_t>(skip);
  std::vector<float> positions;
  // GL writes depth only with the depth test on.
  const bool may_write = (d.flags & kDepthTest) && (d.flags & kDepthMask) && !(d.flags & kRasterizerDiscard) && d.depth_bits > 0;
  std::vector<float> before;
  Target target;
  if (may_write && !plain_draw(d, skip, feedback_primitive(mode, p))) {
    target = target_of(d.framebuffer);
    if (!read_depth(d.framebuffer, target, before)) before.clear();
  }
  if (skip != Skip::None) {
    if (!query_open) g.glBeginQuery(GL_SAMPLES_PASSED, o.samples);
    run();
    if (!query_open) {
      g.glEndQuery(GL_SAMPLES_PASSED);
      GLuint64 samples = 0;
      g.glGetQueryObjectui64v(o.samples, GL_QUERY_RESULT, &samples);
      d.samples_passed = samples;
    }
  } else {
    const GLenum primitive = feedback_primitive(mode, p);
    d.primitive = primitive;
    const std::size_t bytes = vertices_bound(primitive, vertices, p) * 4 * sizeof(float);
    if (bytes > o.capacity) {
      std::size_t capacity = std::max<std::size_t>(o.capacity, 1 << 20);
      while (capacity < bytes) capacity *= 2;
      g.glNamedBufferData(o.buffer, static_cast<GLsizeiptr>(capacity), nullptr, GL_STREAM_READ);
      o.capacity = capacity;
    }
    const GLint app_feedback = get_int(GL_TRANSFORM_FEEDBACK_BINDING);
    const GLint app_buffer = get_int(GL_TRANSFORM_FEEDBACK_BUFFER_BINDING);
    g.glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, o.feedback);
    g.glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, o.buffer);
    // A fixed-function draw: the capture pass (the ftransform program, rasterization discarded),
    // then the draw itself alone in the samples query; any other: one run inside all three queries.
    const bool capture_pass = fixed_function != 0;
    const bool discarding = capture_pass && g.glIsEnabled(GL_RASTERIZER_DISCARD) != GL_FALSE;
    if (capture_pass) {
      g.glUseProgram(fixed_function);
      g.glEnable(GL_RASTERIZER_DISCARD);
    } else {
      g.glBeginQuery(GL_SAMPLES_PASSED, o.samples);
    }
    g.glBeginQuery(GL_PRIMITIVES_GENERATED, o.generated);
    g.glBeginQuery(GL_TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN, o.written);
    g.glBeginTransformFeedback(primitive);
    run();
    g.glEndTransformFeedback();
    g.glEndQuery(GL_TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN);
    g.glEndQuery(GL_PRIMITIVES_GENERATED);
    if (capture_pass) {
      if (!discarding) g.glDisable(GL_RASTERIZER_DISCARD);
      g.glUseProgram(0);
    } else {
      g.glEndQuery(GL_SAMPLES_PASSED);
    }
    g.glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, static_cast<GLuint>(app_feedback));
    g.glBindBuffer(GL_TRANSFORM_FEEDBACK_BUFFER, static_cast<GLuint>(app_buffer));
    if (capture_pass) {
      g.glBeginQuery(GL_SAMPLES_PASSED, o.samples);
      run();
      g.glEndQuery(GL_SAMPLES_PASSED);
    }
    GLuint64 samples = 0, generated = 0, written = 0;
    g.glGetQueryObjectui64v(o.samples, GL_QUERY_RESULT, &samples);
    g.glGetQueryObjectui64v(o.generated, GL_QUERY_RESULT, &generated);
    g.glGetQueryObjectui64v(o.written, GL_QUERY_RESULT, &written);
    d.samples_passed = samples;
    if (written < generated) d.flags |= kOverflow;
    const std::size_t per = primitive == GL_POINTS ? 1 : primitive == GL_LINES ? 2 : 3;
    const std::size_t count = static_cast<std::size_t>(written) * per;
    positions.resize(count * 4);
    if (count > 0) g.glGetNamedBufferSubData(o.buffer, 0, static_cast<GLsizeiptr>(positions.size() * sizeof(float)), positions.data());
    d.vertices = static_cast<std::uint32_t>(count);
  }
  g_frame_samples[d.framebuffer] += d.samples_passed;
  rec.put(RawType::Draw, &d, sizeof d, positions.data(), positions.size() * sizeof(float));
  std::vector<float> after;
  if (!before.empty() && read_depth(d.framebuffer, target, after) && after.size() == before.size()) {
    std::vector<std::uint32_t> pixels;
    std::vector<float> depths;
    for (std::size_t i = 0; i < after.size(); ++i)
      if (std::memcmp(&after[i], &before[i], sizeof(float)) != 0) pixels.push_back(static_cast<std::uint32_t>(i)), depths.push_back(after[i]);
    const DeltaHead h{d.frame, d.index, d.framebuffer, target.width, target.height, static_cast<std::uint32_t>(pixels.size())};
    std::vector<std::uint8_t> payload(pixels.size() * 8);
    if (!pixels.empty()) {
      std::memcpy(payload.data(), pixels.data(), pixels.size() * 4);
      std::memcpy(payload.data() + pixels.size() * 4, depths.data(), depths.size() * 4);
    }
    rec.put(RawType::Delta, &h, sizeof h, payload.data(), payload.size());
  }
}

// A clear of `buffers` (ClearBuffer bits) with the given values; glClear obeys the depth and stencil
// write masks and the scissor, glClearBuffer the same.
// `framebuffer`: a named framebuffer's clear (glClearNamedFramebuffer*), or -1 for the one bound
// for drawing.
void record_clear(std::uint32_t buffers, double depth, GLint stencil, GLint framebuffer = -1) {
  Recording& rec = recording();
  if (!rec.recording() || !gl().complete) return;
  std::lock_guard lock(g_mutex);
  Gl& g = gl();
  ClearHead c{};
  c.frame = rec.frame();
  c.index = rec.draws();
  c.framebuffer = static_cast<std::uint32_t>(framebuffer >= 0 ? framebuffer : get_int(GL_DRAW_FRAMEBUFFER_BINDING));
  c.buffers = buffers;
  if (g.glIsEnabled(GL_SCISSOR_TEST)) c.flags |= kScissor;
  GLboolean mask = GL_TRUE;
  g.glGetBooleanv(GL_DEPTH_WRITEMASK, &mask);
  if (mask) c.flags |= kDepthMask;
  g.glGetIntegerv(GL_SCISSOR_BOX, c.scissor);
  c.stencil_write_mask = static_cast<std::uint32_t>(get_int(GL_STENCIL_WRITEMASK));
  c.stencil = stencil;
  c.depth = depth;
  rec.put(RawType::Clear, &c, sizeof c);
}

// The frame's end: the depth of the render target that passed the most samples.
void record_frame_end() {
  Recording& rec = recording();
  if (!rec.on()) {
    rec.end_frame(FrameHead{}, nullptr);  // counts the frame (and ends the process after the last asked for)
    return;
  }
  FrameHead f{};
  f.frame = rec.frame();
  f.draws = rec.draws();
  std::vector<float> depth;
  if (rec.recording() && gl().complete) {
    std::lock_guard lock(g_mutex);
    GLuint best = 0;
    std::uint64_t most = 0;
    for (const auto& [fb, samples] : g_frame_samples)
      if (samples > most || (samples == most && fb == 0)) best = fb, most = samples;
    f.framebuffer = best;
    const Target t = target_of(best);
    f.width = t.width, f.height = t.height;
    f.has_depth = read_depth(best, t, depth) ? 1 : 0;
    g_frame_samples.clear();
  }
  rec.end_frame(f, depth.data());
}

// ---- The wrapped entry points ------------------------------------------------------------------
// Each wrapper keeps the real function the program resolved under that name.

template <class Fn>
struct Real {
  Fn fn = nullptr;
};

// Program setup.
Real<PFNGLSHADERSOURCEPROC> real_glShaderSource;
Real<PFNGLLINKPROGRAMPROC> real_glLinkProgram;
Real<PFNGLTRANSFORMFEEDBACKVARYINGSPROC> real_glTransformFeedbackVaryings;

void hook_glShaderSource(GLuint shader, GLsizei count, const GLchar* const* strings, const GLint* lengths) {
  {
    std::lock_guard lock(g_mutex);
    std::string source;
    for (GLsizei i = 0; strings && i < count; ++i) {
      if (!strings[i]) continue;
      if (lengths && lengths[i] >= 0) source.append(strings[i], static_cast<std::size_t>(lengths[i]));
      else source.append(strings[i]);
    }
    g_shader_source[shader] = std::move(source);
  }
  real_glShaderSource.fn(shader, count, strings, lengths);
}

void hook_glTransformFeedbackVaryings(GLuint program, GLsizei count, const GLchar* const* varyings, GLenum mode) {
  {
    std::lock_guard lock(g_mutex);
    // gl_Position alone is what the library records itself: such a program is captured as is.
    const bool position_only = count == 1 && varyings && varyings[0] && std::strcmp(varyings[0], "gl_Position") == 0;
    if (count > 0 && !position_only) g_own_varyings.insert(program);
    else g_own_varyings.erase(program);
  }
  real_glTransformFeedbackVaryings.fn(program, count, varyings, mode);
}

void hook_glLinkProgram(GLuint program) {
  if (recording().on()) note_context();
  Gl& g = gl();
  if (!g.complete || !recording().on()) {
    real_glLinkProgram.fn(program);
    return;
  }
  std::lock_guard lock(g_mutex);
  ProgramInfo info;
  info.own_varyings = g_own_varyings.count(program) != 0;
  // The fragment stage's source: may it discard, does it write depth.
  GLuint shaders[16] = {};
  GLsizei attached = 0;
  g.glGetAttachedShaders(program, 16, &attached, shaders);
  bool geometry = false;
  for (GLsizei i = 0; i < attached; ++i) {
    GLint type = 0;
    g.glGetShaderiv(shaders[i], GL_SHADER_TYPE, &type);
    if (type == GL_GEOMETRY_SHADER) geometry = true;
    if (type == GL_TESS_EVALUATION_SHADER) info.tessellation = true;
    if (type != GL_FRAGMENT_SHADER) continue;
    const auto it = g_shader_source.find(shaders[i]);
    if (it == g_shader_source.end()) continue;
    const std::string code = glsl_active_text(it->second);  // the branches the compiler keeps
    info.discards = info.discards || has_token(code, "discard");
    info.writes_depth = info.writes_depth || has_token(code, "gl_FragDepth");
  }
  if (!info.own_varyings) {
    const GLchar* position = "gl_Position";
    g.glTransformFeedbackVaryings(program, 1, &position, GL_INTERLEAVED_ATTRIBS);
  }
  real_glLinkProgram.fn(program);
  GLint linked = 0;
  g.glGetProgramiv(program, GL_LINK_STATUS, &linked);
  if (!info.own_varyings) {
    if (linked) {
      info.position = true;
    } else {  // a program with no gl_Position to record: linked as the program asked
      g.glTransformFeedbackVaryings(program, 0, nullptr, GL_INTERLEAVED_ATTRIBS);
      real_glLinkProgram.fn(program);
      g.glGetProgramiv(program, GL_LINK_STATUS, &linked);
    }
  }
  if (linked && geometry) {
    GLint out = 0, vertices = 0, invocations = 1;
    g.glGetProgramiv(program, GL_GEOMETRY_OUTPUT_TYPE, &out);
    g.glGetProgramiv(program, GL_GEOMETRY_VERTICES_OUT, &vertices);
    g.glGetProgramiv(program, GL_GEOMETRY_SHADER_INVOCATIONS, &invocations);
    info.primitive = out == GL_POINTS ? GL_POINTS : out == GL_LINE_STRIP ? GL_LINES : GL_TRIANGLES;
    info.gs_vertices = std::max(1, vertices) * std::max(1, invocations);
  } else if (linked && info.tessellation) {
    GLint mode = 0, points = 0;
    g.glGetProgramiv(program, GL_TESS_GEN_MODE, &mode);
    g.glGetProgramiv(program, GL_TESS_GEN_POINT_MODE, &points);
    info.primitive = points ? GL_POINTS : mode == GL_ISOLINES ? GL_LINES : GL_TRIANGLES;
  }
  g_programs[program] = info;
}

// Draws.
std::size_t instanced(std::size_t count, GLsizei instances) { return count * static_cast<std::size_t>(std::max(instances, 0)); }
std::size_t count_of(GLsizei count) { return static_cast<std::size_t>(std::max(count, 0)); }
std::size_t sum_of(const GLsizei* counts, GLsizei n) {
  std::size_t s = 0;
  for (GLsizei i = 0; counts && i < n; ++i) s += count_of(counts[i]);
  return s;
}

#define NBSIM_DRAW_WRAPPER(name, call, params, args, vertices, indirect)                     \
  Real<PFN##name##PROC> real_##name;                                                       \
  void APIENTRY hook_##name params {                                                       \
    record_draw(DrawCall::call, mode, vertices, indirect, [&] { real_##name.fn args; });   \
  }

// Names as GL's headers spell their PFN types (upper case), then the entry point's own name.
#define PFNglDrawArraysPROC PFNGLDRAWARRAYSPROC
#define PFNglDrawElementsPROC PFNGLDRAWELEMENTSPROC
#define PFNglDrawRangeElementsPROC PFNGLDRAWRANGEELEMENTSPROC
#define PFNglDrawArraysInstancedPROC PFNGLDRAWARRAYSINSTANCEDPROC
#define PFNglDrawElementsInstancedPROC PFNGLDRAWELEMENTSINSTANCEDPROC
#define PFNglDrawElementsBaseVertexPROC PFNGLDRAWELEMENTSBASEVERTEXPROC
#define PFNglDrawRangeElementsBaseVertexPROC PFNGLDRAWRANGEELEMENTSBASEVERTEXPROC
#define PFNglDrawElementsInstancedBaseVertexPROC PFNGLDRAWELEMENTSINSTANCEDBASEVERTEXPROC
#define PFNglDrawArraysInstancedBaseInstancePROC PFNGLDRAWARRAYSINSTANCEDBASEINSTANCEPROC
#define PFNglDrawElementsInstancedBaseInstancePROC PFNGLDRAWELEMENTSINSTANCEDBASEINSTANCEPROC
#define PFNglDrawElementsInstancedBaseVertexBaseInstancePROC PFNGLDRAWELEMENTSINSTANCEDBASEVERTEXBASEINSTANCEPROC
#define PFNglMultiDrawArraysPROC PFNGLMULTIDRAWARRAYSPROC
#define PFNglMultiDrawElementsPROC PFNGLMULTIDRAWELEMENTSPROC
#define PFNglMultiDrawElementsBaseVertexPROC PFNGLMULTIDRAWELEMENTSBASEVERTEXPROC
#define PFNglDrawArraysIndirectPROC PFNGLDRAWARRAYSINDIRECTPROC
#define PFNglDrawElementsIndirectPROC PFNGLDRAWELEMENTSINDIRECTPROC
#define PFNglMultiDrawArraysIndirectPROC PFNGLMULTIDRAWARRAYSINDIRECTPROC
#define PFNglMultiDrawElementsIndirectPROC PFNGLMULTIDRAWELEMENTSINDIRECTPROC

NBSIM_DRAW_WRAPPER(glDrawArrays, Arrays, (GLenum mode, GLint first, GLsizei count), (mode, first, count), count_of(count), false)
NBSIM_DRAW_WRAPPER(glDrawElements, Elements, (GLenum mode, GLsizei count, GLenum type, const void* indices), (mode, count, type, indices),
                   count_of(count), false)
NBSIM_DRAW_WRAPPER(glDrawRangeElements, RangeElements,
                   (GLenum mode, GLuint start, GLuint end, GLsizei count, GLenum type, const void* indices),
                   (mode, start, end, count, type, indices), count_of(count), false)
NBSIM_DRAW_WRAPPER(glDrawArraysInstanced, ArraysInstanced, (GLenum mode, GLint first, GLsizei count, GLsizei n),
                   (mode, first, count, n), instanced(count_of(count), n), false)
NBSIM_DRAW_WRAPPER(glDrawElementsInstanced, ElementsInstanced,
                   (GLenum mode, GLsizei count, GLenum type, const void* indices, GLsizei n), (mode, count, type, indices, n),
                   instanced(count_of(count), n), false)
NBSIM_DRAW_WRAPPER(glDrawElementsBaseVertex, ElementsBaseVertex,
                   (GLenum mode, GLsizei count, GLenum type, const void* indices, GLint base), (mode, count, type, indices, base),
                   count_of(count), false)
NBSIM_DRAW_WRAPPER(glDrawRangeElementsBaseVertex, RangeElementsBaseVertex,
                   (GLenum mode, GLuint start, GLuint end, GLsizei count, GLenum type, const void* indices, GLint base),
                   (mode, start, end, count, type, indices, base), count_of(count), false)
NBSIM_DRAW_WRAPPER(glDrawElementsInstancedBaseVertex, ElementsInstancedBaseVertex,
                   (GLenum mode, GLsizei count, GLenum type, const void* indices, GLsizei n, GLint base),
                   (mode, count, type, indices, n, base), instanced(count_of(count), n), false)
NBSIM_DRAW_WRAPPER(glDrawArraysInstancedBaseInstance, ArraysInstancedBaseInstance,
                   (GLenum mode, GLint first, GLsizei count, GLsizei n, GLuint base_instance), (mode, first, count, n, base_instance),
                   instanced(count_of(count), n), false)
NBSIM_DRAW_WRAPPER(glDrawElementsInstancedBaseInstance, ElementsInstancedBaseInstance,
                   (GLenum mode, GLsizei count, GLenum type, const void* indices, GLsizei n, GLuint base_instance),
                   (mode, count, type, indices, n, base_instance), instanced(count_of(count), n), false)
NBSIM_DRAW_WRAPPER(glDrawElementsInstancedBaseVertexBaseInstance, ElementsInstancedBaseVertexBaseInstance,
                   (GLenum mode, GLsizei count, GLenum type, const void* indices, GLsizei n, GLint base, GLuint base_instance),
                   (mode, count, type, indices, n, base, base_instance), instanced(count_of(count), n), false)
NBSIM_DRAW_WRAPPER(glMultiDrawArrays, MultiArrays, (GLenum mode, const GLint* first, const GLsizei* count, GLsizei n),
                   (mode, first, count, n), sum_of(count, n), false)
NBSIM_DRAW_WRAPPER(glMultiDrawElements, MultiElements,
                   (GLenum mode, const GLsizei* count, GLenum type, const void* const* indices, GLsizei n), (mode, count, type, indices, n),
                   sum_of(count, n), false)
NBSIM_DRAW_WRAPPER(glMultiDrawElementsBaseVertex, MultiElementsBaseVertex,
                   (GLenum mode, const GLsizei* count, GLenum type, const void* const* indices, GLsizei n, const GLint* base),
                   (mode, count, type, indices, n, base), sum_of(count, n), false)
NBSIM_DRAW_WRAPPER(glDrawArraysIndirect, ArraysIndirect, (GLenum mode, const void* indirect), (mode, indirect), 0, true)
NBSIM_DRAW_WRAPPER(glDrawElementsIndirect, ElementsIndirect, (GLenum mode, GLenum type, const void* indirect), (mode, type, indirect), 0,
                   true)
NBSIM_DRAW_WRAPPER(glMultiDrawArraysIndirect, MultiArraysIndirect, (GLenum mode, const void* indirect, GLsizei n, GLsizei stride),
                   (mode, indirect, n, stride), 0, true)
NBSIM_DRAW_WRAPPER(glMultiDrawElementsIndirect, MultiElementsIndirect,
                   (GLenum mode, GLenum type, const void* indirect, GLsizei n, GLsizei stride), (mode, type, indirect, n, stride), 0, true)

// Clears.
Real<PFNGLCLEARPROC> real_glClear;
void APIENTRY hook_glClear(GLbitfield mask) {
  const std::uint32_t buffers = ((mask & GL_DEPTH_BUFFER_BIT) ? kClearDepth : 0u) | ((mask & GL_STENCIL_BUFFER_BIT) ? kClearStencil : 0u);
  if (buffers != 0 && gl().complete && recording().recording()) {
    GLdouble depth = 1.0;
    gl().glGetDoublev(GL_DEPTH_CLEAR_VALUE, &depth);
    record_clear(buffers, depth, get_int(GL_STENCIL_CLEAR_VALUE));
  }
  real_glClear.fn(mask);
}
Real<PFNGLCLEARBUFFERFVPROC> real_glClearBufferfv;
void APIENTRY hook_glClearBufferfv(GLenum buffer, GLint drawbuffer, const GLfloat* value) {
  if (buffer == GL_DEPTH && value) record_clear(kClearDepth, value[0], 0);
  real_glClearBufferfv.fn(buffer, drawbuffer, value);
}
Real<PFNGLCLEARBUFFERIVPROC> real_glClearBufferiv;
void APIENTRY hook_glClearBufferiv(GLenum buffer, GLint drawbuffer, const GLint* value) {
  if (buffer == GL_STENCIL && value) record_clear(kClearStencil, 0.0, value[0]);
  real_glClearBufferiv.fn(buffer, drawbuffer, value);
}
Real<PFNGLCLEARBUFFERFIPROC> real_glClearBufferfi;
void APIENTRY hook_glClearBufferfi(GLenum buffer, GLint drawbuffer, GLfloat depth, GLint stencil) {
  if (buffer == GL_DEPTH_STENCIL) record_clear(kClearDepth | kClearStencil, depth, stencil);
  real_glClearBufferfi.fn(buffer, drawbuffer, depth, stencil);
}
// The direct-state-access clears of a named framebuffer (0: the window's).
Real<PFNGLCLEARNAMEDFRAMEBUFFERFVPROC> real_glClearNamedFramebufferfv;
void APIENTRY hook_glClearNamedFramebufferfv(GLuint fb, GLenum buffer, GLint drawbuffer, const GLfloat* value) {
  if (buffer == GL_DEPTH && value) record_clear(kClearDepth, value[0], 0, static_cast<GLint>(fb));
  real_glClearNamedFramebufferfv.fn(fb, buffer, drawbuffer, value);
}
Real<PFNGLCLEARNAMEDFRAMEBUFFERIVPROC> real_glClearNamedFramebufferiv;
void APIENTRY hook_glClearNamedFramebufferiv(GLuint fb, GLenum buffer, GLint drawbuffer, const GLint* value) {
  if (buffer == GL_STENCIL && value) record_clear(kClearStencil, 0.0, value[0], static_cast<GLint>(fb));
  real_glClearNamedFramebufferiv.fn(fb, buffer, drawbuffer, value);
}
Real<PFNGLCLEARNAMEDFRAMEBUFFERFIPROC> real_glClearNamedFramebufferfi;
void APIENTRY hook_glClearNamedFramebufferfi(GLuint fb, GLenum buffer, GLint drawbuffer, GLfloat depth, GLint stencil) {
  if (buffer == GL_DEPTH_STENCIL) record_clear(kClearDepth | kClearStencil, depth, stencil, static_cast<GLint>(fb));
  real_glClearNamedFramebufferfi.fn(fb, buffer, drawbuffer, depth, stencil);
}

// Features not handled: recorded by name.
Real<PFNGLBLITFRAMEBUFFERPROC> real_glBlitFramebuffer;
void APIENTRY hook_glBlitFramebuffer(GLint a, GLint b, GLint c, GLint d, GLint e, GLint f, GLint g, GLint h, GLbitfield mask, GLenum filter) {
  if (mask & GL_DEPTH_BUFFER_BIT) recording().unhandled("glBlitFramebuffer of depth");
  real_glBlitFramebuffer.fn(a, b, c, d, e, f, g, h, mask, filter);
}
Real<PFNGLBLITNAMEDFRAMEBUFFERPROC> real_glBlitNamedFramebuffer;
void APIENTRY hook_glBlitNamedFramebuffer(GLuint from, GLuint to, GLint a, GLint b, GLint c, GLint d, GLint e, GLint f, GLint g, GLint h,
                                          GLbitfield mask, GLenum filter) {
  if (mask & GL_DEPTH_BUFFER_BIT) recording().unhandled("glBlitNamedFramebuffer of depth");
  real_glBlitNamedFramebuffer.fn(from, to, a, b, c, d, e, f, g, h, mask, filter);
}
using BeginFn = void(APIENTRY*)(GLenum);
Real<BeginFn> real_glBegin;
void APIENTRY hook_glBegin(GLenum mode) {
  recording().unhandled("glBegin (immediate mode)");
  real_glBegin.fn(mode);
}
using CallListFn = void(APIENTRY*)(GLuint);
Real<CallListFn> real_glCallList;
void APIENTRY hook_glCallList(GLuint list) {
  recording().unhandled("glCallList (display lists)");
  real_glCallList.fn(list);
}
using CallListsFn = void(APIENTRY*)(GLsizei, GLenum, const void*);
Real<CallListsFn> real_glCallLists;
void APIENTRY hook_glCallLists(GLsizei n, GLenum type, const void* lists) {
  recording().unhandled("glCallLists (display lists)");
  real_glCallLists.fn(n, type, lists);
}

// Frames.
using SwapFn = EGLBoolean (*)(EGLDisplay, EGLSurface);
Real<SwapFn> real_eglSwapBuffers;
EGLBoolean hook_eglSwapBuffers(EGLDisplay display, EGLSurface surface) {
  record_frame_end();
  return real_eglSwapBuffers.fn(display, surface);
}

// A frame marker (kFrameMarker) from a program without a window: a swap.
using DebugMessageInsertFn = void(APIENTRY*)(GLenum, GLenum, GLuint, GLenum, GLsizei, const GLchar*);
Real<DebugMessageInsertFn> real_glDebugMessageInsert;
void APIENTRY hook_glDebugMessageInsert(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei length, const GLchar* text) {
  if (type == GL_DEBUG_TYPE_MARKER && text) {
    const std::size_t n = length < 0 ? std::strlen(text) : static_cast<std::size_t>(length);
    if (std::string_view(text, n) == kFrameMarker) record_frame_end();
  }
  real_glDebugMessageInsert.fn(source, type, id, severity, length, text);
}

void* hook_eglGetProcAddress(const char* name);

// The table: a name, its wrapper and where the real function goes.
struct Hook {
  const char* name;
  void* wrapper;
  void** real;
};

#define NBSIM_HOOK(name) Hook{#name, reinterpret_cast<void*>(&hook_##name), reinterpret_cast<void**>(&real_##name.fn)}
#define NBSIM_HOOK_AS(alias, name) Hook{#alias, reinterpret_cast<void*>(&hook_##name), reinterpret_cast<void**>(&real_##name.fn)}

const std::vector<Hook>& hooks() {
  static const std::vector<Hook> table = {
      NBSIM_HOOK(glShaderSource),
      NBSIM_HOOK_AS(glShaderSourceARB, glShaderSource),
      NBSIM_HOOK(glLinkProgram),
      NBSIM_HOOK_AS(glLinkProgramARB, glLinkProgram),
      NBSIM_HOOK(glTransformFeedbackVaryings),
      NBSIM_HOOK_AS(glTransformFeedbackVaryingsEXT, glTransformFeedbackVaryings),
      NBSIM_HOOK(glDrawArrays),
      NBSIM_HOOK_AS(glDrawArraysEXT, glDrawArrays),
      NBSIM_HOOK(glDrawElements),
      NBSIM_HOOK(glDrawRangeElements),
      NBSIM_HOOK_AS(glDrawRangeElementsEXT, glDrawRangeElements),
      NBSIM_HOOK(glDrawArraysInstanced),
      NBSIM_HOOK_AS(glDrawArraysInstancedARB, glDrawArraysInstanced),
      NBSIM_HOOK_AS(glDrawArraysInstancedEXT, glDrawArraysInstanced),
      NBSIM_HOOK(glDrawElementsInstanced),
      NBSIM_HOOK_AS(glDrawElementsInstancedARB, glDrawElementsInstanced),
      NBSIM_HOOK_AS(glDrawElementsInstancedEXT, glDrawElementsInstanced),
      NBSIM_HOOK(glDrawElementsBaseVertex),
      NBSIM_HOOK(glDrawRangeElementsBaseVertex),
      NBSIM_HOOK(glDrawElementsInstancedBaseVertex),
      NBSIM_HOOK(glDrawArraysInstancedBaseInstance),
      NBSIM_HOOK(glDrawElementsInstancedBaseInstance),
      NBSIM_HOOK(glDrawElementsInstancedBaseVertexBaseInstance),
      NBSIM_HOOK(glMultiDrawArrays),
      NBSIM_HOOK_AS(glMultiDrawArraysEXT, glMultiDrawArrays),
      NBSIM_HOOK(glMultiDrawElements),
      NBSIM_HOOK_AS(glMultiDrawElementsEXT, glMultiDrawElements),
      NBSIM_HOOK(glMultiDrawElementsBaseVertex),
      NBSIM_HOOK(glDrawArraysIndirect),
      NBSIM_HOOK(glDrawElementsIndirect),
      NBSIM_HOOK(glMultiDrawArraysIndirect),
      NBSIM_HOOK(glMultiDrawElementsIndirect),
      NBSIM_HOOK(glClear),
      NBSIM_HOOK(glClearBufferfv),
      NBSIM_HOOK(glClearBufferiv),
      NBSIM_HOOK(glClearBufferfi),
      NBSIM_HOOK(glClearNamedFramebufferfv),
      NBSIM_HOOK(glClearNamedFramebufferiv),
      NBSIM_HOOK(glClearNamedFramebufferfi),
      NBSIM_HOOK(glBlitNamedFramebuffer),
      NBSIM_HOOK(glBlitFramebuffer),
      NBSIM_HOOK_AS(glBlitFramebufferEXT, glBlitFramebuffer),
      NBSIM_HOOK(glBegin),
      NBSIM_HOOK(glCallList),
      NBSIM_HOOK(glCallLists),
      NBSIM_HOOK(eglSwapBuffers),
      NBSIM_HOOK(glDebugMessageInsert),
      NBSIM_HOOK_AS(glDebugMessageInsertKHR, glDebugMessageInsert),
      NBSIM_HOOK_AS(glDebugMessageInsertARB, glDebugMessageInsert),
  };
  return table;
}

// What the program gets for `name`: the wrapper when the library wraps it (the real function kept).
void* wrap(const char* name, void* real) {
  if (!real || !name) return real;
  if (std::strcmp(name, "eglGetProcAddress") == 0) {
    if (!g_real_get_proc) g_real_get_proc = reinterpret_cast<GetProcFn>(real);
    return reinterpret_cast<void*>(&hook_eglGetProcAddress);
  }
  for (const Hook& h : hooks()) {
    if (std::strcmp(name, h.name) != 0) continue;
    if (!*h.real) *h.real = real;
    return h.wrapper;
  }
  return real;
}

void* hook_eglGetProcAddress(const char* name) { return wrap(name, g_real_get_proc ? g_real_get_proc(name) : nullptr); }

}  // namespace
}  // namespace nbsim::apitrace

extern "C" {

__attribute__((visibility("default"))) void* dlsym(void* handle, const char* name) {
  const auto real = nbsim::apitrace::real_dlsym();
  if (!real) return nullptr;
  return nbsim::apitrace::wrap(name, real(handle, name));
}

}  // extern "C"

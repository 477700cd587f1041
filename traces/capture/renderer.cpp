// The capture renderer on Mesa; see renderer.h. GL objects live in Impl; one frame is:
// frustum culling -> occluders -> [N-buffer build] -> bounds tests -> visible objects -> ID buffer.
#include "traces/capture/renderer.h"

#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>
#include <fmt/format.h>

#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "model/common/error.h"
#include "model/nbuffer/covering.h"
#include "model/scene/visibility.h"
#include "nbsim_shaders.h"

namespace nbsim::capture {

namespace {

using trace::DrawRecord;
using trace::DrawRole;
using trace::TestMode;

GLuint compile(GLenum type, const std::string& source, const char* name) {
  const GLuint s = glCreateShader(type);
  const char* src = source.c_str();
  glShaderSource(s, 1, &src, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    throw std::runtime_error(fmt::format("GLSL compile error in {}: {}", name, log));
  }
  return s;
}

GLuint link(std::initializer_list<GLuint> shaders, const char* name, bool capture_position = false) {
  const GLuint p = glCreateProgram();
  for (GLuint s : shaders) glAttachShader(p, s);
  if (capture_position) {
    const char* varyings[] = {"gl_Position"};
    glTransformFeedbackVaryings(p, 1, varyings, GL_INTERLEAVED_ATTRIBS);
  }
  glLinkProgram(p);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    glGetProgramInfoLog(p, sizeof log, nullptr, log);
    throw std::runtime_error(fmt::format("GLSL link error in {}: {}", name, log));
  }
  for (GLuint s : shaders) glDeleteShader(s);
  return p;
}

// Inserts `defines` after the #version line of a shader.
std::string with_defines(const char* source, const std::string& defines) {
  std::string s(source);
  const auto eol = s.find('\n', s.find("#version"));
  return s.insert(eol + 1, defines);
}

}  // namespace

struct Renderer::Impl {
  const City& city;
  RendererOptions opt;
  gl::Context context;
  int levels = 1;
  bool reversed = false;

  GLuint scene_vao = 0, scene_vbo = 0, scene_ebo = 0;
  GLuint box_vao = 0, box_vbo = 0, box_ebo = 0;
  GLuint scene_prog = 0, build_prog = 0, query_prog = 0, empty_vao = 0;
  GLint u_view_proj = -1, u_draw_slot = -1, u_object_id = -1;
  GLuint fbo = 0, depth_tex = 0, id_tex = 0;
  std::vector<GLuint> level_tex, level_fbo;
  GLuint level_array = 0;
  GLuint counts_ssbo = 0, query_ssbo = 0, result_ssbo = 0, tf_buffer = 0, tf_object = 0;
  std::size_t counts_capacity = 0, tf_capacity = 0;
  std::vector<GLuint> q_samples, q_clip_in, q_clip_out;

  // Per-frame state.
  std::vector<DrawRecord> draws;
  // Where each recorded draw's results are: a GL draw has counters and maybe captured vertices.
  struct Pending {
    bool gl_draw = false;
    std::size_t tf_offset = 0, tf_bytes = 0;
  };
  std::vector<Pending> pending;
  std::size_t tf_used = 0;
  glm::mat4 view_proj{1.0f};
  std::vector<std::uint32_t> previous_visible;

  Impl(const City& c, RendererOptions o) : city(c), opt(o) {
    reversed = opt.projection.reversed_z;
    levels = nbuffer_level_count(opt.width, opt.height);
    init_geometry();
    init_programs();
    init_targets();
    glGenTransformFeedbacks(1, &tf_object);
    glCreateBuffers(1, &counts_ssbo);
    glCreateBuffers(1, &query_ssbo);
    glCreateBuffers(1, &result_ssbo);
    glCreateBuffers(1, &tf_buffer);
    if (reversed) glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  }

  ~Impl() {
    glDeleteVertexArrays(1, &scene_vao);
    glDeleteVertexArrays(1, &box_vao);
    glDeleteVertexArrays(1, &empty_vao);
    const GLuint buffers[] = {scene_vbo, scene_ebo, box_vbo, box_ebo, counts_ssbo, query_ssbo, result_ssbo, tf_buffer};
    glDeleteBuffers(static_cast<GLsizei>(std::size(buffers)), buffers);
    glDeleteTransformFeedbacks(1, &tf_object);
    glDeleteProgram(scene_prog);
    glDeleteProgram(build_prog);
    glDeleteProgram(query_prog);
    glDeleteFramebuffers(1, &fbo);
    glDeleteFramebuffers(static_cast<GLsizei>(level_fbo.size()), level_fbo.data());
    glDeleteTextures(static_cast<GLsizei>(level_tex.size()), level_tex.data());
    glDeleteTextures(1, &level_array);
    glDeleteTextures(1, &depth_tex);
    glDeleteTextures(1, &id_tex);
    for (auto* pool : {&q_samples, &q_clip_in, &q_clip_out}) glDeleteQueries(static_cast<GLsizei>(pool->size()), pool->data());
  }

  void init_geometry() {
    glCreateVertexArrays(1, &scene_vao);
    glCreateBuffers(1, &scene_vbo);
    glCreateBuffers(1, &scene_ebo);
    glNamedBufferStorage(scene_vbo, static_cast<GLsizeiptr>(city.vertices.size() * sizeof(glm::vec3)), city.vertices.data(), 0);
    glNamedBufferStorage(scene_ebo, static_cast<GLsizeiptr>(city.indices.size() * 4), city.indices.data(), 0);
    glVertexArrayVertexBuffer(scene_vao, 0, scene_vbo, 0, sizeof(glm::vec3));
    glVertexArrayElementBuffer(scene_vao, scene_ebo);
    glEnableVertexArrayAttrib(scene_vao, 0);
    glVertexArrayAttribFormat(scene_vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(scene_vao, 0, 0);

    // Boxes of every object, then of every BVH node: 8 corners each.
    std::vector<glm::vec3> corners;
    auto add = [&](const trace::Aabb& b) {
      for (int i = 0; i < 8; ++i) corners.push_back({i & 1 ? b.hi[0] : b.lo[0], i & 2 ? b.hi[1] : b.lo[1], i & 4 ? b.hi[2] : b.lo[2]});
    };
    for (const auto& b : city.scene.objects) add(b);
    for (const auto& b : city.scene.node_bounds) add(b);
    glCreateVertexArrays(1, &box_vao);
    glCreateBuffers(1, &box_vbo);
    glCreateBuffers(1, &box_ebo);
    glNamedBufferStorage(box_vbo, static_cast<GLsizeiptr>(corners.size() * sizeof(glm::vec3)), corners.data(), 0);
    // The box pattern the model uses too (model/scene/visibility.h), widened to GL's index type.
    const std::array<std::uint32_t, 36> box_indices = [] {
      std::array<std::uint32_t, 36> out{};
      std::copy(scene::kBoxIndices.begin(), scene::kBoxIndices.end(), out.begin());
      return out;
    }();
    glNamedBufferStorage(box_ebo, sizeof box_indices, box_indices.data(), 0);
    glVertexArrayVertexBuffer(box_vao, 0, box_vbo, 0, sizeof(glm::vec3));
    glVertexArrayElementBuffer(box_vao, box_ebo);
    glEnableVertexArrayAttrib(box_vao, 0);
    glVertexArrayAttribFormat(box_vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(box_vao, 0, 0);
    glCreateVertexArrays(1, &empty_vao);
  }

  void init_programs() {
    scene_prog = link({compile(GL_VERTEX_SHADER, shaders::scene_vert, "scene.vert"),
                       compile(GL_FRAGMENT_SHADER, shaders::count_frag, "count.frag")},
                      "scene", true);
    u_view_proj = glGetUniformLocation(scene_prog, "view_proj");
    u_draw_slot = glGetUniformLocation(scene_prog, "draw_slot");
    u_object_id = glGetUniformLocation(scene_prog, "object_id");
    const std::string far = reversed ? "#define FAR(a, b) min(a, b)\n#define FARTHER_THAN(a, b) ((a) < (b))\n"
                                     : "#define FAR(a, b) max(a, b)\n#define FARTHER_THAN(a, b) ((a) > (b))\n";
    build_prog = link({compile(GL_VERTEX_SHADER, shaders::fullscreen_vert, "fullscreen.vert"),
                       compile(GL_FRAGMENT_SHADER, with_defines(shaders::nbuffer_build_frag, far), "nbuffer_build.frag")},
                      "nbuffer_build");
    query_prog = link({compile(GL_COMPUTE_SHADER, with_defines(shaders::nbuffer_query_comp, far), "nbuffer_query.comp")},
                      "nbuffer_query");
  }

  void init_targets() {
    const int w = opt.width, h = opt.height;
    glCreateTextures(GL_TEXTURE_2D, 1, &depth_tex);
    glTextureStorage2D(depth_tex, 1, GL_DEPTH_COMPONENT32F, w, h);
    glTextureParameteri(depth_tex, GL_TEXTURE_COMPARE_MODE, GL_NONE);
    glTextureParameteri(depth_tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(depth_tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glCreateTextures(GL_TEXTURE_2D, 1, &id_tex);
    glTextureStorage2D(id_tex, 1, GL_R32UI, w, h);
    glCreateFramebuffers(1, &fbo);
    glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, depth_tex, 0);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, id_tex, 0);
    if (glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("the capture framebuffer is incomplete");
    // N-buffer: one R32F texture per level to render into (no feedback loop), then copied into an
    // array texture that the query shader reads.
    level_tex.resize(static_cast<std::size_t>(levels));
    level_fbo.resize(static_cast<std::size_t>(levels));
    glCreateTextures(GL_TEXTURE_2D, levels, level_tex.data());
    glCreateFramebuffers(levels, level_fbo.data());
    for (int i = 0; i < levels; ++i) {
      glTextureStorage2D(level_tex[static_cast<std::size_t>(i)], 1, GL_R32F, w, h);
      glNamedFramebufferTexture(level_fbo[static_cast<std::size_t>(i)], GL_COLOR_ATTACHMENT0, level_tex[static_cast<std::size_t>(i)], 0);
    }
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &level_array);
    glTextureStorage3D(level_array, 1, GL_R32F, w, h, levels);
    for (GLuint t : level_tex) {
      glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    glTextureParameteri(level_array, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(level_array, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  }

  // ---- per-draw recording -------------------------------------------------------------------

  // Grows a buffer to hold at least `need` bytes, keeping its contents (zero past them).
  static void grow(GLuint& buffer, std::size_t& capacity, std::size_t need) {
    if (need <= capacity) return;
    const std::size_t size = std::max(need, capacity * 2);
    GLuint b = 0;
    glCreateBuffers(1, &b);
    glNamedBufferStorage(b, static_cast<GLsizeiptr>(size), nullptr, GL_DYNAMIC_STORAGE_BIT);
    const GLuint zero = 0;
    glClearNamedBufferData(b, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    if (capacity) glCopyNamedBufferSubData(buffer, b, 0, 0, static_cast<GLsizeiptr>(capacity));
    glDeleteBuffers(1, &buffer);
    buffer = b;
    capacity = size;
  }

  void reserve(std::size_t draw_count, std::size_t tf_bytes) {
    std::size_t bytes = counts_capacity * 4;
    if (draw_count * 4 > bytes) {
      grow(counts_ssbo, bytes, draw_count * 4);
      counts_capacity = bytes / 4;
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, counts_ssbo);
    }
    grow(tf_buffer, tf_capacity, tf_bytes);
    while (q_samples.size() < draw_count) {
      GLuint q[3];
      glGenQueries(3, q);
      q_samples.push_back(q[0]);
      q_clip_in.push_back(q[1]);
      q_clip_out.push_back(q[2]);
    }
  }

  trace::DepthState depth_state(bool write, bool test) const {
    trace::DepthState s;
    s.func = reversed ? trace::DepthFunc::Greater : trace::DepthFunc::Less;
    s.write = write;
    s.test = test;
    s.cull = trace::CullFace::Back;
    s.front_ccw = true;
    s.clip = reversed ? trace::ClipControl::ZeroToOne : trace::ClipControl::NegativeOneToOne;
    return s;
  }

  // Issues one recorded draw of triangles with the scene program. Queries and transform feedback
  // wrap it; results are read at the end of the frame (or at once by result()).
  std::size_t draw(DrawRole role, std::int32_t object, std::int32_t node, bool box, std::uint32_t index_count,
                   std::uint32_t first_index, GLint base_vertex) {
    const std::size_t slot = draws.size();
    const std::size_t bytes = static_cast<std::size_t>(index_count) * 16;
    reserve(slot + 1, tf_used + bytes);
    DrawRecord d;
    d.index = static_cast<std::uint32_t>(slot);
    d.role = role;
    d.object = object;
    d.node = node;
    const bool query = role == DrawRole::BoundsQuery || role == DrawRole::NodeQuery;
    d.state = depth_state(!query, true);
    draws.push_back(d);
    pending.push_back({true, tf_used, bytes});

    glUniform1ui(u_draw_slot, static_cast<GLuint>(slot));
    glUniform1ui(u_object_id, static_cast<GLuint>(std::max(object, 0)));
    glDepthMask(query ? GL_FALSE : GL_TRUE);
    glBindBufferRange(GL_TRANSFORM_FEEDBACK_BUFFER, 0, tf_buffer, static_cast<GLintptr>(tf_used), static_cast<GLsizeiptr>(bytes));
    tf_used += bytes;
    glBeginQuery(GL_SAMPLES_PASSED, q_samples[slot]);
    glBeginQuery(GL_CLIPPING_INPUT_PRIMITIVES, q_clip_in[slot]);
    glBeginQuery(GL_CLIPPING_OUTPUT_PRIMITIVES, q_clip_out[slot]);
    glBeginTransformFeedback(GL_TRIANGLES);
    glBindVertexArray(box ? box_vao : scene_vao);
    glDrawElementsBaseVertex(GL_TRIANGLES, static_cast<GLsizei>(index_count), GL_UNSIGNED_INT,
                             reinterpret_cast<const void*>(static_cast<std::uintptr_t>(first_index) * 4), base_vertex);
    glEndTransformFeedback();
    glEndQuery(GL_CLIPPING_OUTPUT_PRIMITIVES);
    glEndQuery(GL_CLIPPING_INPUT_PRIMITIVES);
    glEndQuery(GL_SAMPLES_PASSED);
    return slot;
  }

  std::size_t draw_object(DrawRole role, std::uint32_t o) {
    const Object& obj = city.objects[o];
    return draw(role, static_cast<std::int32_t>(o), -1, false, obj.index_count, obj.first_index, 0);
  }

  // Bounding box of object o (node < 0) or of BVH node `node`, inside an occlusion query.
  std::size_t draw_box(std::int32_t object, std::int32_t node) {
    const std::size_t box = node >= 0 ? city.scene.objects.size() + static_cast<std::size_t>(node) : static_cast<std::size_t>(object);
    return draw(node >= 0 ? DrawRole::NodeQuery : DrawRole::BoundsQuery, object, node, true, 36, 0,
                static_cast<GLint>(box * 8));
  }

  std::uint64_t samples_passed(std::size_t slot) {
    GLuint64 v = 0;
    glGetQueryObjectui64v(q_samples[slot], GL_QUERY_RESULT, &v);
    return v;
  }

  void begin_scene_pass() {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, opt.width, opt.height);
    glUseProgram(scene_prog);
    glUniformMatrix4fv(u_view_proj, 1, GL_FALSE, glm::value_ptr(view_proj));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, counts_ssbo);
    glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, tf_object);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(reversed ? GL_GREATER : GL_LESS);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
    glColorMaski(0, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  }

  // ---- bounds tests (the scene's, model/scene/visibility.h) --------------------------------

  // Tests a batch of bounds against the GLSL N-buffer in one compute dispatch; sets .visible.
  void nbuffer_query(std::vector<trace::BoundsTest>& tests) {
    struct alignas(16) Gpu { std::int32_t rect[4]; float nearest; std::uint32_t always, pad0, pad1; };
    std::vector<Gpu> in;
    for (const auto& t : tests) {
      Gpu g{};
      // Off-screen bounds are never visible; crossing the near plane always is.
      g.rect[0] = std::min(t.x, opt.width - 1), g.rect[1] = std::min(t.y, opt.height - 1);
      g.rect[2] = std::max(t.w, 1), g.rect[3] = std::max(t.h, 1);
      g.nearest = t.nearest_depth;
      g.always = t.crosses_near ? 1u : 0u;
      in.push_back(g);
    }
    if (in.empty()) return;
    glDeleteBuffers(1, &query_ssbo);
    glCreateBuffers(1, &query_ssbo);
    glNamedBufferStorage(query_ssbo, static_cast<GLsizeiptr>(in.size() * sizeof(Gpu)), in.data(), 0);
    glDeleteBuffers(1, &result_ssbo);
    glCreateBuffers(1, &result_ssbo);
    glNamedBufferStorage(result_ssbo, static_cast<GLsizeiptr>(in.size() * 4), nullptr, 0);
    glUseProgram(query_prog);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, query_ssbo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, result_ssbo);
    glBindTextureUnit(0, level_array);
    glUniform1i(glGetUniformLocation(query_prog, "levels"), 0);
    glUniform1i(glGetUniformLocation(query_prog, "top_level"), levels - 1);
    glUniform1ui(glGetUniformLocation(query_prog, "count"), static_cast<GLuint>(in.size()));
    glDispatchCompute(static_cast<GLuint>((in.size() + 63) / 64), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<std::uint32_t> out(in.size());
    glGetNamedBufferSubData(result_ssbo, 0, static_cast<GLsizeiptr>(out.size() * 4), out.data());
    for (std::size_t i = 0; i < tests.size(); ++i) tests[i].visible = tests[i].w > 0 && tests[i].h > 0 && out[i] != 0;
  }

  // The GLSL N-buffer construction from the current depth buffer, one recorded pass per level.
  void build_nbuffer() {
    glUseProgram(build_prog);
    glBindVertexArray(empty_vao);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, counts_ssbo);
    glBindTextureUnit(1, depth_tex);
    glUniform1i(glGetUniformLocation(build_prog, "depth"), 1);
    glUniform1i(glGetUniformLocation(build_prog, "levels"), 0);
    const GLint u_src = glGetUniformLocation(build_prog, "source_level"), u_step = glGetUniformLocation(build_prog, "step");
    const GLint u_is_depth = glGetUniformLocation(build_prog, "source_is_depth"), u_slot = glGetUniformLocation(build_prog, "draw_slot");
    for (int i = 0; i < levels; ++i) {
      const std::size_t slot = draws.size();
      reserve(slot + 1, tf_used);
      DrawRecord d;
      d.index = static_cast<std::uint32_t>(slot);
      d.role = DrawRole::NBufferBuild;
      d.level = static_cast<std::uint8_t>(i);
      d.state = depth_state(false, false);
      d.state.cull = trace::CullFace::None;
      draws.push_back(d);
      pending.push_back({true, 0, 0});
      // Level i is rendered into its own texture while level i - 1 is read from the array copy,
      // so no texture is read and written by the same pass.
      glBindFramebuffer(GL_FRAMEBUFFER, level_fbo[static_cast<std::size_t>(i)]);
      glViewport(0, 0, opt.width, opt.height);
      glBindTextureUnit(0, level_array);
      glUniform1i(u_src, std::max(i - 1, 0));
      glUniform1i(u_step, i > 0 ? 1 << (i - 1) : 0);
      glUniform1i(u_is_depth, i == 0);
      glUniform1ui(u_slot, static_cast<GLuint>(slot));
      glBeginQuery(GL_SAMPLES_PASSED, q_samples[slot]);
      glBeginQuery(GL_CLIPPING_INPUT_PRIMITIVES, q_clip_in[slot]);
      glBeginQuery(GL_CLIPPING_OUTPUT_PRIMITIVES, q_clip_out[slot]);
      glDrawArrays(GL_TRIANGLES, 0, 3);
      glEndQuery(GL_CLIPPING_OUTPUT_PRIMITIVES);
      glEndQuery(GL_CLIPPING_INPUT_PRIMITIVES);
      glEndQuery(GL_SAMPLES_PASSED);
      glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
      glCopyImageSubData(level_tex[static_cast<std::size_t>(i)], GL_TEXTURE_2D, 0, 0, 0, 0, level_array, GL_TEXTURE_2D_ARRAY,
                         0, 0, 0, i, opt.width, opt.height, 1);
    }
    glEnable(GL_CULL_FACE);
  }

  // ---- one frame -----------------------------------------------------------------------------

  trace::DepthSnapshot read_depth(trace::DepthWhich which) {
    trace::DepthSnapshot d;
    d.name = std::string(trace::to_string(which));
    d.width = opt.width;
    d.height = opt.height;
    d.texels.resize(static_cast<std::size_t>(opt.width) * opt.height);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, opt.width, opt.height, GL_DEPTH_COMPONENT, GL_FLOAT, d.texels.data());  // bottom row first = y up
    return d;
  }

  CapturedFrame render(std::uint32_t index, const CameraPose& pose, bool keep_levels) {
    CapturedFrame f;
    draws.clear();
    pending.clear();
    tf_used = 0;
    const glm::mat4 view = view_matrix(pose);
    const glm::mat4 proj = projection_matrix(opt.projection, static_cast<double>(opt.width) / opt.height);
    view_proj = proj * view;
    f.begin.frame = index;
    f.begin.mode = opt.mode;
    std::memcpy(f.begin.view.data(), glm::value_ptr(view), 64);
    std::memcpy(f.begin.proj.data(), glm::value_ptr(proj), 64);
    f.begin.eye = {pose.eye.x, pose.eye.y, pose.eye.z};

    const scene::FrameView v =
        scene::FrameView::make(f.begin, opt.width, opt.height, opt.projection.near_m, opt.nearest_margin, reversed, reversed);
    const std::vector<std::uint32_t> in_frustum = scene::frustum_objects(city.scene, v);
    std::vector<char> is_occluder(city.objects.size(), 0), in_view(city.objects.size(), 0);
    for (auto o : in_frustum) in_view[o] = 1;
    for (auto o : previous_visible)
      if (in_view[o]) is_occluder[o] = 1;

    const auto t0 = std::chrono::steady_clock::now();
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    const float clear_depth = reversed ? 0.0f : 1.0f;
    glDepthMask(GL_TRUE);  // clears obey the write masks
    glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &clear_depth);
    // Zero the fragment counters of this frame (capacity grows as draws are issued).
    reserve(std::max<std::size_t>(4 * in_frustum.size() + 64, 256), 0);
    const GLuint zero = 0;
    glClearNamedBufferData(counts_ssbo, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);

    // 1. Occluders: last frame's visible objects.
    begin_scene_pass();
    std::vector<std::uint32_t> rendered;
    for (auto o : in_frustum)
      if (is_occluder[o]) { draw_object(DrawRole::Occluder, o); rendered.push_back(o); }
    f.depth.push_back(read_depth(trace::DepthWhich::AfterOccluders));

    // 2. Bounds tests of every other object in the frustum.
    std::vector<char> visible(city.objects.size(), 0);
    const bool nbuffer_mode = opt.mode == TestMode::NBuffer || opt.mode == TestMode::NBufferHier;
    if (nbuffer_mode) build_nbuffer();
    if (opt.mode == TestMode::None) {
      for (auto o : in_frustum) visible[o] = !is_occluder[o];
    } else {
      const bool hier = opt.mode == TestMode::OcclusionQueryHier || opt.mode == TestMode::NBufferHier;
      const scene::BatchTester tester = [&](const std::vector<scene::TestItem>& items, std::vector<trace::BoundsTest>& tests) {
        if (nbuffer_mode)
          test_with_nbuffer(items, tests);
        else
          test_with_queries(items, tests);
      };
      visible = scene::find_visible(city.scene, v, in_frustum, is_occluder, hier, tester);
    }

    // 3. The objects found visible.
    begin_scene_pass();
    for (auto o : in_frustum)
      if (visible[o] && !is_occluder[o]) { draw_object(DrawRole::Visible, o); rendered.push_back(o); }
    glFinish();
    f.end.gl_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    f.depth.push_back(read_depth(trace::DepthWhich::Final));
    if (nbuffer_mode && keep_levels) f.levels = read_levels();
    collect(f);

    // 4. Ground truth: every object in the frustum, nothing culled, into the ID buffer, in the
    //    technique's order (occluders first), so that ties at equal depth resolve as in the frame.
    std::vector<std::uint32_t> order;
    for (auto o : in_frustum)
      if (is_occluder[o]) order.push_back(o);
    for (auto o : in_frustum)
      if (!is_occluder[o]) order.push_back(o);
    f.truth = ground_truth(order);
    previous_visible.clear();
    for (std::size_t o = 0; o < f.truth.visible_pixels.size(); ++o)
      if (f.truth.visible_pixels[o]) previous_visible.push_back(static_cast<std::uint32_t>(o));
    std::sort(rendered.begin(), rendered.end());
    f.rendered_objects = std::move(rendered);
    f.end.frame = index;
    f.end.draws = static_cast<std::uint32_t>(f.draws.size());
    return f;
  }

  // One batch of bounds tests as occlusion queries: each box drawn inside a query, then every
  // query's passed samples read (the round trip the technique stalls on).
  void test_with_queries(const std::vector<scene::TestItem>& items, std::vector<trace::BoundsTest>& tests) {
    begin_scene_pass();
    std::vector<std::size_t> slots;
    for (std::size_t i = 0; i < items.size(); ++i) {
      const std::size_t slot = draw_box(items[i].object, items[i].node);
      draws[slot].has_bounds = true;
      draws[slot].bounds = tests[i];
      slots.push_back(slot);
    }
    for (std::size_t i = 0; i < items.size(); ++i) {
      tests[i].visible = tests[i].crosses_near || samples_passed(slots[i]) > 0;
      draws[slots[i]].bounds.visible = tests[i].visible;
    }
  }

  // One batch of bounds tests against the GLSL N-buffer (one compute dispatch), each recorded.
  void test_with_nbuffer(const std::vector<scene::TestItem>& items, std::vector<trace::BoundsTest>& tests) {
    nbuffer_query(tests);
    for (std::size_t i = 0; i < items.size(); ++i) record_lookup(items[i].object, items[i].node, tests[i]);
  }

  // A bounds test against the N-buffer, recorded as a draw without geometry.
  void record_lookup(std::int32_t object, std::int32_t node, const trace::BoundsTest& t) {
    DrawRecord d;
    d.index = static_cast<std::uint32_t>(draws.size());
    d.role = DrawRole::NBufferQuery;
    d.object = object;
    d.node = node;
    d.state = depth_state(false, false);
    d.has_bounds = true;
    d.bounds = t;
    draws.push_back(d);
    pending.push_back({false, 0, 0});  // no GL draw: no counters to read
  }

  // Reads every draw's counters and captured clip-space vertices.
  void collect(CapturedFrame& f) {
    std::vector<std::uint32_t> counts(draws.size());
    if (!draws.empty()) glGetNamedBufferSubData(counts_ssbo, 0, static_cast<GLsizeiptr>(counts.size() * 4), counts.data());
    std::vector<float> tf(tf_used / 4);
    if (tf_used) glGetNamedBufferSubData(tf_buffer, 0, static_cast<GLsizeiptr>(tf_used), tf.data());
    for (std::size_t i = 0; i < draws.size(); ++i) {
      DrawRecord& d = draws[i];
      const Pending& p = pending[i];
      if (!p.gl_draw) continue;  // an N-buffer lookup, not a GL draw
      d.gl.fragments = counts[i];
      glGetQueryObjectui64v(q_samples[i], GL_QUERY_RESULT, &d.gl.samples_passed);
      glGetQueryObjectui64v(q_clip_in[i], GL_QUERY_RESULT, &d.gl.clip_prims_in);
      glGetQueryObjectui64v(q_clip_out[i], GL_QUERY_RESULT, &d.gl.clip_prims_out);
      for (std::size_t b = p.tf_offset; b < p.tf_offset + p.tf_bytes; b += 16)
        d.clip_positions.push_back({tf[b / 4], tf[b / 4 + 1], tf[b / 4 + 2], tf[b / 4 + 3]});
    }
    f.draws = std::move(draws);
    draws.clear();
  }

  trace::NBufferLevels read_levels() {
    trace::NBufferLevels l;
    l.op = reversed ? 1 : 0;
    l.width = opt.width;
    l.height = opt.height;
    l.levels = levels;
    l.texels.resize(static_cast<std::size_t>(levels) * opt.width * opt.height);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glGetTextureImage(level_array, 0, GL_RED, GL_FLOAT, static_cast<GLsizei>(l.texels.size() * 4), l.texels.data());
    return l;
  }

  trace::GroundTruth ground_truth(const std::vector<std::uint32_t>& order) {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    const float clear_depth = reversed ? 0.0f : 1.0f;
    const GLuint clear_id[4] = {0, 0, 0, 0};
    glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);  // clears obey the write masks
    glDepthMask(GL_TRUE);
    glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &clear_depth);
    glClearNamedFramebufferuiv(fbo, GL_COLOR, 0, clear_id);
    begin_scene_pass();
    glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glBindVertexArray(scene_vao);
    // Counters of this pass land in a slot past the frame's draws and are not recorded.
    reserve(draws.size() + 1, 0);
    glUniform1ui(u_draw_slot, static_cast<GLuint>(counts_capacity - 1));
    for (auto o : order) {
      const Object& obj = city.objects[o];
      glUniform1ui(u_object_id, o);
      glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(obj.index_count), GL_UNSIGNED_INT,
                     reinterpret_cast<const void*>(static_cast<std::uintptr_t>(obj.first_index) * 4));
    }
    std::vector<std::uint32_t> ids(static_cast<std::size_t>(opt.width) * opt.height);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, opt.width, opt.height, GL_RED_INTEGER, GL_UNSIGNED_INT, ids.data());
    trace::GroundTruth t;
    t.visible_pixels.assign(city.objects.size(), 0);
    t.id_width = opt.width;
    t.id_height = opt.height;
    t.ids.resize(ids.size());
    for (std::size_t i = 0; i < ids.size(); ++i) {
      const std::uint32_t id = ids[i];
      t.ids[i] = static_cast<std::int32_t>(id) - 1;  // -1 where no object
      if (id == 0) continue;
      ++t.covered_pixels;
      NBSIM_CHECK(id - 1 < t.visible_pixels.size(), "ID buffer holds an id past the scene");
      ++t.visible_pixels[id - 1];
    }
    glColorMaski(0, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    return t;
  }
};

Renderer::Renderer(const City& city, RendererOptions options) : impl_(std::make_unique<Impl>(city, options)) {}
Renderer::~Renderer() = default;

CapturedFrame Renderer::render(std::uint32_t index, const CameraPose& pose, bool keep_levels) {
  return impl_->render(index, pose, keep_levels);
}

const gl::ContextInfo& Renderer::gl_info() const { return impl_->context.info(); }

}  // namespace nbsim::capture

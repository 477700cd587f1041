// The relief walks on GL; see gl_walk.h.
#include "traces/capture/relief/gl_walk.h"

#include <zlib.h>

#include <chrono>
#include <cstring>
#include <stdexcept>

#include "model/common/error.h"
#include "traces/capture/glsl_nbuffer.h"
#include "traces/capture/gl_program.h"
#include "traces/capture/readback.h"
#include "nbsim_shaders.h"
#include "model/relief/roles.h"

namespace nbsim::capture {

namespace {
constexpr int kWords = 6;  // relief.frag's record: ran, hit, t, lookups, steps, bisections
}

struct GlReliefWalker::Objects {
  GLuint program = 0, keep = 0, vao = 0, vbo = 0, ebo = 0, results = 0, fbo = 0, depth = 0, colour = 0;
  GLuint heights = 0, radii = 0;
  std::unique_ptr<GlslNBuffer> nbuffer;
  ~Objects() {
    glDeleteProgram(program);
    glDeleteProgram(keep);
    glDeleteVertexArrays(1, &vao);
    GLuint buffers[] = {vbo, ebo, results};
    glDeleteBuffers(3, buffers);
    glDeleteFramebuffers(1, &fbo);
    GLuint textures[] = {depth, colour, heights, radii};
    glDeleteTextures(4, textures);
  }
};

GlReliefWalker::GlReliefWalker(int width, int height, CoveringSpec covering, relief::BoxDepth box_depth)
    : gl_(std::make_unique<Objects>()), width_(width), height_(height), covering_(covering), box_depth_(box_depth) {
  NBSIM_CHECK(width > 0 && height > 0, "relief viewport");
  Objects& o = *gl_;
  const std::string defines = covering_glsl(covering) + "#define BOX_DEPTH " + std::to_string(static_cast<int>(box_depth)) + "\n";
  o.program = link_program({compile_shader(GL_VERTEX_SHADER, shaders::relief_relief_vert, "relief/relief.vert"),
                            compile_shader(GL_FRAGMENT_SHADER, with_defines(shaders::relief_relief_frag, defines), "relief/relief.frag")},
                           "relief", true);
  if (box_depth == relief::BoxDepth::Box)
    o.keep = link_program({compile_shader(GL_VERTEX_SHADER, shaders::relief_relief_vert, "relief/relief.vert"),
                           compile_shader(GL_FRAGMENT_SHADER, shaders::relief_relief_keep_frag, "relief/relief_keep.frag")},
                          "relief keep");
  glCreateVertexArrays(1, &o.vao);
  glCreateBuffers(1, &o.vbo);
  glCreateBuffers(1, &o.ebo);
  // Twelve triangles, counter-clockwise seen from outside the box.
  static const std::uint32_t kIndices[36] = {0, 2, 1, 1, 2, 3,  4, 5, 6, 5, 7, 6,  0, 1, 4, 1, 5, 4,
                                             2, 6, 3, 3, 6, 7,  0, 4, 2, 2, 4, 6,  1, 3, 5, 3, 7, 5};
  glNamedBufferStorage(o.ebo, sizeof(kIndices), kIndices, 0);
  glNamedBufferStorage(o.vbo, 8 * 3 * sizeof(float), nullptr, GL_DYNAMIC_STORAGE_BIT);
  glVertexArrayVertexBuffer(o.vao, 0, o.vbo, 0, 3 * sizeof(float));
  glVertexArrayElementBuffer(o.vao, o.ebo);
  glEnableVertexArrayAttrib(o.vao, 0);
  glVertexArrayAttribFormat(o.vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(o.vao, 0, 0);
  glCreateBuffers(1, &o.results);
  glNamedBufferStorage(o.results, static_cast<GLsizeiptr>(std::size_t{4} * kWords * width * height), nullptr,
                       GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);
  glCreateTextures(GL_TEXTURE_2D, 1, &o.depth);
  glTextureStorage2D(o.depth, 1, GL_DEPTH_COMPONENT32F, width, height);
  glCreateTextures(GL_TEXTURE_2D, 1, &o.colour);
  glTextureStorage2D(o.colour, 1, GL_R32UI, width, height);
  glCreateFramebuffers(1, &o.fbo);
  glNamedFramebufferTexture(o.fbo, GL_DEPTH_ATTACHMENT, o.depth, 0);
  glNamedFramebufferTexture(o.fbo, GL_COLOR_ATTACHMENT0, o.colour, 0);
  glNamedFramebufferDrawBuffer(o.fbo, GL_COLOR_ATTACHMENT0);
  if (glCheckNamedFramebufferStatus(o.fbo, GL_DRAW_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error("relief: framebuffer incomplete");
}

GlReliefWalker::~GlReliefWalker() = default;

int GlReliefWalker::level_count() const noexcept { return gl_->nbuffer ? gl_->nbuffer->levels() : 0; }

void GlReliefWalker::set_field(const relief::Heightfield& field, const relief::SafetyRadius& radius, DrawRecorder& recorder) {
  Objects& o = *gl_;
  const int n = field.size;
  size_ = n;
  GLuint old[] = {o.heights, o.radii};
  glDeleteTextures(2, old);
  const auto texture = [n](const float* data) {
    GLuint t = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &t);
    glTextureStorage2D(t, 1, GL_R32F, n, n);
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureSubImage2D(t, 0, 0, 0, n, n, GL_RED, GL_FLOAT, data);
    return t;
  };
  o.heights = texture(field.heights.data());
  const std::vector<float> zeros(static_cast<std::size_t>(n) * n, 0.0f);
  o.radii = texture(radius.radius.size() == zeros.size() ? radius.radius.data() : zeros.data());
  o.nbuffer = std::make_unique<GlslNBuffer>(n, n, FarOp::Max);
  scene::DepthState state;
  state.test = false;
  state.write = false;
  state.cull = scene::CullFace::Back;
  o.nbuffer->build(o.heights, recorder, state);
  const float corners[8][3] = {{0, 0, 0}, {static_cast<float>(n), 0, 0}, {0, static_cast<float>(n), 0},
                               {static_cast<float>(n), static_cast<float>(n), 0}, {0, 0, 1}, {static_cast<float>(n), 0, 1},
                               {0, static_cast<float>(n), 1}, {static_cast<float>(n), static_cast<float>(n), 1}};
  glNamedBufferSubData(o.vbo, 0, sizeof(corners), corners);
}

std::vector<float> GlReliefWalker::levels() const {
  NBSIM_CHECK(gl_->nbuffer != nullptr, "relief: levels before set_field");
  return gl_->nbuffer->read().texels;
}

void GlReliefWalker::clear_depth() {
  glDepthMask(GL_TRUE);  // a clear honours the depth write mask, which the box draws leave off
  const float far_depth = 1.0f;
  glClearNamedFramebufferfv(gl_->fbo, GL_DEPTH, 0, &far_depth);
}

GlFragments GlReliefWalker::draw(relief::Method method, const ReliefView& view, const relief::WalkParams& params, DrawRecorder& recorder,
                                 GLuint framebuffer) {
  NBSIM_CHECK(size_ > 0, "relief: draw before set_field");
  NBSIM_CHECK(params.covering == covering_, "relief: a draw's covering is not the one the walker's shader was built with");
  Objects& o = *gl_;
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, framebuffer ? framebuffer : o.fbo);
  glViewport(0, 0, width_, height_);
  glDisable(GL_BLEND);
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_STENCIL_TEST);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(box_depth_ == relief::BoxDepth::Exact ? GL_TRUE : GL_FALSE);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glFrontFace(GL_CCW);
  if (framebuffer) glColorMaski(0, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  else glColorMaski(0, GL_TRUE, GL_FALSE, GL_FALSE, GL_FALSE);
  const std::uint32_t zero = 0;
  glClearNamedBufferData(o.results, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);

  const GLuint p = o.program;
  glUseProgram(p);
  glBindVertexArray(o.vao);
  recorder.bind();
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, o.results);
  glBindTextureUnit(0, o.heights);
  glBindTextureUnit(1, o.radii);
  glBindTextureUnit(2, o.nbuffer->texture());
  glUniform1i(glGetUniformLocation(p, "heights"), 0);
  glUniform1i(glGetUniformLocation(p, "radii"), 1);
  glUniform1i(glGetUniformLocation(p, "levels"), 2);
  glUniformMatrix4fv(glGetUniformLocation(p, "texel_to_clip"), 1, GL_FALSE, view.texel_to_clip.data());
  glUniform1i(glGetUniformLocation(p, "viewport_width"), width_);
  glUniform1i(glGetUniformLocation(p, "size"), size_);
  glUniform1i(glGetUniformLocation(p, "top_level"), o.nbuffer->levels() - 1);
  glUniform1i(glGetUniformLocation(p, "method"), static_cast<int>(method));
  glUniform1i(glGetUniformLocation(p, "linear_steps"), params.linear_steps);
  glUniform1i(glGetUniformLocation(p, "binary_steps"), params.binary_steps);
  glUniform1i(glGetUniformLocation(p, "root_steps"), params.root_steps);
  glUniform3fv(glGetUniformLocation(p, "origin"), 1, view.ray.origin.data());
  glUniform3fv(glGetUniformLocation(p, "ray_a"), 1, view.ray.a.data());
  glUniform3fv(glGetUniformLocation(p, "ray_b"), 1, view.ray.b.data());
  glUniform3fv(glGetUniformLocation(p, "ray_c"), 1, view.ray.c.data());
  glUniform1i(glGetUniformLocation(p, "frustum"), view.ray.frustum ? 1 : 0);
  glUniform4fv(glGetUniformLocation(p, "eye_h"), 1, view.ray.eye_h.data());
  glUniform4fv(glGetUniformLocation(p, "ray_qa"), 1, view.ray.qa.data());
  glUniform4fv(glGetUniformLocation(p, "ray_qb"), 1, view.ray.qb.data());
  glUniform4fv(glGetUniformLocation(p, "ray_qc"), 1, view.ray.qc.data());

  scene::DrawRecord d;
  d.role = nbsim::relief::kReliefBoxRole;
  d.state.func = scene::DepthFunc::Less;
  d.state.test = true;
  d.state.write = box_depth_ != relief::BoxDepth::None;  // the paper's draw (box: the keep pass below writes)
  d.state.cull = scene::CullFace::Back;
  d.state.front_ccw = true;
  d.discards = true;
  d.writes_depth = box_depth_ == relief::BoxDepth::Exact;
  const std::size_t slot = recorder.begin_draw(std::move(d), 36);
  glUniform1ui(glGetUniformLocation(p, "draw_slot"), static_cast<GLuint>(slot));
  glDrawElements(GL_TRIANGLES, 36, GL_UNSIGNED_INT, nullptr);
  recorder.end_draw();
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
  if (box_depth_ == relief::BoxDepth::Box) {  // the hits' box depth, late (relief_keep.frag)
    glUseProgram(o.keep);
    glUniformMatrix4fv(glGetUniformLocation(o.keep, "texel_to_clip"), 1, GL_FALSE, view.texel_to_clip.data());
    glUniform1i(glGetUniformLocation(o.keep, "viewport_width"), width_);
    glColorMaski(0, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glDepthMask(GL_TRUE);
    glDrawElements(GL_TRIANGLES, 36, GL_UNSIGNED_INT, nullptr);
    glDepthMask(GL_FALSE);
  }

  std::vector<std::uint32_t> words(std::size_t{kWords} * width_ * height_);
  glGetNamedBufferSubData(o.results, 0, static_cast<GLsizeiptr>(words.size() * 4), words.data());
  GlFragments out;
  for (std::size_t px = 0; px < words.size() / kWords; ++px) {
    const std::uint32_t* w = &words[px * kWords];
    if (w[0] == 0) continue;
    out.pixel.push_back(static_cast<std::uint32_t>(px));
    out.hit.push_back(w[1]);
    float t = 0.0f;
    static_assert(sizeof t == 4);
    std::memcpy(&t, &w[2], 4);
    out.t.push_back(t);
    out.lookups.push_back(w[3]);
    out.steps.push_back(w[4]);
    out.bisections.push_back(w[5]);
  }
  glUseProgram(0);
  if (box_depth_ != relief::BoxDepth::None) {  // the depth the draw left, as a checksum (its read-back timed apart)
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<float> depth = read_depth(framebuffer ? framebuffer : o.fbo, width_, height_, scene::DepthWhich::Final).texels;
    out.depth_crc = static_cast<std::uint32_t>(
        crc32(0L, reinterpret_cast<const Bytef*>(depth.data()), static_cast<uInt>(depth.size() * sizeof(float))));
    out.readback_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  return out;
}

}  // namespace nbsim::capture

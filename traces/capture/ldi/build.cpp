// The LDI's GL stages: viewpoint selection, peel, crop, compression, and the parity test; see build.h.
#include "traces/capture/ldi/build.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "model/common/error.h"
#include "nbsim_shaders.h"
#include "traces/capture/gl_program.h"

namespace nbsim::capture {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  glFinish();
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// GL names deleted on every path out.
struct Programs {
  std::vector<GLuint> programs;
  ~Programs() {
    for (GLuint p : programs) glDeleteProgram(p);
  }
};
struct Buffers {
  std::vector<GLuint> ids;
  GLuint make() {
    GLuint b = 0;
    glCreateBuffers(1, &b);
    ids.push_back(b);
    return b;
  }
  ~Buffers() { glDeleteBuffers(static_cast<GLsizei>(ids.size()), ids.data()); }
};
struct Textures {
  std::vector<GLuint> ids;
  GLuint make(GLenum target) {
    GLuint t = 0;
    glCreateTextures(target, 1, &t);
    ids.push_back(t);
    return t;
  }
  void adopt(GLuint t) { ids.push_back(t); }
  ~Textures() { glDeleteTextures(static_cast<GLsizei>(ids.size()), ids.data()); }
};

GLuint compute_program(const char* source, const char* name) {
  return link_program({compile_shader(GL_COMPUTE_SHADER, source, name)}, name);
}

void check_gl(const char* stage) {
  if (glGetError() != GL_NO_ERROR) throw std::runtime_error(fmt::format("ldi {}: a GL call failed", stage));
}

GLuint groups(int n, int local) { return static_cast<GLuint>((n + local - 1) / local); }

// Viewpoint selection: per direction, fragments per texel into an R32UI image, read back.
void select_viewpoint(const mesh::TriMesh& m, const LdiBuildConfig& c, LdiBuild& b) {
  const int n = c.size_texels;
  Programs progs;
  const GLuint prog = link_program({compile_shader(GL_VERTEX_SHADER, shaders::ldi_peel_vert, "ldi/peel.vert"),
                                    compile_shader(GL_FRAGMENT_SHADER, shaders::ldi_count_frag, "ldi/count.frag")},
                                   "ldi viewpoint count");
  progs.programs.push_back(prog);
  Buffers bufs;
  const GLuint vbo = bufs.make(), ebo = bufs.make();
  glNamedBufferStorage(vbo, static_cast<GLsizeiptr>(m.vertices.size() * 3 * sizeof(float)), nullptr, GL_DYNAMIC_STORAGE_BIT);
  glNamedBufferStorage(ebo, static_cast<GLsizeiptr>(m.triangles.size() * sizeof(mesh::Tri)), m.triangles.data(), 0);
  GLuint vao = 0, fbo = 0;
  glCreateVertexArrays(1, &vao);
  glVertexArrayVertexBuffer(vao, 0, vbo, 0, 3 * sizeof(float));
  glVertexArrayElementBuffer(vao, ebo);
  glEnableVertexArrayAttrib(vao, 0);
  glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(vao, 0, 0);
  Textures tex;
  const GLuint counts = tex.make(GL_TEXTURE_2D);
  glTextureStorage2D(counts, 1, GL_R32UI, n, n);
  glCreateFramebuffers(1, &fbo);  // no attachments: the fragments only count
  glNamedFramebufferParameteri(fbo, GL_FRAMEBUFFER_DEFAULT_WIDTH, n);
  glNamedFramebufferParameteri(fbo, GL_FRAMEBUFFER_DEFAULT_HEIGHT, n);

  GLint old_origin = 0, old_depth = 0;
  glGetIntegerv(GL_CLIP_ORIGIN, &old_origin);
  glGetIntegerv(GL_CLIP_DEPTH_MODE, &old_depth);
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);  // as the peel: the same clipping, the same fragments
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
  glViewport(0, 0, n, n);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_SCISSOR_TEST);
  glUseProgram(prog);
  glBindVertexArray(vao);
  glBindImageTexture(0, counts, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);

  const std::size_t directions = static_cast<std::size_t>(c.grid_h) * static_cast<std::size_t>(c.grid_v);
  b.candidate_d.assign(directions, 0);
  b.candidate_coverage.assign(directions, 0);
  std::vector<float> vertices(m.vertices.size() * 3);
  std::vector<std::uint32_t> image(static_cast<std::size_t>(n) * n);
  for (int v = 0; v < c.grid_v; ++v)
    for (int h = 0; h < c.grid_h; ++h) {
      const std::size_t dir = static_cast<std::size_t>(v) * c.grid_h + h;
      const OrthoMapping map = OrthoMapping::fit_unit_cube(grid_frame(h, v, c.grid_h, c.grid_v), n, n);
      for (std::size_t i = 0; i < m.vertices.size(); ++i) {
        const auto q = map.project({m.vertices[i][0], m.vertices[i][1], m.vertices[i][2]});
        for (int a = 0; a < 3; ++a) vertices[3 * i + a] = static_cast<float>(q[a]);
      }
      glNamedBufferSubData(vbo, 0, static_cast<GLsizeiptr>(vertices.size() * sizeof(float)), vertices.data());
      const GLuint zero = 0;
      glClearTexImage(counts, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
      glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
      glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(m.triangles.size() * 3), GL_UNSIGNED_INT, nullptr);
      glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
      glGetTextureImage(counts, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, static_cast<GLsizei>(image.size() * 4), image.data());
      std::uint32_t d = 0, covered = 0;
      for (std::uint32_t k : image) d = std::max(d, k), covered += k > 0;
      b.candidate_d[dir] = d;
      b.candidate_coverage[dir] = covered;
    }
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glClipControl(static_cast<GLenum>(old_origin), static_cast<GLenum>(old_depth));
  glDeleteFramebuffers(1, &fbo);
  glDeleteVertexArrays(1, &vao);
  check_gl("viewpoint selection");
  std::size_t best = 0;
  for (std::size_t i = 1; i < directions; ++i)
    if (b.candidate_d[i] < b.candidate_d[best] ||
        (b.candidate_d[i] == b.candidate_d[best] && b.candidate_coverage[i] > b.candidate_coverage[best]))
      best = i;
  b.direction = static_cast<std::uint32_t>(best);
}

// The crop shader: the bounding rectangle of the texels with a valid layer 0.
Rect gl_crop(GLuint layers, int n) {
  Programs progs;
  const GLuint prog = compute_program(shaders::ldi_crop_comp, "ldi/crop.comp");
  progs.programs.push_back(prog);
  Buffers bufs;
  const GLuint bounds = bufs.make();
  const std::int32_t init[4] = {std::numeric_limits<std::int32_t>::max(), std::numeric_limits<std::int32_t>::max(), -1, -1};
  glNamedBufferStorage(bounds, sizeof(init), init, 0);
  glUseProgram(prog);
  glBindTextureUnit(0, layers);
  glUniform1i(glGetUniformLocation(prog, "layers"), 0);
  glUniform2i(glGetUniformLocation(prog, "size"), n, n);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, bounds);
  glDispatchCompute(groups(n, 8), groups(n, 8), 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::int32_t r[4] = {};
  glGetNamedBufferSubData(bounds, 0, sizeof(r), r);
  check_gl("crop");
  if (r[2] < 0) return Rect{};
  return Rect{r[0], r[1], r[2] - r[0] + 1, r[3] - r[1] + 1};
}

// The three compression shaders; the texture read back.
ldi::CompressedLdi gl_compress(GLuint layers, const ldi::Ldi& l, const ldi::Crop& crop) {
  ldi::CompressedLdi c;
  c.source_width = l.width();
  c.source_height = l.height();
  c.source_layers = l.layer_count();
  c.crop = crop;
  const Rect& r = crop.rect;
  if (r.w <= 0 || r.h <= 0) return c;  // nothing to compress: side 0
  const std::uint32_t entries = static_cast<std::uint32_t>(r.w) * static_cast<std::uint32_t>(r.h);
  Programs progs;
  const GLuint count = compute_program(shaders::ldi_compress_count_comp, "ldi/compress_count.comp");
  progs.programs.push_back(count);
  const GLuint scan = compute_program(shaders::ldi_compress_scan_comp, "ldi/compress_scan.comp");
  progs.programs.push_back(scan);
  const GLuint write = compute_program(shaders::ldi_compress_write_comp, "ldi/compress_write.comp");
  progs.programs.push_back(write);
  Buffers bufs;
  const GLuint layer_count = bufs.make(), range_count = bufs.make(), offsets = bufs.make(), total = bufs.make();
  for (GLuint buf : {layer_count, range_count, offsets}) glNamedBufferStorage(buf, GLsizeiptr{entries} * 4, nullptr, 0);
  glNamedBufferStorage(total, 4, nullptr, 0);
  glBindTextureUnit(0, layers);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, layer_count);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, range_count);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, offsets);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, total);

  glUseProgram(count);
  glUniform1i(glGetUniformLocation(count, "layers"), 0);
  glUniform4i(glGetUniformLocation(count, "crop"), r.x, r.y, r.w, r.h);
  glUniform1i(glGetUniformLocation(count, "depth_complexity"), crop.depth_complexity);
  glDispatchCompute(groups(r.w, 8), groups(r.h, 8), 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  glUseProgram(scan);
  glUniform1ui(glGetUniformLocation(scan, "entries"), entries);
  glDispatchCompute(1, 1, 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  std::uint32_t ranges = 0;
  glGetNamedBufferSubData(total, 0, 4, &ranges);

  c.index_texels = entries;
  c.range_texels = ranges;
  const std::uint32_t side = ldi::ceil_sqrt(std::uint64_t{entries} + ranges);
  if (side > static_cast<std::uint32_t>(ldi::kMaxSideTexels))
    throw InputError(fmt::format("ldi compression: the compressed texture's side {} exceeds {}", side, ldi::kMaxSideTexels));
  c.side = static_cast<int>(side);
  Textures tex;
  const GLuint out = tex.make(GL_TEXTURE_2D);
  glTextureStorage2D(out, 1, GL_RG32UI, c.side, c.side);
  const GLuint zero[2] = {0, 0};
  glClearTexImage(out, 0, GL_RG_INTEGER, GL_UNSIGNED_INT, zero);  // the padding
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
  glUseProgram(write);
  glUniform1i(glGetUniformLocation(write, "layers"), 0);
  glUniform4i(glGetUniformLocation(write, "crop"), r.x, r.y, r.w, r.h);
  glUniform1ui(glGetUniformLocation(write, "index_texels"), entries);
  glUniform1ui(glGetUniformLocation(write, "side"), side);
  glBindImageTexture(0, out, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RG32UI);
  glDispatchCompute(groups(r.w, 8), groups(r.h, 8), 1);
  glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
  c.texels.resize(2 * std::size_t{side} * side);
  glGetTextureImage(out, 0, GL_RG_INTEGER, GL_UNSIGNED_INT, static_cast<GLsizei>(c.texels.size() * 4), c.texels.data());
  check_gl("compression");
  return c;
}

}  // namespace

mesh::OrthoFrame grid_frame(int h, int v, int grid_h, int grid_v) {
  const double phi = 2.0 * std::numbers::pi * (h + 0.5) / grid_h;
  const double y = -1.0 + 2.0 * (v + 0.5) / grid_v;
  const double r = std::sqrt(std::max(0.0, 1.0 - y * y));
  return mesh::OrthoFrame::look_along({r * std::cos(phi), y, r * std::sin(phi)}, {0.0, 1.0, 0.0});
}

LdiBuild build_ldi(const mesh::TriMesh& m, const LdiBuildConfig& config, DrawRecorder* recorder) {
  if (config.size_texels < 1 || config.size_texels > ldi::kMaxSideTexels)
    throw InputError(fmt::format("ldi: size {} outside [1, {}]", config.size_texels, ldi::kMaxSideTexels));
  if (config.grid_h < 1 || config.grid_v < 1 || config.grid_h > 1024 || config.grid_v > 1024)
    throw InputError(fmt::format("ldi: viewpoint grid {}x{}: each side must be 1 to 1024", config.grid_h, config.grid_v));
  if (config.max_layers < 1 || config.max_layers > ldi::kMaxLayers)
    throw InputError(fmt::format("ldi: max_layers {} outside [1, {}]", config.max_layers, ldi::kMaxLayers));
  for (const mesh::Tri& t : m.triangles)
    for (std::uint32_t i : t)
      if (i >= m.vertices.size()) throw InputError("ldi: the mesh has an out-of-range vertex index");
  LdiBuild b;
  auto t0 = Clock::now();
  select_viewpoint(m, config, b);
  b.times.viewpoint_ms = ms_since(t0);

  const int h = static_cast<int>(b.direction % static_cast<std::uint32_t>(config.grid_h));
  const int v = static_cast<int>(b.direction / static_cast<std::uint32_t>(config.grid_h));
  LdiBuild rest = build_ldi_along(m, grid_frame(h, v, config.grid_h, config.grid_v), config.size_texels, config.max_layers, recorder);
  rest.candidate_d = std::move(b.candidate_d);
  rest.candidate_coverage = std::move(b.candidate_coverage);
  rest.direction = b.direction;
  rest.times.viewpoint_ms = b.times.viewpoint_ms;
  return rest;
}

LdiBuild build_ldi_along(const mesh::TriMesh& m, const mesh::OrthoFrame& frame, int n, int max_layers, DrawRecorder* recorder) {
  LdiBuild b;
  auto t0 = Clock::now();
  b.map = OrthoMapping::fit_unit_cube(frame, n, n);
  b.peel = peel_ldi(m, frame, {.width_px = n, .height_px = n, .max_layers = max_layers, .keep_gl_layers = true}, recorder);
  b.times.peel_ms = ms_since(t0);
  Textures owned;
  owned.adopt(b.peel.gl_layers);
  const GLuint layers = b.peel.gl_layers;
  b.peel.gl_layers = 0;

  t0 = Clock::now();
  b.crop.rect = gl_crop(layers, n);
  // d: the peel ends at its first empty pass, so every stored layer holds some texel's layer and
  // the layer count is the depth complexity.
  b.crop.depth_complexity = b.peel.ldi.layer_count();
  b.times.crop_ms = ms_since(t0);

  t0 = Clock::now();
  b.compressed = gl_compress(layers, b.peel.ldi, b.crop);
  b.times.compression_ms = ms_since(t0);
  return b;
}

void upload_vpt_textures(const LdiBuild& b, GLuint cropped, GLuint compressed) {
  const Rect& r = b.crop.rect;
  const int d = b.crop.depth_complexity;
  const ldi::Ldi& l = b.peel.ldi;
  if (r.w > 0 && r.h > 0 && d > 0) {
    // The cropped layered texture: GL's layers inside GL's crop, d deep.
    std::vector<float> texels(static_cast<std::size_t>(r.w) * r.h * d);
    for (int k = 0; k < d; ++k)
      for (int cy = 0; cy < r.h; ++cy)
        for (int cx = 0; cx < r.w; ++cx)
          texels[(static_cast<std::size_t>(k) * r.h + cy) * r.w + cx] = l.depth(r.x + cx, r.y + cy, k);
    glTextureStorage3D(cropped, 1, GL_R32F, r.w, r.h, d);
    glTextureSubImage3D(cropped, 0, 0, 0, 0, r.w, r.h, d, GL_RED, GL_FLOAT, texels.data());
    glTextureStorage2D(compressed, 1, GL_RG32UI, b.compressed.side, b.compressed.side);
    glTextureSubImage2D(compressed, 0, 0, 0, b.compressed.side, b.compressed.side, GL_RG_INTEGER, GL_UNSIGNED_INT,
                        b.compressed.texels.data());
  } else {
    const float inf = ldi::kInvalidDepth;
    const GLuint zero[2] = {0, 0};
    glTextureStorage3D(cropped, 1, GL_R32F, 1, 1, 1);
    glTextureSubImage3D(cropped, 0, 0, 0, 0, 1, 1, 1, GL_RED, GL_FLOAT, &inf);
    glTextureStorage2D(compressed, 1, GL_RG32UI, 1, 1);
    glTextureSubImage2D(compressed, 0, 0, 0, 1, 1, GL_RG_INTEGER, GL_UNSIGNED_INT, zero);
  }
  for (GLuint t : {cropped, compressed}) {
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  }
}

GlVptAnswers gl_vpt(const LdiBuild& b, const std::vector<std::int32_t>& x, const std::vector<std::int32_t>& y,
                    const std::vector<float>& z) {
  if (x.size() != y.size() || x.size() != z.size()) throw std::invalid_argument("gl_vpt: point vectors of unequal length");
  const std::size_t count = x.size();
  GlVptAnswers a;
  a.inside_layers.resize(count);
  a.fetches_layers.resize(count);
  a.inside_ranges.resize(count);
  a.fetches_ranges.resize(count);
  a.inside_all.resize(count);
  a.fetches_all.resize(count);
  if (count == 0) return a;
  const Rect& r = b.crop.rect;
  const int d = b.crop.depth_complexity;
  const bool any = r.w > 0 && r.h > 0 && d > 0;
  Textures tex;
  const GLuint cropped = tex.make(GL_TEXTURE_2D_ARRAY), compressed = tex.make(GL_TEXTURE_2D);
  upload_vpt_textures(b, cropped, compressed);
  std::vector<std::int32_t> points(4 * count);
  for (std::size_t p = 0; p < count; ++p) {
    points[4 * p] = x[p];
    points[4 * p + 1] = y[p];
    points[4 * p + 2] = std::bit_cast<std::int32_t>(z[p]);
  }
  Programs progs;
  const GLuint prog = compute_program(shaders::ldi_vpt_comp, "ldi/vpt.comp");
  progs.programs.push_back(prog);
  Buffers bufs;
  const GLuint in = bufs.make(), out = bufs.make(), out_all = bufs.make();
  glNamedBufferStorage(in, static_cast<GLsizeiptr>(points.size() * 4), points.data(), 0);
  glNamedBufferStorage(out, static_cast<GLsizeiptr>(count * 16), nullptr, 0);
  glNamedBufferStorage(out_all, static_cast<GLsizeiptr>(count * 8), nullptr, 0);
  glUseProgram(prog);
  glBindTextureUnit(0, cropped);
  glBindTextureUnit(1, compressed);
  glUniform1i(glGetUniformLocation(prog, "cropped"), 0);
  glUniform1i(glGetUniformLocation(prog, "compressed"), 1);
  glUniform4i(glGetUniformLocation(prog, "crop"), r.x, r.y, any ? r.w : 0, any ? r.h : 0);
  glUniform1i(glGetUniformLocation(prog, "depth_complexity"), d);
  glUniform1ui(glGetUniformLocation(prog, "side"), static_cast<GLuint>(std::max(1, b.compressed.side)));
  glUniform1ui(glGetUniformLocation(prog, "count"), static_cast<GLuint>(count));
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, in);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, out_all);
  glDispatchCompute(groups(static_cast<int>(count), 64), 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<std::uint32_t> res(4 * count);
  glGetNamedBufferSubData(out, 0, static_cast<GLsizeiptr>(res.size() * 4), res.data());
  std::vector<std::uint32_t> all(2 * count);
  glGetNamedBufferSubData(out_all, 0, static_cast<GLsizeiptr>(all.size() * 4), all.data());
  check_gl("parity test");
  for (std::size_t p = 0; p < count; ++p) {
    a.inside_layers[p] = res[4 * p];
    a.fetches_layers[p] = res[4 * p + 1];
    a.inside_ranges[p] = res[4 * p + 2];
    a.fetches_ranges[p] = res[4 * p + 3];
    a.inside_all[p] = all[2 * p];
    a.fetches_all[p] = all[2 * p + 1];
  }
  return a;
}

VptScore score_vpt(const GlVptAnswers& gl, const std::vector<std::int32_t>& reference) {
  VptScore v;
  for (std::size_t p = 0; p < reference.size(); ++p) {
    v.fetches_layers += gl.fetches_layers[p];
    v.fetches_ranges += gl.fetches_ranges[p];
    v.readers_disagree += gl.inside_layers[p] != gl.inside_ranges[p];
    if (reference[p] < 0) {
      ++v.near_surface;
      continue;
    }
    const std::uint32_t inside = static_cast<std::uint32_t>(reference[p]) & 1u;
    v.wrong_layers += gl.inside_layers[p] != inside;
    v.wrong_ranges += gl.inside_ranges[p] != inside;
  }
  return v;
}

}  // namespace nbsim::capture

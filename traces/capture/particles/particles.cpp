// The particles technique; see particles.h.
#include "traces/capture/particles/particles.h"

#include <fmt/format.h>

#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>

#include "model/common/error.h"
#include "model/particles/sprite.h"
#include "model/scene/visibility.h"
#include "nbsim_shaders.h"
#include "traces/capture/draw_recorder.h"
#include "traces/capture/glsl_nbuffer.h"
#include "traces/capture/particles/glsl_hiz.h"
#include "traces/capture/particles/particle_systems.h"
#include "traces/capture/readback.h"
#include "traces/capture/render_target.h"
#include "traces/capture/scene_pass.h"
#include "traces/format/particles/particles_chunk.h"
#include "model/particles/roles.h"

namespace nbsim::capture {

namespace {

using scene::DrawRecord;
using scene::DrawRole;

// Margin a sprite's depth must be behind the farthest depth by to be culled, so that the vertex
// shader's window depth and GL's (computed apart) can never disagree across it. Tunable; 1e-6
// is ~16 float ulps at 1, as occlusion culling's nearest_margin.
constexpr float kMargin = 1e-6f;
// Attenuated sprites: a particle 0.6 m across (tunable), sides rounded to whole pixels in [1, 64].
constexpr double kParticleWidthM = 0.6;
constexpr float kMinAttenuatedPx = 1.0f;
using particles::kMaxAttenuatedPx;
// Emitters of --emitters auto (tunable).
constexpr int kAutoEmitters = 12;
// Bounds of --particles: a frame's records must stay within the format's per-frame limit (64 MiB +
// 128 bytes a viewport pixel, FORMAT.md "Limits"): a particle takes 52 bytes there (32 in PRTC, 20
// in its draw's clip position and point size), so 500,000 take 26 MB.
constexpr std::int64_t kMaxParticles = 500000;

using particles::Mode;  // the model's: the trace's particle_mode names are kModeNames
using particles::kModeNames;
constexpr std::array<const char*, 4> kModeDefines = {"MODE_NONE", "MODE_CENTER", "MODE_NB", "MODE_HIZ"};

const OptionSpec& particles_option() {
  static const OptionSpec spec = integer_option("particles", "Particles a frame, shared out over the emitters", 10000, 1, kMaxParticles);
  return spec;
}
const OptionSpec& sprite_option() {
  static const OptionSpec spec =
      choice_option("sprite", "Sprite side: 16 or 24 pixels, or atten (distance-attenuated, 1 to 64 pixels)", "16", {"16", "24", "atten"});
  return spec;
}
const OptionSpec& mode_option() {
  static const OptionSpec spec = choice_option("mode",
                                                "Vertex-stage culling: none, center (one depth lookup at the centre: pops), nb (the "
                                                "N-buffer: 1 to 4 lookups), hiz (a Hi-Z pyramid, 1 to 4 lookups)",
                                                "nb", {kModeNames.begin(), kModeNames.end()});
  return spec;
}
const OptionSpec& level_cap_option() {
  static const OptionSpec spec = integer_option(
      "level-cap", "Highest N-buffer (or Hi-Z) level built; sprites that need a higher one are never culled", 5, 0, 12);
  return spec;
}
const OptionSpec& emitters_option() {
  static const OptionSpec spec = text_option("emitters",
                                              "auto (12 emitters around the site's centre) or ground positions X:Z,X:Z,... in metres, "
                                              "kinds in turn smoke, fire, sparks, birds; each must be inside the scene",
                                              "auto");
  return spec;
}
const OptionSpec& levels_every_option() {
  static const OptionSpec spec = levels_every_spec("the GLSL N-buffer levels");
  return spec;
}
// The vertex stage reads only the levels built, so the one-square covering (which may need a
// level above them) is not offered; a power-of-two sprite is one lookup under either.
const OptionSpec& particles_covering_option() {
  static const OptionSpec spec = covering_option({"paper", "corners"});
  return spec;
}

// "X:Z,X:Z" -> positions; throws InputError naming the bad item.
std::vector<std::pair<double, double>> parse_emitters(const std::string& text) {
  std::vector<std::pair<double, double>> out;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    const std::string item = text.substr(pos, comma - pos);
    const std::size_t colon = item.find(':');
    double x = 0, z = 0;
    std::size_t nx = 0, nz = 0;
    bool ok = colon != std::string::npos;
    try {
      if (ok) {
        x = std::stod(item.substr(0, colon), &nx);
        z = std::stod(item.substr(colon + 1), &nz);
        ok = nx == colon && nz == item.size() - colon - 1 && std::isfinite(x) && std::isfinite(z);
      }
    } catch (const std::exception&) {
      ok = false;
    }
    if (!ok)
      throw InputError(fmt::format("--emitters: '{}' is not a ground position X:Z in metres (write auto or X:Z,X:Z,...)", item));
    out.emplace_back(x, z);
    pos = comma + 1;
  }
  if (out.size() > 256) throw InputError(fmt::format("--emitters: {} emitters, more than the limit of 256", out.size()));
  return out;
}


class Particles final : public Technique {
 public:
  explicit Particles(const TechniqueSetup& s);
  ~Particles() override;
  Particles(const Particles&) = delete;
  Particles& operator=(const Particles&) = delete;

  trace::Properties variant_properties() const override {
    return {{"particle_mode", std::string(kModeNames[static_cast<std::size_t>(mode_)])}, {"sprite", sprite_}};
  }
  trace::Properties setting_properties() const override {
    return {{"particles", std::to_string(count_)},
            {"emitters", emitters_text_},
            {"level_cap", std::to_string(level_cap_)},
            {"levels_built", std::to_string(levels_built_)},
            {"cull_margin", fmt::format("{}", kMargin)},
            {"levels_every", std::to_string(levels_every_)},
            covering_property(covering_)};
  }

  CapturedFrame render(std::uint32_t index, const CameraPose& pose) override;

 private:
  void set_uniforms(GLuint program, const glm::mat4& view_proj) const;

  const CaptureScene& scene_;
  int width_, height_;
  Projection projection_;
  bool reversed_;
  Mode mode_;
  std::string sprite_;
  std::uint32_t count_;
  int level_cap_, levels_built_ = 0, levels_every_;
  CoveringSpec covering_;  // of mode nb's lookups
  std::string emitters_text_;
  std::uint32_t seed_;
  std::vector<Emitter> emitters_;
  ScenePass pass_;
  RenderTarget target_;
  DrawRecorder recorder_;
  std::unique_ptr<GlslNBuffer> nbuffer_;  // mode nb
  std::unique_ptr<GlslHiZ> hiz_;          // mode hiz
  GLuint particle_prog_ = 0, reference_prog_ = 0, vao_ = 0, vbo_ = 0, decisions_ = 0, reference_ = 0;
  GLuint depth_copy_ = 0;  // mode center: a copy of the scene depth, sampled
};

Particles::Particles(const TechniqueSetup& s)
    : scene_(s.scene),
      width_(s.width),
      height_(s.height),
      projection_(s.projection),
      reversed_(s.projection.reversed_z),
      mode_(static_cast<Mode>(std::find(mode_option().choices.begin(), mode_option().choices.end(), s.options.text(mode_option())) -
                              mode_option().choices.begin())),
      sprite_(s.options.text(sprite_option())),
      count_(static_cast<std::uint32_t>(s.options.integer(particles_option()))),
      level_cap_(static_cast<int>(s.options.integer(level_cap_option()))),
      levels_every_(static_cast<int>(s.options.integer(levels_every_option()))),
      covering_(read_covering(s.options, particles_covering_option())),
      emitters_text_(s.options.text(emitters_option())),
      seed_(static_cast<std::uint32_t>(s.options.integer(seed_option()))),
      pass_(s.scene, false),
      target_(s.width, s.height) {
  emitters_ = emitters_text_ == "auto" ? place_emitters(s.scene.site, kAutoEmitters, count_, seed_)
                                       : emitters_at(s.scene.site, parse_emitters(emitters_text_), count_);
  if (reversed_) glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  const FarOp op = reversed_ ? FarOp::Min : FarOp::Max;
  // The largest sprite's pixel rectangle gives the level it needs (the model computes it alike).
  const int largest = sprite_ == "atten" ? static_cast<int>(particles::kMaxAttenuatedPx) : std::stoi(sprite_);
  if (mode_ == Mode::NBuffer) {
    nbuffer_ = std::make_unique<GlslNBuffer>(width_, height_, op,
                                             particles::top_level_needed(Mode::NBuffer, largest, level_cap_));
    levels_built_ = nbuffer_->levels();
  } else if (mode_ == Mode::HiZ) {
    hiz_ = std::make_unique<GlslHiZ>(width_, height_, op, particles::top_level_needed(Mode::HiZ, largest, level_cap_));
    levels_built_ = hiz_->levels();
  }

  std::string defines = fmt::format("#define {}\n", kModeDefines[static_cast<std::size_t>(mode_)]);
  defines += reversed_ ? "#define ZERO_TO_ONE\n#define FAR(a, b) min(a, b)\n#define HIDDEN(d, f) ((d) + margin < (f))\n"
                       : "#define FAR(a, b) max(a, b)\n#define HIDDEN(d, f) ((d) - margin > (f))\n";
  defines += covering_glsl(covering_);
  particle_prog_ = link_program({compile_shader(GL_VERTEX_SHADER, with_defines(shaders::particles_particles_vert, defines),
                                                "particles/particles.vert"),
                                 compile_shader(GL_FRAGMENT_SHADER, shaders::common_count_frag, "common/count.frag")},
                                "particles", true, true);
  reference_prog_ = link_program({compile_shader(GL_VERTEX_SHADER, with_defines(shaders::particles_particles_vert, "#define REFERENCE\n"),
                                                 "particles/particles.vert (reference)"),
                                  compile_shader(GL_FRAGMENT_SHADER, shaders::particles_reference_frag, "particles/reference.frag")},
                                 "particles_reference");
  const auto bytes = [&](std::size_t per) { return static_cast<GLsizeiptr>(std::max<std::size_t>(count_, 1) * per); };
  glCreateBuffers(1, &vbo_);
  glNamedBufferStorage(vbo_, bytes(16), nullptr, GL_DYNAMIC_STORAGE_BIT);
  glCreateVertexArrays(1, &vao_);
  glVertexArrayVertexBuffer(vao_, 0, vbo_, 0, 16);
  glEnableVertexArrayAttrib(vao_, 0);
  glVertexArrayAttribFormat(vao_, 0, 4, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(vao_, 0, 0);
  glCreateBuffers(1, &decisions_);
  glNamedBufferStorage(decisions_, bytes(32), nullptr, GL_DYNAMIC_STORAGE_BIT);
  glCreateBuffers(1, &reference_);
  glNamedBufferStorage(reference_, bytes(4), nullptr, GL_DYNAMIC_STORAGE_BIT);
  if (mode_ == Mode::Center) {
    glCreateTextures(GL_TEXTURE_2D, 1, &depth_copy_);
    glTextureStorage2D(depth_copy_, 1, GL_DEPTH_COMPONENT32F, width_, height_);
    glTextureParameteri(depth_copy_, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(depth_copy_, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  }
}

Particles::~Particles() {
  glDeleteProgram(particle_prog_);
  glDeleteProgram(reference_prog_);
  glDeleteVertexArrays(1, &vao_);
  const GLuint buffers[] = {vbo_, decisions_, reference_};
  glDeleteBuffers(3, buffers);
  if (depth_copy_) glDeleteTextures(1, &depth_copy_);
}

void Particles::set_uniforms(GLuint program, const glm::mat4& view_proj) const {
  glUseProgram(program);
  glUniformMatrix4fv(glGetUniformLocation(program, "view_proj"), 1, GL_FALSE, glm::value_ptr(view_proj));
  glUniform2i(glGetUniformLocation(program, "viewport"), width_, height_);
  glUniform1f(glGetUniformLocation(program, "fixed_size"), sprite_ == "atten" ? 0.0f : std::stof(sprite_));
  const double px_per_m_at_1m = height_ / (2.0 * std::tan(projection_.fov_y_deg * 3.14159265358979323846 / 360.0));
  glUniform1f(glGetUniformLocation(program, "atten_px_m"), static_cast<float>(kParticleWidthM * px_per_m_at_1m));
  glUniform1f(glGetUniformLocation(program, "min_size"), kMinAttenuatedPx);
  glUniform1f(glGetUniformLocation(program, "max_size"), kMaxAttenuatedPx);
  glUniform1f(glGetUniformLocation(program, "margin"), kMargin);
  glUniform1i(glGetUniformLocation(program, "top_level"), levels_built_ - 1);
  glUniform1i(glGetUniformLocation(program, "depth"), 2);
  glUniform1i(glGetUniformLocation(program, "levels"), 3);
}

CapturedFrame Particles::render(std::uint32_t index, const CameraPose& pose) {
  CapturedFrame out;
  scene::Frame& f = out.frame;
  const glm::mat4 view = view_matrix(pose);
  const glm::mat4 proj = projection_matrix(projection_, static_cast<double>(width_) / height_);
  const glm::mat4 view_proj = proj * view;
  f.begin.frame = index;
  f.begin.mode = scene::TestMode::None;
  std::memcpy(f.begin.view.data(), glm::value_ptr(view), 64);
  std::memcpy(f.begin.proj.data(), glm::value_ptr(proj), 64);
  f.begin.eye = {pose.eye.x, pose.eye.y, pose.eye.z};
  const scene::FrameView v = scene::FrameView::make(f.begin, width_, height_, projection_.near_m, 0.0, reversed_, reversed_);
  const std::vector<std::uint32_t> in_frustum = scene::frustum_objects(scene_.scene, v);
  const std::vector<glm::vec4> positions = particle_positions(emitters_, index, seed_);
  if (!positions.empty())
    glNamedBufferSubData(vbo_, 0, static_cast<GLsizeiptr>(positions.size() * sizeof(glm::vec4)), positions.data());
  const GLuint zero = 0;
  glClearNamedBufferData(reference_, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glClearNamedBufferData(decisions_, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);

  const auto t0 = std::chrono::steady_clock::now();
  glBindFramebuffer(GL_FRAMEBUFFER, target_.framebuffer());
  target_.clear_depth(reversed_);
  recorder_.begin_frame(in_frustum.size() + emitters_.size() + 32);

  // 1. The scene: every object in the frustum, its depth.
  pass_.begin(target_, view_proj, reversed_, recorder_);
  for (auto o : in_frustum) {
    DrawRecord d;
    d.role = DrawRole::Scene;
    d.object = static_cast<std::int32_t>(o);
    d.state = depth_state(reversed_, true, true);
    pass_.draw_object(recorder_, std::move(d), o);
  }

  // 2. The query structure of the mode.
  scene::DepthState build_state = depth_state(reversed_, false, false);
  build_state.cull = scene::CullFace::None;
  if (nbuffer_) nbuffer_->build(target_.depth_texture(), recorder_, build_state);
  if (hiz_) hiz_->build(target_.depth_texture(), recorder_, build_state);
  if (depth_copy_)
    glCopyImageSubData(target_.depth_texture(), GL_TEXTURE_2D, 0, 0, 0, 0, depth_copy_, GL_TEXTURE_2D, 0, 0, 0, 0, width_, height_, 1);

  // 3. The particles, one draw an emitter, culled in the vertex stage.
  target_.bind();
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(reversed_ ? GL_GREATER : GL_LESS);
  glDepthMask(GL_FALSE);
  glColorMaski(0, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glEnable(GL_PROGRAM_POINT_SIZE);
  set_uniforms(particle_prog_, view_proj);
  glUniform1ui(glGetUniformLocation(particle_prog_, "object_id"), 0);
  const GLint u_slot = glGetUniformLocation(particle_prog_, "draw_slot");
  recorder_.bind();
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, decisions_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, reference_);
  if (depth_copy_) glBindTextureUnit(2, depth_copy_);
  if (nbuffer_) glBindTextureUnit(3, nbuffer_->texture());
  if (hiz_) glBindTextureUnit(3, hiz_->texture());
  glBindVertexArray(vao_);
  std::vector<std::uint32_t> draw_of(count_, 0);
  for (const Emitter& e : emitters_) {
    if (e.count == 0) continue;
    DrawRecord d;
    d.role = nbsim::particles::kParticlesRole;
    d.state = depth_state(reversed_, false, true);
    d.state.cull = scene::CullFace::None;  // points have no faces
    const std::size_t slot = recorder_.begin_draw(std::move(d), e.count, GL_POINTS);
    glUniform1ui(u_slot, static_cast<GLuint>(slot));
    glDrawArrays(GL_POINTS, static_cast<GLint>(e.first), static_cast<GLsizei>(e.count));
    recorder_.end_draw();
    std::fill(draw_of.begin() + e.first, draw_of.begin() + e.first + e.count, static_cast<std::uint32_t>(slot));
  }
  glFinish();
  f.end.gl_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  // 4. The reference: every particle, the same depth test, a passed-sample counter each.
  set_uniforms(reference_prog_, view_proj);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(count_));
  glDisable(GL_PROGRAM_POINT_SIZE);
  glDepthMask(GL_TRUE);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);

  scene::DepthSnapshot depth = read_depth(target_.framebuffer(), width_, height_, scene::DepthWhich::Final);
  depth.name = "scene";
  f.depths.push_back(std::move(depth));
  if (nbuffer_ && levels_every_ > 0 && index % static_cast<std::uint32_t>(levels_every_) == 0) {
    f.levels.push_back(nbuffer_->read());
    f.levels.back().source = "scene";
  }
  f.draws = recorder_.collect();

  struct Decision {
    float window[4];
    std::uint32_t culled, lookups, pad0, pad1;
  };
  static_assert(sizeof(Decision) == 32);
  std::vector<Decision> decisions(count_);
  std::vector<std::uint32_t> samples(count_);
  glGetNamedBufferSubData(decisions_, 0, static_cast<GLsizeiptr>(count_ * sizeof(Decision)), decisions.data());
  glGetNamedBufferSubData(reference_, 0, static_cast<GLsizeiptr>(count_ * 4), samples.data());
  std::vector<float> x(count_), y(count_), depth_w(count_), size(count_);
  std::vector<std::uint32_t> culled(count_), lookups(count_);
  std::uint64_t n_culled = 0, n_popping = 0, n_lookups = 0, n_visible = 0;
  for (std::uint32_t p = 0; p < count_; ++p) {
    const Decision& d = decisions[p];
    x[p] = d.window[0], y[p] = d.window[1], depth_w[p] = d.window[2], size[p] = d.window[3];
    culled[p] = d.culled, lookups[p] = d.lookups;
    n_culled += d.culled;
    n_lookups += d.lookups;
    n_visible += samples[p] > 0;
    n_popping += d.culled != 0 && samples[p] > 0;
  }
  trace::TechniqueRecord r;
  r.type = trace::kParticlesChunk;
  r.decoded = true;
  r.fields = {{"count", std::uint64_t{count_}},      {"draw", std::move(draw_of)}, {"x", std::move(x)},
              {"y", std::move(y)},                   {"depth", std::move(depth_w)}, {"size", std::move(size)},
              {"culled", std::move(culled)},         {"lookups", std::move(lookups)},
              {"reference_samples", std::move(samples)}};
  f.technique_records.push_back(std::move(r));
  out.counts = {{"particles", count_}, {"particles_visible", n_visible}, {"particles_culled", n_culled},
                {"popping", n_popping}, {"lookups", n_lookups}};
  f.end.frame = index;
  f.end.draws = static_cast<std::uint32_t>(f.draws.size());
  return out;
}

}  // namespace

const std::vector<OptionSpec>& particles_options() {
  static const std::vector<OptionSpec> options = {particles_option(), sprite_option(),   mode_option(),
                                                  level_cap_option(), emitters_option(), levels_every_option(),
                                                  particles_covering_option(), align_option(), seed_option()};
  return options;
}

BenchPreset particles_bench_preset() {
  return {"city", "walk", "512x512", {{"mode", "nb"}, {"levels-every", "0"}, {"particles", "10000"}, {"sprite", "16"}}, "mode", {}};
}

std::unique_ptr<Technique> make_particles(const TechniqueSetup& setup) { return std::make_unique<Particles>(setup); }

// This technique's row of the capture's table (technique.h).
TechniqueRow particles_technique() {
  return {{"particles",
           "Point-sprite particles culled in the vertex stage: none, centre lookup, partial N-buffer or Hi-Z, with a "
           "reference pass for popping (N-buffer paper, 3.2 and 4.3)",
           particles_options()},
          make_particles,
          particles_bench_preset(),
          {},
          {}};
}

}  // namespace nbsim::capture

// The shadows technique; see shadows.h.
#include "traces/capture/shadows/shadows.h"

#include <fmt/format.h>

#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <map>
#include <random>
#include <string>

#include "model/common/error.h"
#include "model/nbuffer/covering.h"
#include "model/scene/visibility.h"
#include "nbsim_shaders.h"
#include "traces/capture/draw_recorder.h"
#include "traces/capture/glsl_nbuffer.h"
#include "traces/capture/readback.h"
#include "traces/capture/render_target.h"
#include "traces/capture/scene_pass.h"
#include "traces/capture/shadows/volumes.h"
#include "traces/format/header.h"
#include "traces/format/shadows/shadows_chunk.h"
#include "model/shadows/caster.h"
#include "model/shadows/litmap.h"
#include "model/shadows/roles.h"

namespace nbsim::capture {

namespace {

using scene::DrawRecord;
using scene::DrawRole;
using trace::CasterDecision;

enum class Mode : std::uint8_t { Infinite = 0, Culled = 1, Clamped = 2 };
constexpr std::array<const char*, 3> kModeNames = {"infinite", "culled", "clamped"};

// How a clamped volume starts: "edge", the paper's rule (every point of the caster's silhouette
// edges and lit faces nearer the light than the min plane is projected onto it, the rest start at
// the caster: the faces and edges that cross the plane are split there), or "caster" (the min plane
// only when the whole caster is nearer the light than it, else the volume starts at the caster).
using nbsim::shadows::ClampRule;
// The auto light: this far above the scene's top, as a fraction of the site's side (tunable).
constexpr double kLightHeight = 0.5;

const OptionSpec& shadow_mode_option() {
  static const OptionSpec spec =
      choice_option("shadow-mode",
                    "Shadow volumes: infinite (every caster, to infinity), culled (casters with no visible "
                    "receiver behind them dropped), clamped (culled, and each volume clamped between z_min and z_max)",
                    "clamped", {kModeNames.begin(), kModeNames.end()});
  return spec;
}
const OptionSpec& clamp_rule_option() {
  static const OptionSpec spec =
      choice_option("clamp-rule",
                    "Where a clamped volume starts: edge (the paper's: each silhouette edge and lit face projected on the min plane "
                    "unless farther from the light than it, split where it crosses it) or caster (the min plane only when the whole "
                    "caster is in front of it)",
                    "edge", {std::string(nbsim::shadows::kClampRuleNames[0]), std::string(nbsim::shadows::kClampRuleNames[1])});
  return spec;
}
// The litmap pass keeps a fragment the observer may see: not farther than the farthest observer
// depth of its 3x3 pixels by more than this share of view distance plus metres (larger is more
// conservative and only loosens [z_min, z_max]).
const OptionSpec& reproject_option() {
  static const OptionSpec spec = text_option(
      "reproject-tolerance", "How far behind the observer's depth a litmap fragment still counts as seen: SHARE,METRES (of view distance)",
      "0.01,0.05");
  return spec;
}
// Clamp planes and the cull decision are widened by this share of light distance plus metres: a
// clamp plane through a receiver would make its stencil count a depth tie, and the mask's receivers
// are unprojected from 24-bit depth and rounded to f32.
const OptionSpec& clamp_margin_option() {
  static const OptionSpec spec = text_option(
      "clamp-margin", "How far each slab is widened beyond its visible receivers: SHARE,METRES (of light distance)", "0.01,0.1");
  return spec;
}
nbsim::shadows::ClampMargin read_margin(const OptionValues& options, const OptionSpec& spec) {
  const std::string text = options.text(spec);
  const std::size_t comma = text.find(',');
  const auto m = comma == std::string::npos ? std::nullopt
                                            : nbsim::shadows::parse_clamp_margin(text.substr(0, comma) + " + " + text.substr(comma + 1) + " m");
  if (!m) throw InputError(fmt::format("--{} '{}' is not SHARE,METRES with the share in 0 .. 1 and the metres in 0 .. 1000", spec.name, text));
  return *m;
}

const OptionSpec& litmap_option() {
  static const OptionSpec spec = integer_option("litmap", "Side of the square litmaps and their N-buffers, lexels", 512, 16, 4096);
  return spec;
}
const OptionSpec& light_option() {
  static const OptionSpec spec = text_option("light",
                                              "auto (a spot light above the scene circling its centre, from the seed) or a fixed light "
                                              "X,Y,Z,TX,TY,TZ: its position and the point it looks at, metres",
                                              "auto");
  return spec;
}
const OptionSpec& light_fov_option() {
  static const OptionSpec spec = integer_option("light-fov", "The spot light's field of view, degrees", 60, 1, 179);
  return spec;
}
const OptionSpec& shadows_covering_option() {
  static const OptionSpec spec = covering_option();
  return spec;
}

const OptionSpec& levels_every_option() {
  static const OptionSpec spec = levels_every_spec("both N-buffers' levels");
  return spec;
}

// "X,Y,Z,TX,TY,TZ" -> eye and target; throws InputError.
std::array<double, 6> parse_light(const std::string& text) {
  std::array<double, 6> v{};
  std::size_t pos = 0, i = 0;
  for (; i < 6 && pos <= text.size(); ++i) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    const std::string item = text.substr(pos, comma - pos);
    std::size_t used = 0;
    bool ok = !item.empty();
    try {
      if (ok) v[i] = std::stod(item, &used);
    } catch (const std::exception&) {
      ok = false;
    }
    if (!ok || used != item.size() || !std::isfinite(v[i]))
      throw InputError(fmt::format("--light: '{}' is not a number (write auto or X,Y,Z,TX,TY,TZ in metres)", item));
    pos = comma + 1;
  }
  if (i != 6 || pos <= text.size())
    throw InputError(fmt::format("--light '{}' does not have six numbers X,Y,Z,TX,TY,TZ (or write auto)", text));
  return v;
}

// Refuses (InputError) a --litmap whose images alone exceed the trace format's per-frame limit for
// the viewport, before any GL object is made or anything written. What a frame surely records: both
// litmaps and, on a levels frame (frame 0 is one unless --levels-every is 0), every level of both
// N-buffers, 4 bytes a lexel; the observer's depth (4 bytes a pixel) and four stencil images (1
// byte a pixel each). Draws come on top (a frame that still exceeds the limit fails when written,
// and the capture leaves no file).
void check_frame_budget(const TechniqueSetup& s) {
  const auto litmap = static_cast<int>(s.options.integer(litmap_option()));
  const bool levels_recorded = s.options.integer(levels_every_option()) > 0;
  const auto lexels = static_cast<std::uint64_t>(litmap) * static_cast<std::uint64_t>(litmap);
  const std::uint64_t levels = levels_recorded ? static_cast<std::uint64_t>(nbuffer_level_count(litmap, litmap)) : 0;
  const std::uint64_t pixels = static_cast<std::uint64_t>(s.width) * static_cast<std::uint64_t>(s.height);
  const std::uint64_t needed = 2 * 4 * lexels * (1 + levels) + 8 * pixels;
  trace::Header h;
  h.viewport = trace::Viewport{s.width, s.height};
  if (needed > h.frame_byte_limit())
    throw InputError(fmt::format("--litmap {}: the two {}x{} litmaps{} come to {} bytes a frame, above the trace format's per-frame limit "
                                 "of {} bytes ({}); use a smaller --litmap{}, or a larger --size",
                                 litmap, litmap, litmap, levels ? fmt::format(" and both N-buffers' {} levels", levels) : "", needed,
                                 h.frame_byte_limit(), h.frame_byte_limit_rule(), levels ? " or --levels-every 0" : ""));
}

// The SHDG record of `casters`: their bounds and triangles, each caster's vertices numbered anew in
// the order its triangles first use them (the model's volumes index them the same way).
trace::TechniqueRecord caster_meshes(const CaptureScene& scene, const std::vector<CasterMesh>& casters) {
  std::vector<std::uint32_t> object, first, count, triangles;
  std::vector<float> bounds, vertices;
  for (const CasterMesh& c : casters) {
    object.push_back(c.object);
    const scene::Aabb& b = scene.scene.objects[c.object];
    bounds.insert(bounds.end(), {b.lo[0], b.lo[1], b.lo[2], b.hi[0], b.hi[1], b.hi[2]});
    first.push_back(static_cast<std::uint32_t>(triangles.size() / 3));
    count.push_back(static_cast<std::uint32_t>(c.triangles.size()));
    std::map<std::uint32_t, std::uint32_t> number;
    for (const auto& t : c.triangles)
      for (std::uint32_t v : t) {
        const auto [it, added] = number.emplace(v, static_cast<std::uint32_t>(vertices.size() / 3));
        if (added) vertices.insert(vertices.end(), {scene.vertices[v].x, scene.vertices[v].y, scene.vertices[v].z});
        triangles.push_back(it->second);
      }
  }
  trace::TechniqueRecord rec;
  rec.type = trace::kCasterMeshesChunk;
  rec.decoded = true;
  rec.fields = {{"count", std::uint64_t{casters.size()}}, {"object", std::move(object)},       {"bounds", std::move(bounds)},
                {"first_triangle", std::move(first)},    {"triangle_count", std::move(count)}, {"vertices", std::move(vertices)},
                {"triangles", std::move(triangles)}};
  return rec;
}

// The SHDM record: every object's triangles in index order (the litmap draws' order), each
// object's vertices numbered anew in the order its triangles first use them.
trace::TechniqueRecord litmap_meshes(const CaptureScene& scene) {
  std::vector<std::uint32_t> object, first, count, triangles;
  std::vector<float> vertices;
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    const MeshRange& m = scene.objects[o];
    object.push_back(static_cast<std::uint32_t>(o));
    first.push_back(static_cast<std::uint32_t>(triangles.size() / 3));
    count.push_back(static_cast<std::uint32_t>(m.index_count / 3));
    std::map<std::uint32_t, std::uint32_t> number;
    for (std::size_t i = m.first_index; i < m.first_index + m.index_count; ++i) {
      const std::uint32_t v = scene.indices[i];
      const auto [it, added] = number.emplace(v, static_cast<std::uint32_t>(vertices.size() / 3));
      if (added) vertices.insert(vertices.end(), {scene.vertices[v].x, scene.vertices[v].y, scene.vertices[v].z});
      triangles.push_back(it->second);
    }
  }
  trace::TechniqueRecord rec;
  rec.type = trace::kLitmapMeshesChunk;
  rec.decoded = true;
  rec.fields = {{"count", std::uint64_t{object.size()}}, {"object", std::move(object)},      {"first_triangle", std::move(first)},
                {"triangle_count", std::move(count)},     {"vertices", std::move(vertices)}, {"triangles", std::move(triangles)}};
  return rec;
}

struct CasterResult {
  std::int32_t x = 0, y = 0, w = 0, h = 0;
  float caster_near = 0, caster_far = 0, z_min = 1, z_max = 0;
  std::uint32_t lookups = 0;
  CasterDecision decision = CasterDecision::Volume;
  nbsim::shadows::KeptBy kept = nbsim::shadows::KeptBy::Dropped;
  float clamp_near = 0, clamp_far = std::numeric_limits<float>::infinity();
  std::int32_t draw = -1;
};

class Shadows final : public Technique {
 public:
  explicit Shadows(const TechniqueSetup& s);
  ~Shadows() override;
  Shadows(const Shadows&) = delete;
  Shadows& operator=(const Shadows&) = delete;

  trace::Properties variant_properties() const override { return {{"shadow_mode", kModeNames[static_cast<std::size_t>(mode_)]}}; }
  trace::Properties setting_properties() const override {
    return {{"litmap_size", std::to_string(litmap_)},
            {"light", light_text_},
            {"light_fov_deg", std::to_string(light_fov_)},
            {"casters", std::to_string(casters_.size())},
            {"stencil_volumes", "zfail_caps_two_sided_depth_clamp"},
            {"reproject_tolerance", fmt::format("{} + {} m", reproject_.rel, reproject_.metres)},
            {"clamp_margin", fmt::format("{} + {} m", margin_.rel, margin_.metres)},
            {"clamp_rule", std::string(nbsim::shadows::kClampRuleNames[static_cast<std::size_t>(rule_)])},
            {"levels_every", std::to_string(levels_every_)},
            covering_property(covering_)};
  }
  std::string depth_format() const override { return "DEPTH24_STENCIL8"; }

  CapturedFrame render(std::uint32_t index, const CameraPose& pose) override;

 private:
  LightCamera light_at(std::uint32_t index) const;
  // A caster's light-space rectangle, bounds depths and eight lookups; decision Volume unless it is
  // outside the light's frustum or crosses its near plane (then final).
  CasterResult measure(const CasterMesh& c, const LightCamera& light, const scene::NBufferLevels& lo,
                       const scene::NBufferLevels& hi) const;
  // The decision and planes of a measured caster from the depth range of the receivers that may lie
  // in its rectangle, [slab_min, slab_max].
  void decide(CasterResult& r, const LightCamera& light, double slab_min, double slab_max) const;
  VolumeEnds ends_of(const CasterResult& r, bool clamped) const;
  double far_end(const LightCamera& light, double slab_max) const { return nbsim::shadows::slab_far_end(light, slab_max, margin_); }
  // Uploads `positions` (three a triangle) to the volume buffer.
  void upload(const std::vector<glm::vec4>& positions);
  std::vector<std::uint8_t> read_stencil() const;

  const CaptureScene& scene_;
  int width_, height_;
  Projection projection_;
  Mode mode_;
  ClampRule rule_;
  nbsim::shadows::ClampMargin reproject_, margin_;
  int litmap_, light_fov_, levels_every_;
  CoveringSpec covering_;  // of the eight lookups a caster makes
  std::string light_text_;
  std::uint32_t seed_;
  std::vector<CasterMesh> casters_;
  scene::Aabb bounds_{};  // of every object
  ScenePass pass_;
  RenderTarget target_;                     // the observer: DEPTH24_STENCIL8
  RenderTarget litmap_min_, litmap_max_;    // DEPTH_COMPONENT32F
  DrawRecorder recorder_;
  GlslNBuffer nb_min_, nb_max_;
  GLuint litmap_prog_ = 0, splat_prog_ = 0, volume_prog_ = 0;
  GLuint splat_vao_ = 0;  // no attributes: the splat's vertices come from gl_VertexID
  GLuint volume_vao_ = 0, volume_vbo_ = 0, reference_count_ = 0;
  std::size_t volume_capacity_ = 0, reference_capacity_ = 4;  // bytes
  std::string class_names_;  // the scene's object classes, comma-separated (SHDC class_names)
  trace::TechniqueRecord meshes_;         // SHDG: the casters' meshes, written with the first frame
  trace::TechniqueRecord litmap_meshes_;  // SHDM: every object's mesh, likewise
};

Shadows::Shadows(const TechniqueSetup& s)
    : scene_(s.scene),
      width_(s.width),
      height_(s.height),
      projection_(s.projection),
      mode_(static_cast<Mode>(std::find(shadow_mode_option().choices.begin(), shadow_mode_option().choices.end(),
                                        s.options.text(shadow_mode_option())) -
                              shadow_mode_option().choices.begin())),
      rule_(s.options.text(clamp_rule_option()) == "caster" ? ClampRule::Caster : ClampRule::Edge),
      reproject_(read_margin(s.options, reproject_option())),
      margin_(read_margin(s.options, clamp_margin_option())),
      litmap_(static_cast<int>(s.options.integer(litmap_option()))),
      light_fov_(static_cast<int>(s.options.integer(light_fov_option()))),
      levels_every_(static_cast<int>(s.options.integer(levels_every_option()))),
      covering_(read_covering(s.options, shadows_covering_option())),
      light_text_(s.options.text(light_option())),
      seed_(static_cast<std::uint32_t>(s.options.integer(seed_option()))),
      casters_(find_casters(s.scene)),
      pass_(s.scene, false),
      target_(s.width, s.height, GL_DEPTH24_STENCIL8),
      litmap_min_(litmap_, litmap_),
      litmap_max_(litmap_, litmap_),
      nb_min_(litmap_, litmap_, FarOp::Min),
      nb_max_(litmap_, litmap_, FarOp::Max) {
  if (projection_.reversed_z)
    throw InputError("the shadows technique records GL's default depth convention only (LESS, [-1, 1] clip z): drop --reversed-z");
  bounds_.lo = {INFINITY, INFINITY, INFINITY};
  bounds_.hi = {-INFINITY, -INFINITY, -INFINITY};
  for (const scene::Aabb& b : scene_.scene.objects)
    for (std::size_t k = 0; k < 3; ++k) bounds_.lo[k] = std::min(bounds_.lo[k], b.lo[k]), bounds_.hi[k] = std::max(bounds_.hi[k], b.hi[k]);
  if (light_text_ != "auto") parse_light(light_text_);
  for (const std::string& name : scene_.class_names) class_names_ += (class_names_.empty() ? "" : ",") + name;
  meshes_ = caster_meshes(scene_, casters_);
  litmap_meshes_ = litmap_meshes(scene_);
  light_at(0);  // a fixed light is checked here (degenerate frustum, inside a caster), before any frame

  litmap_prog_ = link_program({compile_shader(GL_VERTEX_SHADER, shaders::shadows_litmap_vert, "shadows/litmap.vert"),
                               compile_shader(GL_FRAGMENT_SHADER, shaders::shadows_litmap_frag, "shadows/litmap.frag")},
                              "litmap");
  splat_prog_ = link_program({compile_shader(GL_VERTEX_SHADER, shaders::shadows_splat_vert, "shadows/splat.vert"),
                              compile_shader(GL_FRAGMENT_SHADER, shaders::shadows_splat_frag, "shadows/splat.frag")},
                             "receiver_splat");
  glCreateVertexArrays(1, &splat_vao_);
  volume_prog_ = link_program({compile_shader(GL_VERTEX_SHADER, shaders::shadows_volume_vert, "shadows/volume.vert"),
                               compile_shader(GL_FRAGMENT_SHADER, shaders::common_count_frag, "common/count.frag")},
                              "shadow_volume", true);
  glCreateVertexArrays(1, &volume_vao_);
  glEnableVertexArrayAttrib(volume_vao_, 0);
  glVertexArrayAttribFormat(volume_vao_, 0, 4, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(volume_vao_, 0, 0);
  glCreateBuffers(1, &reference_count_);
  glNamedBufferStorage(reference_count_, 4, nullptr, GL_DYNAMIC_STORAGE_BIT);
}

Shadows::~Shadows() {
  glDeleteProgram(litmap_prog_);
  glDeleteProgram(splat_prog_);
  glDeleteProgram(volume_prog_);
  glDeleteVertexArrays(1, &volume_vao_);
  glDeleteVertexArrays(1, &splat_vao_);
  const GLuint buffers[] = {volume_vbo_, reference_count_};
  glDeleteBuffers(2, buffers);
}

LightCamera Shadows::light_at(std::uint32_t index) const {
  LightCamera l;
  l.fov_y_deg = light_fov_;
  const double ext = scene_.site.extent_m, top = bounds_.hi[1];
  if (light_text_ == "auto") {
    // Above the scene's top, circling the site's centre slowly (0.05 rad a frame), looking past the
    // centre at the ground: the phase comes from the seed.
    std::mt19937 rng(seed_ ^ 0x119a7u);
    const double phase = std::uniform_real_distribution<double>(0.0, 6.283185307179586)(rng);
    const double a = phase + 0.05 * index, c = 0.5 * ext;
    l.eye = {c + 0.25 * ext * std::cos(a), top + kLightHeight * ext, c + 0.25 * ext * std::sin(a)};
    l.target = {c - 0.1 * ext * std::cos(a), 0.0, c - 0.1 * ext * std::sin(a)};
    l.near_m = std::max(0.5, 0.5 * (l.eye.y - top));
  } else {
    const auto v = parse_light(light_text_);
    l.eye = {v[0], v[1], v[2]};
    l.target = {v[3], v[4], v[5]};
    l.near_m = 0.5;
  }
  double farthest = 0.0;
  for (int k = 0; k < 8; ++k) {
    const glm::dvec3 corner{k & 1 ? bounds_.hi[0] : bounds_.lo[0], k & 2 ? bounds_.hi[1] : bounds_.lo[1], k & 4 ? bounds_.hi[2] : bounds_.lo[2]};
    farthest = std::max(farthest, glm::length(corner - l.eye));
  }
  l.far_m = std::max(farthest * 1.05, l.near_m * 2.0);
  if (!l.make())
    throw InputError(fmt::format("--light {}: the light camera's frustum is degenerate (position ({}, {}, {}) looking at ({}, {}, {}), "
                                 "near {} m, far {} m, field of view {} degrees)",
                                 light_text_, l.eye.x, l.eye.y, l.eye.z, l.target.x, l.target.y, l.target.z, l.near_m, l.far_m, l.fov_y_deg));
  for (const CasterMesh& c : casters_) {
    const scene::Aabb& b = scene_.scene.objects[c.object];
    bool inside = true;
    for (int k = 0; k < 3; ++k) inside = inside && l.eye[k] >= b.lo[static_cast<std::size_t>(k)] && l.eye[k] <= b.hi[static_cast<std::size_t>(k)];
    if (inside)
      throw InputError(fmt::format("--light {}: the light at ({}, {}, {}) is inside caster object {} (bounds ({}, {}, {}) to ({}, {}, {})): "
                                   "its shadow volume would hold the whole scene",
                                   light_text_, l.eye.x, l.eye.y, l.eye.z, c.object, b.lo[0], b.lo[1], b.lo[2], b.hi[0], b.hi[1], b.hi[2]));
  }
  return l;
}

CasterResult Shadows::measure(const CasterMesh& c, const LightCamera& light, const scene::NBufferLevels& lo,
                              const scene::NBufferLevels& hi) const {
  CasterResult r;
  const nbsim::shadows::CasterRect rect = nbsim::shadows::caster_rect(scene_.scene.objects[c.object], light, litmap_);
  r.caster_near = rect.caster_near, r.caster_far = rect.caster_far;
  if (rect.decision != nbsim::shadows::Decision::Volume) {
    r.decision = rect.decision == nbsim::shadows::Decision::CrossesNear ? CasterDecision::CrossesNear : CasterDecision::OutsideLight;
    return r;
  }
  r.x = rect.x, r.y = rect.y, r.w = rect.w, r.h = rect.h;
  // Up to four lookups in each N-buffer: the nearest (min) and the farthest (max) visible receiver.
  const Covering cov = cover(Rect{r.x, r.y, r.w, r.h}, covering_, lo.levels - 1);
  const std::size_t plane = static_cast<std::size_t>(cov.level) * static_cast<std::size_t>(litmap_) * static_cast<std::size_t>(litmap_);
  for (int k = 0; k < cov.count; ++k) {
    const std::size_t at = plane + static_cast<std::size_t>(cov.squares[static_cast<std::size_t>(k)].y) * static_cast<std::size_t>(litmap_) +
                           static_cast<std::size_t>(cov.squares[static_cast<std::size_t>(k)].x);
    r.z_min = std::min(r.z_min, lo.texels[at]);
    r.z_max = std::max(r.z_max, hi.texels[at]);
  }
  r.lookups = 2u * static_cast<std::uint32_t>(cov.count);
  return r;
}

void Shadows::decide(CasterResult& r, const LightCamera& light, double slab_min, double slab_max) const {
  const nbsim::shadows::Planes p = nbsim::shadows::slab_planes(r.caster_near, r.caster_far, light, slab_min, slab_max, margin_, rule_);
  if (p.culled) {
    r.decision = CasterDecision::Culled;
    return;
  }
  r.clamp_far = p.clamp_far, r.clamp_near = p.clamp_near;
}

VolumeEnds Shadows::ends_of(const CasterResult& r, bool clamped) const { return nbsim::shadows::volume_ends(r.clamp_near, r.clamp_far, clamped); }

void Shadows::upload(const std::vector<glm::vec4>& positions) {
  const std::size_t bytes = std::max<std::size_t>(positions.size() * sizeof(glm::vec4), 16);
  if (bytes > volume_capacity_) {
    glDeleteBuffers(1, &volume_vbo_);
    glCreateBuffers(1, &volume_vbo_);
    volume_capacity_ = std::max(bytes, volume_capacity_ * 2);
    glNamedBufferStorage(volume_vbo_, static_cast<GLsizeiptr>(volume_capacity_), nullptr, GL_DYNAMIC_STORAGE_BIT);
    glVertexArrayVertexBuffer(volume_vao_, 0, volume_vbo_, 0, sizeof(glm::vec4));
  }
  if (!positions.empty()) glNamedBufferSubData(volume_vbo_, 0, static_cast<GLsizeiptr>(positions.size() * sizeof(glm::vec4)), positions.data());
}

std::vector<std::uint8_t> Shadows::read_stencil() const {
  std::vector<std::uint8_t> s(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, target_.framebuffer());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_STENCIL_INDEX, GL_UNSIGNED_BYTE, s.data());  // bottom row first = y up
  return s;
}

CapturedFrame Shadows::render(std::uint32_t index, const CameraPose& pose) {
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
  const LightCamera light = light_at(index);
  const glm::mat4 light_view(light.view), light_proj(light.proj);
  scene::Camera lc;
  std::memcpy(lc.view.data(), glm::value_ptr(light_view), 64);
  std::memcpy(lc.proj.data(), glm::value_ptr(light_proj), 64);
  const glm::mat4 light_view_proj = nbsim::shadows::light_view_proj(lc);  // the model's litmap draws compute it alike
  lc.eye = {static_cast<float>(light.eye.x), static_cast<float>(light.eye.y), static_cast<float>(light.eye.z)};
  f.light = lc;
  const scene::FrameView v = scene::FrameView::make(f.begin, width_, height_, projection_.near_m, 0.0, false, false);
  std::vector<std::uint32_t> in_frustum = scene::frustum_objects(scene_.scene, v);
  std::sort(in_frustum.begin(), in_frustum.end());
  scene::FrameBegin lb;
  lb.view = lc.view, lb.proj = lc.proj, lb.eye = lc.eye;
  const scene::FrameView lv = scene::FrameView::make(lb, litmap_, litmap_, light.near_m, 0.0, false, false);
  std::vector<std::uint32_t> in_light = scene::frustum_objects(scene_.scene, lv);
  std::sort(in_light.begin(), in_light.end());
  std::vector<std::uint32_t> lit_and_seen;  // only what is in both frusta can be a visible, lit receiver
  std::set_intersection(in_frustum.begin(), in_frustum.end(), in_light.begin(), in_light.end(), std::back_inserter(lit_and_seen));

  const auto t0 = std::chrono::steady_clock::now();
  recorder_.begin_frame(in_frustum.size() + 2 * lit_and_seen.size() + casters_.size() + 64);
  // 1. The observer's depth (the stencil cleared to 0 with it).
  glBindFramebuffer(GL_FRAMEBUFFER, target_.framebuffer());
  target_.clear_depth(false);
  target_.clear_stencil(0);
  const GLuint no_object = 0;
  glClearNamedFramebufferuiv(target_.framebuffer(), GL_COLOR, 0, &no_object);
  pass_.begin(target_, view_proj, false, recorder_);
  glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);  // object id + 1 a pixel: which casters the observer sees
  for (auto o : in_frustum) {
    DrawRecord d;
    d.role = DrawRole::Scene;
    d.object = static_cast<std::int32_t>(o);
    d.state = depth_state(false, true, true);
    pass_.draw_object(recorder_, std::move(d), o);
  }

  std::vector<std::uint32_t> ids(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_));
  glGetTextureImage(target_.id_texture(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, static_cast<GLsizei>(ids.size() * 4), ids.data());
  std::vector<char> seen(scene_.objects.size(), 0);
  for (std::uint32_t id : ids)
    if (id > 0 && id <= seen.size()) seen[id - 1] = 1;

  // 2. The min and max litmaps from the light, observer-hidden fragments discarded.
  glUseProgram(litmap_prog_);
  glUniformMatrix4fv(glGetUniformLocation(litmap_prog_, "light_view_proj"), 1, GL_FALSE, glm::value_ptr(light_view_proj));
  const auto rows = nbsim::shadows::reprojection_rows(view_proj, light_view_proj, litmap_);
  for (std::size_t r = 0; r < 4; ++r)
    glUniform4fv(glGetUniformLocation(litmap_prog_, fmt::format("reproject_{}", "xyzw"[r]).c_str()), 1, rows[r].data());
  glUniform2f(glGetUniformLocation(litmap_prog_, "near_far"), static_cast<float>(projection_.near_m), static_cast<float>(projection_.far_m));
  glUniform1f(glGetUniformLocation(litmap_prog_, "tolerance_rel"), static_cast<float>(reproject_.rel));
  glUniform1f(glGetUniformLocation(litmap_prog_, "tolerance_m"), static_cast<float>(reproject_.metres));
  glUniform1i(glGetUniformLocation(litmap_prog_, "observer_depth"), 1);
  const GLint u_slot = glGetUniformLocation(litmap_prog_, "draw_slot");
  glUseProgram(splat_prog_);
  const nbsim::shadows::ReceiverSplat splat(view_proj, light.proj * light.view, width_, height_);
  for (std::size_t r = 0; r < 4; ++r)
    glUniform4dv(glGetUniformLocation(splat_prog_, fmt::format("splat_{}", "xyzw"[r]).c_str()), 1, splat.rows()[r].data());
  glUniform2i(glGetUniformLocation(splat_prog_, "size"), width_, height_);
  glUniform1i(glGetUniformLocation(splat_prog_, "observer_depth"), 1);
  const GLint u_splat_slot = glGetUniformLocation(splat_prog_, "draw_slot");
  glUseProgram(litmap_prog_);
  glBindTextureUnit(1, target_.depth_texture());
  glBindVertexArray(pass_.scene_vertex_array());
  recorder_.bind();
  glDisable(GL_CULL_FACE);  // every surface the observer sees counts, whichever way it faces the light
  glEnable(GL_DEPTH_TEST);
  glColorMaski(0, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  for (const bool max : {false, true}) {
    const RenderTarget& t = max ? litmap_max_ : litmap_min_;
    t.bind();
    t.clear_depth(max);  // 1 for the min litmap, 0 for the max litmap
    glDepthFunc(max ? GL_GEQUAL : GL_LEQUAL);
    glDepthMask(GL_TRUE);
    for (auto o : lit_and_seen) {
      DrawRecord d;
      d.role = nbsim::shadows::kLitmapRole;
      d.object = static_cast<std::int32_t>(o);
      d.state = depth_state(false, true, true);
      d.state.func = max ? scene::DepthFunc::Gequal : scene::DepthFunc::Lequal;
      d.state.cull = scene::CullFace::None;
      d.discards = true;
      const std::size_t slot = recorder_.begin_draw(std::move(d), 0);
      glUniform1ui(u_slot, static_cast<GLuint>(slot));
      const MeshRange& m = scene_.objects[o];
      glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(m.index_count), GL_UNSIGNED_INT,
                     reinterpret_cast<const void*>(static_cast<std::uintptr_t>(m.first_index) * 4));
      recorder_.end_draw();
    }
    // The receiver splat (shaders/shadows/splat.vert): every observer pixel's surface point in the
    // light's frustum as a one-pixel point, same depth func; back to the litmap program after.
    glUseProgram(splat_prog_);
    DrawRecord d;
    d.role = nbsim::shadows::kReceiverSplatRole;
    d.state = depth_state(false, true, true);
    d.state.func = max ? scene::DepthFunc::Gequal : scene::DepthFunc::Lequal;
    d.state.cull = scene::CullFace::None;
    d.topology = scene::Topology::Points;
    const std::size_t slot = recorder_.begin_draw(std::move(d), 0);
    glUniform1ui(u_splat_slot, static_cast<GLuint>(slot));
    glBindVertexArray(splat_vao_);
    glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(width_) * static_cast<GLsizei>(height_));
    recorder_.end_draw();
    glBindVertexArray(pass_.scene_vertex_array());
    glUseProgram(litmap_prog_);
  }

  // 3. A min and a max N-buffer over them.
  scene::DepthState build_state = depth_state(false, false, false);
  build_state.cull = scene::CullFace::None;
  nb_min_.build(litmap_min_.depth_texture(), recorder_, build_state);
  nb_max_.build(litmap_max_.depth_texture(), recorder_, build_state);
  scene::NBufferLevels min_levels = nb_min_.read(), max_levels = nb_max_.read();

  // 4. Each caster's rectangle, eight lookups and decision; 5. the volumes of the mode.
  std::vector<CasterResult> results(casters_.size());
  std::vector<glm::vec4> positions;
  std::vector<std::pair<std::size_t, std::size_t>> ranges(casters_.size());  // first vertex, count
  for (std::size_t c = 0; c < casters_.size(); ++c) results[c] = measure(casters_[c], light, min_levels, max_levels);
  // Each slab: the litmaps' [z_min, z_max] (with the receiver splat, every receiver the mask samples
  // in the rectangle lies inside it). The rule "caster" also widens it as before the splat: a seen
  // caster's own bounds join its own slab, and a seen caster crossing the light's near plane makes
  // every slab [0, 1] (they only loosen the slab).
  bool near_crossing_seen = false;
  for (std::size_t c = 0; c < casters_.size(); ++c)
    near_crossing_seen = near_crossing_seen || (seen[casters_[c].object] && results[c].decision == CasterDecision::CrossesNear);
  for (std::size_t c = 0; c < casters_.size(); ++c) {
    CasterResult& r = results[c];
    if (r.decision == CasterDecision::Volume) {
      double slab_min = r.z_min, slab_max = r.z_max;
      if (rule_ == ClampRule::Caster && seen[casters_[c].object])
        slab_min = std::min(slab_min, static_cast<double>(r.caster_near)), slab_max = std::max(slab_max, static_cast<double>(r.caster_far));
      if (rule_ == ClampRule::Caster && near_crossing_seen) slab_min = 0.0, slab_max = 1.0;
      decide(r, light, slab_min, slab_max);
      // Why it is kept: its slab has a visible receiver behind it, it is seen itself, or only the
      // widening keeps it.
      using nbsim::shadows::KeptBy;
      if (r.decision == CasterDecision::Volume)
        r.kept = seen[casters_[c].object] ? KeptBy::SeenCaster
                 : far_end(light, r.z_max) >= std::max<double>(r.z_min, r.caster_near) ? KeptBy::Receivers
                                                                                                            : KeptBy::Widened;
    }
    if (r.decision == CasterDecision::CrossesNear) r.kept = nbsim::shadows::KeptBy::CrossesNear;
    const bool dropped = results[c].decision == CasterDecision::Culled || results[c].decision == CasterDecision::OutsideLight;
    if (mode_ != Mode::Infinite && dropped) continue;
    const std::size_t first = positions.size();
    append_volume(scene_, casters_[c], light, ends_of(results[c], mode_ == Mode::Clamped), positions);
    ranges[c] = {first, positions.size() - first};
  }
  upload(positions);
  target_.bind();
  glUseProgram(volume_prog_);
  glUniformMatrix4fv(glGetUniformLocation(volume_prog_, "view_proj"), 1, GL_FALSE, glm::value_ptr(view_proj));
  const GLint u_vslot = glGetUniformLocation(volume_prog_, "draw_slot"), u_object = glGetUniformLocation(volume_prog_, "object_id");
  glBindVertexArray(volume_vao_);
  recorder_.bind();
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_FALSE);
  glDisable(GL_CULL_FACE);
  glFrontFace(GL_CCW);
  glEnable(GL_DEPTH_CLAMP);
  glEnable(GL_STENCIL_TEST);
  glStencilFuncSeparate(GL_FRONT_AND_BACK, GL_ALWAYS, 0, 0xFFu);
  glStencilMaskSeparate(GL_FRONT_AND_BACK, 0xFFu);
  glStencilOpSeparate(GL_FRONT, GL_KEEP, GL_DECR_WRAP, GL_KEEP);
  glStencilOpSeparate(GL_BACK, GL_KEEP, GL_INCR_WRAP, GL_KEEP);
  for (std::size_t c = 0; c < casters_.size(); ++c) {
    if (ranges[c].second == 0) continue;
    DrawRecord d = nbsim::shadows::volume_draw(casters_[c].object);
    const std::size_t slot = recorder_.begin_draw(std::move(d), ranges[c].second);
    results[c].draw = static_cast<std::int32_t>(slot);
    glUniform1ui(u_vslot, static_cast<GLuint>(slot));
    glUniform1ui(u_object, casters_[c].object);
    glDrawArrays(GL_TRIANGLES, static_cast<GLint>(ranges[c].first), static_cast<GLsizei>(ranges[c].second));
    recorder_.end_draw();
  }
  glFinish();
  f.end.gl_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const std::vector<std::uint8_t> stencil = read_stencil();

  // 6. The reference: every caster's infinite volume into a cleared stencil, its fill counted apart
  // per caster.
  std::vector<std::uint8_t> reference = stencil;
  std::vector<std::uint32_t> fill_infinite(casters_.size(), 0);
  if (mode_ != Mode::Infinite) {
    positions.clear();
    for (std::size_t c = 0; c < casters_.size(); ++c) {
      const std::size_t first = positions.size();
      append_volume(scene_, casters_[c], light, ends_of(results[c], false), positions);
      ranges[c] = {first, positions.size() - first};
    }
    upload(positions);
    target_.clear_stencil(0);
    const std::size_t bytes = std::max<std::size_t>(4, 4 * casters_.size());
    if (bytes > reference_capacity_) {
      glDeleteBuffers(1, &reference_count_);
      glCreateBuffers(1, &reference_count_);
      glNamedBufferStorage(reference_count_, static_cast<GLsizeiptr>(bytes), nullptr, GL_DYNAMIC_STORAGE_BIT);
      reference_capacity_ = bytes;
    }
    const GLuint zero = 0;
    glClearNamedBufferData(reference_count_, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, reference_count_);
    for (std::size_t c = 0; c < casters_.size(); ++c) {
      if (ranges[c].second == 0) continue;
      glUniform1ui(u_vslot, static_cast<GLuint>(c));
      glDrawArrays(GL_TRIANGLES, static_cast<GLint>(ranges[c].first), static_cast<GLsizei>(ranges[c].second));
    }
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    if (!casters_.empty())
      glGetNamedBufferSubData(reference_count_, 0, static_cast<GLsizeiptr>(4 * casters_.size()), fill_infinite.data());
    reference = read_stencil();
    recorder_.bind();
  }
  glDisable(GL_STENCIL_TEST);
  glDisable(GL_DEPTH_CLAMP);
  glDepthMask(GL_TRUE);
  glEnable(GL_CULL_FACE);

  // The records.
  scene::DepthSnapshot depth = read_depth(target_.framebuffer(), width_, height_, scene::DepthWhich::Final);
  for (const bool max : {false, true}) {
    scene::DepthSnapshot lm = read_depth((max ? litmap_max_ : litmap_min_).framebuffer(), litmap_, litmap_, scene::DepthWhich::Final);
    lm.name = max ? "litmap_max" : "litmap_min";
    f.depths.push_back(std::move(lm));
  }
  // Receivers lit by the spot: pixels with a surface whose point lies inside the light's frustum.
  const glm::dmat4 unproject = glm::inverse(glm::dmat4(view_proj));
  scene::StencilSnapshot region{"light_region", width_, height_, std::vector<std::uint8_t>(stencil.size())};
  scene::StencilSnapshot mask{"shadow_mask", width_, height_, std::vector<std::uint8_t>(stencil.size())};
  scene::StencilSnapshot ref_mask{"shadow_mask_infinite", width_, height_, std::vector<std::uint8_t>(stencil.size())};
  std::uint64_t mask_pixels = 0, diff = 0;
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x);
      const double d = depth.texels[i];
      if (d >= 1.0) continue;
      const glm::dvec4 w = unproject * glm::dvec4((x + 0.5) / width_ * 2.0 - 1.0, (y + 0.5) / height_ * 2.0 - 1.0, 2.0 * d - 1.0, 1.0);
      const glm::dvec4 q = light.clip(glm::dvec3(w) / w.w);
      const bool lit = q.w > 0.0 && std::abs(q.x) <= q.w && std::abs(q.y) <= q.w && std::abs(q.z) <= q.w;
      region.texels[i] = lit;
      mask.texels[i] = lit && stencil[i] != 0;
      ref_mask.texels[i] = lit && reference[i] != 0;
      mask_pixels += mask.texels[i];
      diff += mask.texels[i] != ref_mask.texels[i];
    }
  f.depths.insert(f.depths.begin(), std::move(depth));
  f.stencils.push_back({"stencil", width_, height_, stencil});
  f.stencils.push_back(std::move(region));
  f.stencils.push_back(std::move(mask));
  f.stencils.push_back(std::move(ref_mask));
  if (levels_every_ > 0 && index % static_cast<std::uint32_t>(levels_every_) == 0) {
    min_levels.source = "litmap_min";
    max_levels.source = "litmap_max";
    f.levels.push_back(std::move(min_levels));
    f.levels.push_back(std::move(max_levels));
  }
  f.draws = recorder_.collect();

  std::uint64_t fill = 0, drawn = 0, culled = 0, lookups = 0;
  for (const DrawRecord& d : f.draws)
    if (d.role == nbsim::shadows::kShadowVolumeRole) fill += d.gl.fragments, ++drawn;
  if (mode_ == Mode::Infinite)
    for (std::size_t c = 0; c < casters_.size(); ++c)
      if (results[c].draw >= 0) fill_infinite[c] = static_cast<std::uint32_t>(f.draws[static_cast<std::size_t>(results[c].draw)].gl.fragments);
  std::uint64_t reference_fill = 0;
  for (std::uint32_t k : fill_infinite) reference_fill += k;
  const auto n = casters_.size();
  std::vector<std::uint32_t> object(n), lk(n), decision(n), cls(n), kept(n);
  std::vector<std::int32_t> rx(n), ry(n), rw(n), rh(n), draw(n);
  std::vector<float> cn(n), cf(n), zmin(n), zmax(n), clamp_near(n), clamp_far(n);
  for (std::size_t c = 0; c < n; ++c) {
    const CasterResult& r = results[c];
    object[c] = casters_[c].object, lk[c] = r.lookups, decision[c] = static_cast<std::uint32_t>(r.decision);
    rx[c] = r.x, ry[c] = r.y, rw[c] = r.w, rh[c] = r.h, draw[c] = r.draw;
    cn[c] = r.caster_near, cf[c] = r.caster_far, zmin[c] = r.z_min, zmax[c] = r.z_max;
    clamp_near[c] = r.clamp_near, clamp_far[c] = r.clamp_far;
    cls[c] = scene_.object_class.at(casters_[c].object), kept[c] = static_cast<std::uint32_t>(r.kept);
    culled += r.decision == CasterDecision::Culled || r.decision == CasterDecision::OutsideLight;
    lookups += r.lookups;
  }
  trace::TechniqueRecord rec;
  rec.type = trace::kShadowsChunk;
  rec.decoded = true;
  rec.fields = {{"count", std::uint64_t{n}},
                {"litmap_size", static_cast<std::uint64_t>(litmap_)},
                {"object", std::move(object)},
                {"x", std::move(rx)},
                {"y", std::move(ry)},
                {"w", std::move(rw)},
                {"h", std::move(rh)},
                {"caster_near", std::move(cn)},
                {"caster_far", std::move(cf)},
                {"z_min", std::move(zmin)},
                {"z_max", std::move(zmax)},
                {"lookups", std::move(lk)},
                {"decision", std::move(decision)},
                {"clamp_near", std::move(clamp_near)},
                {"clamp_far", std::move(clamp_far)},
                {"draw", std::move(draw)},
                {"reference_fill", reference_fill},
                {"mask_diff_pixels", diff},
                {"class_names", class_names_},
                {"class", std::move(cls)},
                {"kept", std::move(kept)},
                {"fill_infinite", std::move(fill_infinite)},
                {"light_eye_x", light.eye.x},
                {"light_eye_y", light.eye.y},
                {"light_eye_z", light.eye.z},
                {"light_target_x", light.target.x},
                {"light_target_y", light.target.y},
                {"light_target_z", light.target.z},
                {"light_fov_deg", light.fov_y_deg},
                {"light_near_m", light.near_m},
                {"light_far_m", light.far_m}};
  f.technique_records.push_back(std::move(rec));
  if (index == 0) f.technique_records.push_back(meshes_), f.technique_records.push_back(litmap_meshes_);
  out.counts = {{"fill", fill},
                {"fill_infinite", reference_fill},
                {"casters", n},
                {"casters_culled", culled},
                {"volumes_drawn", drawn},
                {"lookups", lookups},
                {"mask_pixels", mask_pixels},
                {"mask_diff_pixels", diff}};
  f.end.frame = index;
  f.end.draws = static_cast<std::uint32_t>(f.draws.size());
  return out;
}

}  // namespace

const std::vector<OptionSpec>& shadows_options() {
  static const std::vector<OptionSpec> options = {shadow_mode_option(), clamp_rule_option(),    clamp_margin_option(),
                                                  reproject_option(),   litmap_option(),        light_option(),
                                                  light_fov_option(),   levels_every_option(),  shadows_covering_option(),
                                                  align_option(),       seed_option()};
  return options;
}

BenchPreset shadows_bench_preset() {
  // Flown over: the terrain and the boxes have no streets to walk. The replay draws its own litmaps
  // and volumes (in the captured mode), so the ratio counts the whole frame, not GL's images; like
  // GL's time, it leaves out the reference pass of every caster's infinite volume.
  return {"city", "fly", "512x512", {{"shadow-mode", "clamped"}, {"levels-every", "0"}}, "shadow-mode",
          {"shadows.litmaps=model", "shadows.volumes=model", "shadows.own_reference=false"}};
}

std::unique_ptr<Technique> make_shadows(const TechniqueSetup& setup) {
  check_frame_budget(setup);
  return std::make_unique<Shadows>(setup);
}

// This technique's row of the capture's table (technique.h).
TechniqueRow shadows_technique() {
  return {{"shadows",
           "Stencil shadow volumes of a spot light (z-fail, two-sided): infinite, culled or clamped with min/max litmaps and "
           "two N-buffers, with an infinite reference pass for the mask (N-buffer paper, 3.3 and 4.4)",
           shadows_options()},
          make_shadows,
          shadows_bench_preset(),
          {},
          {}};
}

}  // namespace nbsim::capture

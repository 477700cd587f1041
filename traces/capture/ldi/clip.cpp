// The LDI applications in a scene; see clip.h.
#include "traces/capture/ldi/clip.h"

#include <fmt/format.h>

#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "model/common/error.h"
#include "model/ldi/clip.h"
#include "model/mesh/shapes.h"
#include "model/scene/visibility.h"
#include "nbsim_shaders.h"
#include "traces/capture/camera.h"
#include "traces/capture/draw_recorder.h"
#include "traces/capture/ldi/mesh_loader.h"
#include "traces/capture/readback.h"
#include "traces/capture/render_target.h"
#include "traces/capture/scene_pass.h"
#include "traces/format/ldi/ldi_chunk.h"

namespace nbsim::capture {
namespace {

const OptionSpec& application_option() {
  static const OptionSpec spec = choice_option(
      "application", "shape: one shape's LDI and test points (no scene); clip: volumes in the scene clip every fragment inside them "
                     "(the paper's clipping); lens: clipping plus a second pass that shows the scene flattened inside the volumes (3D lenses)",
      "shape", {"shape", "clip", "lens"});
  return spec;
}
const OptionSpec& volumes_option() {
  static const OptionSpec spec = text_option(
      "volumes", "clip, lens: 'auto' (three volumes of --shape or --mesh, 24, 20 and 16 m, standing 40, 70 and 100 m ahead of the first "
                 "frame's eye) or SHAPE@X,Y,Z,SIZE;... with SHAPE a procedural shape (NAME or NAME:PARAM) or mesh:FILE, X,Y,Z the centre of "
                 "its unit cube and SIZE its side, metres; 1 to 4 volumes, apart from each other, touching the scene",
      "auto");
  return spec;
}
const OptionSpec& reader_option() {
  static const OptionSpec spec = choice_option(
      "reader", "clip, lens: the parity test's reader in the fragment shader: all (the paper's, every layer), layers (stops at the "
                "first layer behind the point) or ranges (the compressed texture)",
      "all", {"all", "layers", "ranges"});
  return spec;
}
const OptionSpec& lens_height_option() {
  static const OptionSpec spec = text_option(
      "lens-height", "lens: inside the volumes the objects are drawn at this fraction of their height (0 < f <= 1)", "0.25");
  return spec;
}

double parse_number(const std::string& s, const char* what, double lo, double hi) { return parse_real(s, what, lo, hi); }

std::vector<std::string> split(const std::string& s, char sep) { return split_list(s, sep); }

struct VolumeSpec {
  std::string shape;
  mesh::TriMesh mesh;  // closed, in the unit cube
  glm::dvec3 center{0.0};
  double size = 1.0;
  bool automatic = false;  // placed from the first pose

  glm::dvec3 lo() const { return center - 0.5 * size; }
  glm::dvec3 hi() const { return center + 0.5 * size; }
  std::string describe(std::size_t k) const {
    return fmt::format("volume {} ({} at {},{},{}, size {})", k + 1, shape, center.x, center.y, center.z, size);
  }
};

mesh::TriMesh unit_mesh(mesh::TriMesh m, const std::string& what) {
  mesh::require_closed(m, what);
  mesh::normalize_to_unit_cube(m, 0.0);
  return m;
}

std::vector<VolumeSpec> parse_volumes(const std::string& text, const LdiShapeInput& in) {
  std::vector<VolumeSpec> out;
  if (text == "auto") {
    const double sizes[] = {24.0, 20.0, 16.0};
    for (double s : sizes) {
      VolumeSpec v;
      v.shape = in.shape;
      v.mesh = unit_mesh(in.mesh, fmt::format("--shape {}", in.shape));
      v.size = s;
      v.automatic = true;
      out.push_back(std::move(v));
    }
    return out;
  }
  for (const std::string& item : split(text, ';')) {
    const std::size_t at = item.find('@');
    if (at == std::string::npos) throw InputError(fmt::format("--volumes: '{}' is not SHAPE@X,Y,Z,SIZE", item));
    VolumeSpec v;
    v.shape = item.substr(0, at);
    const std::vector<std::string> where = split(item.substr(at + 1), ',');
    if (where.size() != 4) throw InputError(fmt::format("--volumes: '{}' is not SHAPE@X,Y,Z,SIZE", item));
    for (int k = 0; k < 3; ++k) v.center[k] = parse_number(where[static_cast<std::size_t>(k)], "--volumes: a coordinate", -1e6, 1e6);
    v.size = parse_number(where[3], "--volumes: a size", 1e-3, 1e5);
    if (v.shape.rfind("mesh:", 0) == 0) {
      const std::string file = v.shape.substr(5);
      v.mesh = unit_mesh(load_mesh(file), fmt::format("--volumes: the mesh '{}'", file));
      v.shape = "mesh:" + std::filesystem::path(file).filename().string();
    } else {
      const std::size_t colon = v.shape.find(':');
      std::optional<int> param;
      if (colon != std::string::npos) param = static_cast<int>(parse_number(v.shape.substr(colon + 1), "--volumes: a shape parameter", 1, 1000));
      v.mesh = unit_mesh(mesh::make_shape(v.shape.substr(0, colon), param), fmt::format("--volumes: the shape '{}'", v.shape));
    }
    out.push_back(std::move(v));
  }
  if (out.empty()) throw InputError("--volumes names no volume");
  return out;
}

// The affine map of a unit-cube point to (texel x, texel y, linear depth) of an LDI, as a matrix.
glm::dmat4 unit_to_texel(const OrthoMapping& map) {
  const std::array<double, 3> o = map.project({0.0, 0.0, 0.0});
  const auto texel = [&](const std::array<double, 3>& p) {
    return glm::dvec3((p[0] + 1.0) * 0.5 * map.width, (p[1] + 1.0) * 0.5 * map.height, p[2]);
  };
  glm::dmat4 m(1.0);
  const glm::dvec3 t0 = texel(o);
  for (int k = 0; k < 3; ++k) {
    mesh::Vec3d e{0.0, 0.0, 0.0};
    e[static_cast<std::size_t>(k)] = 1.0;
    m[k] = glm::dvec4(texel(map.project(e)) - t0, 0.0);
  }
  m[3] = glm::dvec4(t0, 1.0);
  return m;
}

constexpr int kMaxVolumes = ldi::kMaxClipVolumes;
constexpr std::uint64_t kMaxTextureBytes = 1ull << 30;  // every volume's peel at --max-layers, together

class LdiApplication final : public Technique {
 public:
  LdiApplication(const TechniqueSetup& s, LdiShapeInput in)
      : width_(s.width), height_(s.height), scene_(s.scene), projection_(s.projection), input_(std::move(in)) {
    const OptionValues& o = s.options;
    lens_ = o.text(application_option()) == "lens";
    if (s.projection.reversed_z) throw InputError("--application clip or lens: reversed Z is not supported (the test rebuilds points from [-1, 1] clip z)");
    reader_ = *ldi::parse_clip_reader(o.text(reader_option()));
    lens_height_ = parse_number(o.text(lens_height_option()), "--lens-height", 1e-3, 1.0);
    if (!lens_ && lens_height_ != 0.25) throw InputError("--lens-height is for --application lens");
    volumes_text_ = o.text(volumes_option());
    volumes_ = parse_volumes(volumes_text_, input_);
    if (volumes_.size() > static_cast<std::size_t>(kMaxVolumes))
      throw InputError(fmt::format("--volumes names {} volumes; the fragment shader tests at most {}", volumes_.size(), kMaxVolumes));
    const std::uint64_t side = static_cast<std::uint64_t>(input_.config.size_texels);
    const std::uint64_t bytes = side * side * static_cast<std::uint64_t>(input_.config.max_layers) * 4 * volumes_.size();
    if (bytes > kMaxTextureBytes)
      throw InputError(fmt::format("{} LDIs of {}x{} texels and up to {} layers need up to {} MiB; the limit is {} MiB: lower --ldi-size or "
                                   "--max-layers",
                                   volumes_.size(), side, side, input_.config.max_layers, bytes >> 20, kMaxTextureBytes >> 20));
    if (scene_.scene.objects.empty()) throw InputError("--application clip or lens needs a scene with objects");
    scene_lo_ = glm::dvec3(std::numeric_limits<double>::infinity());
    scene_hi_ = -scene_lo_;
    for (const scene::Aabb& b : scene_.scene.objects)
      for (int k = 0; k < 3; ++k) {
        scene_lo_[k] = std::min(scene_lo_[k], static_cast<double>(b.lo[static_cast<std::size_t>(k)]));
        scene_hi_[k] = std::max(scene_hi_[k], static_cast<double>(b.hi[static_cast<std::size_t>(k)]));
      }
    if (std::none_of(volumes_.begin(), volumes_.end(), [](const VolumeSpec& v) { return v.automatic; })) check_placement();
    pass_ = std::make_unique<ScenePass>(scene_, false, shaders::ldi_clip_frag, "ldi/clip.frag");
    target_ = std::make_unique<RenderTarget>(width_, height_);
    glCreateBuffers(1, &decisions_);
  }
  ~LdiApplication() override {
    glDeleteBuffers(1, &decisions_);
    for (const GlVolume& v : gl_volumes_) {
      const GLuint t[2] = {v.cropped, v.compressed};
      glDeleteTextures(2, t);
    }
  }
  LdiApplication(const LdiApplication&) = delete;
  LdiApplication& operator=(const LdiApplication&) = delete;

  trace::Properties variant_properties() const override {
    return {{"shape", input_.shape}, {"ldi_application", lens_ ? "lens" : "clip"}, {"ldi_reader", ldi::kClipReaderNames[static_cast<std::size_t>(reader_)]}};
  }
  trace::Properties setting_properties() const override {
    return {{"ldi_size", std::to_string(input_.config.size_texels)},
            {"grid", fmt::format("{}x{}", input_.config.grid_h, input_.config.grid_v)},
            {"max_layers", std::to_string(input_.config.max_layers)},
            {"epsilon", fmt::format("{}", input_.epsilon)},
            {"ldi_volumes", volumes_text_},
            {"ldi_lens_height", fmt::format("{}", lens_height_)},
            {"ldi_placement", "volumes built in frame 0 (LdiVolume), each shape fitted into its unit cube (margin 0), placed by ldi_volumes"},
            {"observer", "the observer follows the camera path; the objects in its frustum are drawn front to back with the volume test"}};
  }

  CapturedFrame render(std::uint32_t index, const CameraPose& pose) override {
    CapturedFrame out;
    scene::Frame& f = out.frame;
    f.begin.frame = index;
    f.begin.mode = scene::TestMode::None;
    if (index == 0) build_volumes(pose, f);
    const glm::mat4 view = view_matrix(pose), proj = projection_matrix(projection_, static_cast<double>(width_) / height_);
    const glm::mat4 view_proj = proj * view;
    std::memcpy(f.begin.view.data(), glm::value_ptr(view), 64);
    std::memcpy(f.begin.proj.data(), glm::value_ptr(proj), 64);
    f.begin.eye = {pose.eye.x, pose.eye.y, pose.eye.z};

    // The objects in the frustum, front to back; for the lens, those whose flattened bounds meet a volume.
    const scene::FrameView fv = scene::FrameView::make(f.begin, width_, height_, projection_.near_m, 0.0, false, false);
    std::vector<std::uint32_t> objects = scene::frustum_objects(scene_.scene, fv);
    const glm::dvec3 eye(pose.eye);
    std::vector<std::pair<double, std::uint32_t>> order;
    for (std::uint32_t o : objects) order.emplace_back(scene::distance_to(scene_.scene.objects[o], eye), o);
    std::sort(order.begin(), order.end());
    objects.clear();
    std::vector<std::uint32_t> focus;
    for (const auto& [dist, o] : order) {
      objects.push_back(o);
      if (lens_ && meets_a_volume(scene_.scene.objects[o])) focus.push_back(o);
    }
    const std::size_t draws = objects.size() + focus.size();

    // The window-to-texel matrix of each volume: window -> NDC -> world (view_proj's inverse, in
    // double, of the float uniform) -> unit cube -> texel.
    glm::dmat4 vp_d(0.0), window_to_ndc(1.0);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) vp_d[c][r] = static_cast<double>(view_proj[c][r]);
    window_to_ndc[0][0] = 2.0 / width_, window_to_ndc[1][1] = 2.0 / height_, window_to_ndc[2][2] = 2.0;
    window_to_ndc[3] = glm::dvec4(-1.0, -1.0, -1.0, 1.0);
    const glm::dmat4 window_to_world = glm::inverse(vp_d) * window_to_ndc;
    std::vector<float> window_to_texel;
    for (const GlVolume& v : gl_volumes_) {
      const glm::dmat4 m = v.world_to_texel * window_to_world;
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) window_to_texel.push_back(static_cast<float>(m[c][r]));
    }

    const auto t0 = std::chrono::steady_clock::now();
    recorder_.begin_frame(draws);
    std::vector<std::uint32_t> zero(4 * std::max<std::size_t>(draws, 1), 0u);
    if (zero.size() * 4 > decisions_bytes_) {
      glDeleteBuffers(1, &decisions_);
      glCreateBuffers(1, &decisions_);
      decisions_bytes_ = zero.size() * 4;
      glNamedBufferStorage(decisions_, static_cast<GLsizeiptr>(decisions_bytes_), nullptr, GL_DYNAMIC_STORAGE_BIT);
    }
    glNamedBufferSubData(decisions_, 0, static_cast<GLsizeiptr>(zero.size() * 4), zero.data());
    glBindFramebuffer(GL_FRAMEBUFFER, target_->framebuffer());
    target_->clear_depth(false);
    pass_->begin(*target_, view_proj, false, recorder_);
    set_uniforms(window_to_texel);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, decisions_);
    std::vector<std::uint32_t> tested, keep;
    const auto draw_all = [&](const std::vector<std::uint32_t>& list, bool keep_inside) {
      glUniform1i(glGetUniformLocation(pass_->program(), "keep_inside"), keep_inside ? 1 : 0);
      for (std::uint32_t o : list) {
        scene::DrawRecord d;
        d.role = scene::DrawRole::Scene;
        d.object = static_cast<std::int32_t>(o);
        d.state = depth_state(false, true, true);
        tested.push_back(static_cast<std::uint32_t>(pass_->draw_object(recorder_, std::move(d), o)));
        keep.push_back(keep_inside ? 1u : 0u);
      }
    };
    draw_all(objects, false);
    if (lens_ && !focus.empty()) {
      // The focus pass: the same objects flattened towards the ground (y = 0), kept inside the volumes.
      glm::mat4 flatten(1.0f);
      flatten[1][1] = static_cast<float>(lens_height_);
      pass_->begin(*target_, view_proj * flatten, false, recorder_);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, decisions_);
      draw_all(focus, true);
    }
    glFinish();  // GL's time: the draws, not the read-backs after them
    f.end.gl_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::vector<std::uint32_t> words(4 * draws);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    if (draws) glGetNamedBufferSubData(decisions_, 0, static_cast<GLsizeiptr>(words.size() * 4), words.data());
    f.draws = recorder_.collect();
    const std::vector<float> depth = read_depth(target_->framebuffer(), width_, height_, scene::DepthWhich::Final).texels;
    glUseProgram(0);

    std::vector<std::uint32_t> discarded, fetches, hash_a, hash_b;
    std::uint64_t fragments = 0, kept = 0;
    for (std::size_t k = 0; k < tested.size(); ++k) {
      const std::size_t slot = tested[k];
      discarded.push_back(words[4 * slot]);
      fetches.push_back(words[4 * slot + 1]);
      hash_a.push_back(words[4 * slot + 2]);
      hash_b.push_back(words[4 * slot + 3]);
      fragments += f.draws[slot].gl.fragments;
      kept += f.draws[slot].gl.samples_passed;
    }
    trace::TechniqueRecord clip;
    clip.type = trace::kLdiClipChunk;
    clip.decoded = true;
    clip.fields = {{"volume_count", static_cast<std::uint64_t>(gl_volumes_.size())},
                   {"reader", static_cast<std::uint64_t>(reader_)},
                   {"width", static_cast<std::uint64_t>(width_)},
                   {"height", static_cast<std::uint64_t>(height_)},
                   {"epsilon", input_.epsilon},
                   {"view_proj", std::vector<float>(glm::value_ptr(view_proj), glm::value_ptr(view_proj) + 16)},
                   {"window_to_texel", window_to_texel},
                   {"draws", tested},
                   {"keep_inside", keep},
                   {"gl_discarded", discarded},
                   {"gl_fetches", fetches},
                   {"gl_hash_a", hash_a},
                   {"gl_hash_b", hash_b},
                   {"depth_crc", static_cast<std::uint64_t>(ldi::depth_crc(depth))}};
    f.technique_records.push_back(std::move(clip));
    std::uint64_t all_discarded = 0, all_fetches = 0;
    for (std::size_t k = 0; k < discarded.size(); ++k) all_discarded += discarded[k], all_fetches += fetches[k];
    out.counts = {{"clip_draws", tested.size()},      {"clip_fragments", fragments}, {"clip_discarded", all_discarded},
                  {"clip_fetches", all_fetches},       {"clip_samples", kept}};
    f.end.frame = index;
    f.end.draws = static_cast<std::uint32_t>(f.draws.size());
    return out;
  }

 private:
  struct GlVolume {
    GLuint cropped = 0, compressed = 0;
    Rect crop;
    int d = 0, side = 0;
    glm::dmat4 world_to_texel{1.0};
  };

  // Automatic volumes: on the ground ahead of the first frame's eye, alternately left and right.
  void place(const CameraPose& pose) {
    glm::dvec3 ahead(pose.target.x - pose.eye.x, 0.0, pose.target.z - pose.eye.z);
    if (glm::length(ahead) < 1e-9) ahead = glm::dvec3(1, 0, 0);
    ahead = glm::normalize(ahead);
    const glm::dvec3 side(-ahead.z, 0.0, ahead.x);
    for (std::size_t k = 0; k < volumes_.size(); ++k) {
      VolumeSpec& v = volumes_[k];
      if (!v.automatic) continue;
      const double along = 40.0 + 30.0 * static_cast<double>(k), across = k % 2 == 0 ? -6.0 : 6.0;
      v.center = glm::dvec3(pose.eye.x, 0.0, pose.eye.z) + along * ahead + across * side;
      v.center.y = 0.35 * v.size;
    }
  }

  // Each volume must touch the scene's bounds and stay apart from the others.
  void check_placement() const {
    for (std::size_t a = 0; a < volumes_.size(); ++a) {
      const VolumeSpec& v = volumes_[a];
      for (int k = 0; k < 3; ++k)
        if (v.hi()[k] <= scene_lo_[k] || v.lo()[k] >= scene_hi_[k])
          throw InputError(fmt::format("{} lies outside the scene's bounds ({:.1f},{:.1f},{:.1f} to {:.1f},{:.1f},{:.1f}): it would clip nothing",
                                       v.describe(a), scene_lo_.x, scene_lo_.y, scene_lo_.z, scene_hi_.x, scene_hi_.y, scene_hi_.z));
      for (std::size_t b = 0; b < a; ++b) {
        const VolumeSpec& w = volumes_[b];
        bool apart = false;
        for (int k = 0; k < 3; ++k) apart = apart || v.hi()[k] <= w.lo()[k] || w.hi()[k] <= v.lo()[k];
        if (!apart)
          throw InputError(fmt::format(
              "{} and {} overlap (their unit cubes intersect). Each volume has its own LDI and parity test, so a point inside both is "
              "inside the union; but the test cannot tell a lens's styles apart there, and one LDI of both would count every crossing of "
              "both meshes, cancelling where they overlap. Place them apart, or merge them into one closed mesh",
              w.describe(b), v.describe(a)));
      }
    }
  }

  void build_volumes(const CameraPose& pose, scene::Frame& f) {
    place(pose);
    check_placement();
    GLint max_layers = 0, max_side = 0;
    glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &max_layers);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_side);
    for (std::size_t k = 0; k < volumes_.size(); ++k) {
      const VolumeSpec& v = volumes_[k];
      LdiBuild b = build_ldi(v.mesh, input_.config);
      const ldi::CompressedLdi& c = b.compressed;
      if (b.crop.depth_complexity > max_layers || c.side > max_side)
        throw InputError(fmt::format("{}: its LDI has {} layers and a compressed texture {} texels a side; GL allows {} layers and {} texels",
                                     v.describe(k), b.crop.depth_complexity, c.side, max_layers, max_side));
      GlVolume g;
      glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &g.cropped);
      glCreateTextures(GL_TEXTURE_2D, 1, &g.compressed);
      upload_vpt_textures(b, g.cropped, g.compressed);
      g.crop = b.crop.rect;
      g.d = b.crop.depth_complexity;
      g.side = c.side;
      glm::dmat4 world_to_unit(1.0 / v.size);
      world_to_unit[3] = glm::dvec4(0.5 - v.center / v.size, 1.0);
      g.world_to_texel = unit_to_texel(b.map) * world_to_unit;
      gl_volumes_.push_back(g);

      std::vector<float> xyz;
      std::vector<std::uint32_t> tri;
      for (const mesh::Vec3f& p : v.mesh.vertices) xyz.insert(xyz.end(), p.begin(), p.end());
      for (const mesh::Tri& t : v.mesh.triangles) tri.insert(tri.end(), t.begin(), t.end());
      std::vector<float> frame;
      for (const mesh::Vec3d* a : {&b.map.frame.direction, &b.map.frame.right, &b.map.frame.up})
        for (double x : *a) frame.push_back(static_cast<float>(x));
      trace::TechniqueRecord r;
      r.type = trace::kLdiVolumeChunk;
      r.decoded = true;
      r.fields = {{"volume", static_cast<std::uint64_t>(k)},
                  {"shape", v.shape},
                  {"center_x", v.center.x},
                  {"center_y", v.center.y},
                  {"center_z", v.center.z},
                  {"size", v.size},
                  {"mesh_vertices", std::move(xyz)},
                  {"mesh_triangles", std::move(tri)},
                  {"view", std::move(frame)},
                  {"width", static_cast<std::uint64_t>(b.peel.ldi.width())},
                  {"height", static_cast<std::uint64_t>(b.peel.ldi.height())},
                  {"layer_count", static_cast<std::uint64_t>(b.peel.ldi.layer_count())},
                  {"layers", b.peel.ldi.depths()},
                  {"crop_x", std::int64_t{b.crop.rect.x}},
                  {"crop_y", std::int64_t{b.crop.rect.y}},
                  {"crop_w", std::int64_t{b.crop.rect.w}},
                  {"crop_h", std::int64_t{b.crop.rect.h}},
                  {"comp_side", static_cast<std::uint64_t>(c.side)},
                  {"compressed", c.texels}};
      f.technique_records.push_back(std::move(r));
    }
  }

  void set_uniforms(const std::vector<float>& window_to_texel) const {
    const GLuint p = pass_->program();
    glUniform1i(glGetUniformLocation(p, "viewport_width"), width_);
    glUniform1i(glGetUniformLocation(p, "volume_count"), static_cast<GLint>(gl_volumes_.size()));
    glUniform1i(glGetUniformLocation(p, "reader"), static_cast<GLint>(reader_));
    glUniformMatrix4fv(glGetUniformLocation(p, "window_to_texel"), static_cast<GLsizei>(gl_volumes_.size()), GL_FALSE, window_to_texel.data());
    for (int k = 0; k < kMaxVolumes; ++k) {
      // Every sampler on a unit of its own (two sampler types must not share one), unused ones too.
      glUniform1i(glGetUniformLocation(p, fmt::format("layers[{}]", k).c_str()), 2 + k);
      glUniform1i(glGetUniformLocation(p, fmt::format("compressed[{}]", k).c_str()), 2 + kMaxVolumes + k);
      if (static_cast<std::size_t>(k) >= gl_volumes_.size()) continue;
      const GlVolume& v = gl_volumes_[static_cast<std::size_t>(k)];
      glBindTextureUnit(static_cast<GLuint>(2 + k), v.cropped);
      glBindTextureUnit(static_cast<GLuint>(2 + kMaxVolumes + k), v.compressed);
      glUniform4i(glGetUniformLocation(p, fmt::format("crop[{}]", k).c_str()), v.crop.x, v.crop.y, v.crop.w, v.crop.h);
      glUniform1i(glGetUniformLocation(p, fmt::format("depth_complexity[{}]", k).c_str()), v.d);
      glUniform1ui(glGetUniformLocation(p, fmt::format("comp_side[{}]", k).c_str()), static_cast<GLuint>(v.side));
    }
  }

  bool meets_a_volume(const scene::Aabb& b) const {
    // The object's bounds flattened towards y = 0.
    const glm::dvec3 lo(b.lo[0], b.lo[1] * lens_height_, b.lo[2]), hi(b.hi[0], b.hi[1] * lens_height_, b.hi[2]);
    for (const VolumeSpec& v : volumes_) {
      bool apart = false;
      for (int k = 0; k < 3; ++k) apart = apart || hi[k] < v.lo()[k] || v.hi()[k] < lo[k];
      if (!apart) return true;
    }
    return false;
  }


  int width_, height_;
  const CaptureScene& scene_;
  Projection projection_;
  LdiShapeInput input_;
  bool lens_ = false;
  ldi::ClipReader reader_ = ldi::ClipReader::All;
  double lens_height_ = 0.25;
  std::string volumes_text_;
  std::vector<VolumeSpec> volumes_;
  glm::dvec3 scene_lo_{0.0}, scene_hi_{0.0};
  std::vector<GlVolume> gl_volumes_;
  std::unique_ptr<ScenePass> pass_;
  std::unique_ptr<RenderTarget> target_;
  GLuint decisions_ = 0;
  std::size_t decisions_bytes_ = 0;
  DrawRecorder recorder_;
};

}  // namespace

const std::vector<OptionSpec>& ldi_application_options() {
  static const std::vector<OptionSpec> options = {application_option(), volumes_option(), reader_option(), lens_height_option()};
  return options;
}

bool ldi_application_chosen(const OptionValues& o) { return o.text(application_option()) != "shape"; }

std::unique_ptr<Technique> make_ldi_application(const TechniqueSetup& setup, LdiShapeInput input) {
  return std::make_unique<LdiApplication>(setup, std::move(input));
}

}  // namespace nbsim::capture

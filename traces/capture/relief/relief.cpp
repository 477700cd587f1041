// The `relief` capture technique; see relief.h.
#include "traces/capture/relief/relief.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <sstream>
#include <string>

#include "model/common/error.h"
#include "model/mesh/shapes.h"
#include "model/relief/box_depth.h"
#include "model/relief/heightfield.h"
#include "model/relief/paper_radius.h"
#include "model/relief/radius.h"
#include "model/relief/score.h"
#include "model/relief/walk.h"
#include "model/scene/visibility.h"
#include "io/image_io.h"
#include "traces/capture/camera.h"
#include "traces/capture/draw_recorder.h"
#include "traces/capture/ldi/mesh_loader.h"
#include "traces/capture/relief/bake.h"
#include "traces/capture/relief/gl_walk.h"
#include "traces/capture/relief/view.h"
#include "traces/capture/render_target.h"
#include "traces/capture/scene_pass.h"
#include "traces/format/relief/relief_chunk.h"
#include "model/relief/roles.h"

namespace nbsim::capture {
namespace {

const OptionSpec& field_option() {
  static const OptionSpec spec =
      text_option("field", "Procedural heightfield: fbm, walls, spikes, saddle or step (model/relief/heightfield.h)", "fbm");
  return spec;
}
const OptionSpec& field_param_option() {
  static const OptionSpec spec = integer_option(
      "field-param", "The field's parameter (fbm: octaves, walls: spacing, spikes: count); 0 takes the field's default", 0, 0, 1 << 20);
  return spec;
}
const OptionSpec& field_size_option() {
  static const OptionSpec spec = integer_option("field-size", "Side N of the procedural heightfield, texels (2 to 1024)", 64, 1, 1 << 20);
  return spec;
}
const OptionSpec& field_file_option() {
  static const OptionSpec spec = text_option(
      "field-file", "A square single-channel image (EXR, PNG, ... through OpenImageIO) of heights in [0, 1] instead of --field ('none': use --field)",
      "none");
  return spec;
}
const OptionSpec& field_mesh_option() {
  static const OptionSpec spec = text_option(
      "field-mesh", "Bake the heightfield from a mesh seen from above: a mesh file assimp reads, or shape:NAME[:PARAM] "
                    "(model/mesh/shapes.h); --field-size texels a side ('none': use --field)",
      "none");
  return spec;
}
const OptionSpec& radius_file_option() {
  static const OptionSpec spec = text_option(
      "radius-file", "A single-channel image of safety radii in texels for the field, checked against the strict guarantee; it replaces "
                     "--radius ('none': computed)", "none");
  return spec;
}
const OptionSpec& radius_option() {
  static const OptionSpec spec = choice_option(
      "radius", "The safety radius: paper (Baboud & Decoret 3.5, the default: unblocked rays only, the maximum over directions, "
                "with --radius-epsilon and --radius-combine) or strict (nbsim's: every ray from anywhere in the texel, blocked ones "
                "too, so the robust search never steps over a crossing)",
      "paper", {"paper", "strict"});
  return spec;
}
const OptionSpec& radius_epsilon_option() {
  static const OptionSpec spec = text_option(
      "radius-epsilon", "Paper radius: how far (box heights, 0 to 1) a ray may pass under the surface without counting as a second "
                        "crossing; larger gives larger radii and misses silhouettes up to that tall",
      "0");
  return spec;
}
const OptionSpec& radius_combine_option() {
  static const OptionSpec spec = choice_option(
      "radius-combine", "Paper radius: a texel's radius is the maximum over directions (the paper's wording) or the minimum (a bound "
                        "for every ray)",
      "max", {"max", "min"});
  return spec;
}
const OptionSpec& max_radius_option() {
  static const OptionSpec spec = integer_option("max-radius", "Cap of the safety radius, texels", 16, 1, 255);
  return spec;
}
const OptionSpec& methods_option() {
  static const OptionSpec spec =
      text_option("methods", "Walk methods, comma-separated: binary, exact, robust, robust_clamp, nbuffer (or all); one box draw each", "all");
  return spec;
}
const OptionSpec& angles_option() {
  static const OptionSpec spec = text_option(
      "angles", "View angles from the box's up axis, degrees, comma-separated (0 head-on from above, 80 to 89 grazing, up to 179.9 from "
                "below); frame k takes angle k mod count",
      "0,45,80,89");
  return spec;
}
const OptionSpec& box_height_option() {
  static const OptionSpec spec = text_option("box-height", "Height of the box over its width (the heightfield's 1.0)", "0.25");
  return spec;
}
const OptionSpec& linear_steps_option() {
  static const OptionSpec spec = integer_option("linear-steps", "binary: linear steps before the bisection", 16, 1, 1024);
  return spec;
}
const OptionSpec& binary_steps_option() {
  static const OptionSpec spec = integer_option("binary-steps", "binary and robust: bisections after the bracket", 8, 0, 32);
  return spec;
}
const OptionSpec& root_steps_option() {
  static const OptionSpec spec = integer_option("root-steps", "exact, nbuffer and robust's cell steps: bisections inside a cell", 16, 0, 32);
  return spec;
}
const OptionSpec& frustum_option() {
  static const OptionSpec spec = text_option(
      "frustum", "0: the box; A > 0: a reverse-perspective frustum over the box's bottom face, its apex A box heights below it "
                 "(traces/capture/relief/view.h); a --field-mesh is baked along the frustum's rays",
      "0");
  return spec;
}
const OptionSpec& placement_option() {
  static const OptionSpec spec = choice_option(
      "placement", "own: the box seen from its own camera (--angles); city: the box standing in the capture's scene, seen by the "
                   "observer along --path, the scene drawn first (early depth tests cull the box's hidden fragments)",
      "own", {"own", "city"});
  return spec;
}
const OptionSpec& box_depth_option() {
  static const OptionSpec spec = choice_option(
      "box-depth", "what a box draw leaves in the depth buffer (the relief paper's section 4.4; model/relief/box_depth.h): box: "
                   "the box face's depth where the ray hit, a miss discarded (the paper's; early depth test, late write); exact: "
                   "the hit's depth (gl_FragDepth: every fragment walks, tested after); none: nothing (depth writes off)",
      "box", {"box", "exact", "none"});
  return spec;
}
const OptionSpec& box_at_option() {
  static const OptionSpec spec = text_option(
      "box-at", "placement city: X,Z,SIZE in metres (the box's corner on the ground at y = 0 and its side; its height is "
                "--box-height x SIZE), or 'auto': 40 m ahead of the first frame's eye, 16 m a side",
      "auto");
  return spec;
}
const OptionSpec& relief_covering_option() {
  static const OptionSpec spec = covering_option();
  return spec;
}

const OptionSpec& tolerance_option() {
  static const OptionSpec spec =
      text_option("tolerance", "Hit error tolerance for the capture's own counts, texels (model/relief/score.h)", "0.25");
  return spec;
}

double parse_number(const std::string& s, const char* option, double lo, double hi) { return parse_real(s, std::string("--") + option, lo, hi); }

std::vector<std::string> split(const std::string& s) { return split_list(s, ','); }

std::vector<relief::Method> parse_methods(const std::string& s) {
  if (s == "all") return {relief::kAllMethods.begin(), relief::kAllMethods.end()};
  std::vector<relief::Method> out;
  for (const std::string& name : split(s)) {
    const std::optional<relief::Method> m = relief::parse_method(name);
    if (!m) throw InputError(fmt::format("--methods: '{}' is not a method (binary, exact, robust, robust_clamp, nbuffer or all)", name));
    out.push_back(*m);
  }
  if (out.empty()) throw InputError("--methods names no method");
  return out;
}

std::vector<double> parse_angles(const std::string& s) {
  std::vector<double> out;
  for (const std::string& a : split(s)) out.push_back(parse_number(a, "angles", 0.0, 179.9));
  if (out.empty()) throw InputError("--angles names no angle");
  return out;
}

// A single-channel image as a square grid of floats, y up.
relief::Heightfield read_square(const std::string& file, const char* what) {
  if (!std::filesystem::exists(file)) throw InputError(fmt::format("{} '{}' does not exist", what, file));
  const DepthImage img = io::read_values(file);
  if (img.width != img.height)
    throw InputError(fmt::format("{} '{}' is {}x{}; a heightfield is square", what, file, img.width, img.height));
  relief::Heightfield f;
  f.size = img.width;
  f.heights = img.texels;
  return f;
}

std::string join(const std::vector<double>& v) {
  std::string s;
  for (double a : v) {
    if (!s.empty()) s += ',';
    s += fmt::format("{}", a);  // appended, not "," + ...: GCC 12's -Wstringop-overflow misreads that form
  }
  return s;
}

// A frustum's qa, qb, qc in a row (RLFH ray_q), or nothing for a box.
std::vector<float> ray_q(const relief::RayFrame& r) {
  if (!r.frustum) return {};
  std::vector<float> q;
  for (const auto* v : {&r.qa, &r.qb, &r.qc}) q.insert(q.end(), v->begin(), v->end());
  return q;
}

class Relief final : public Technique {
 public:
  explicit Relief(const TechniqueSetup& s) : width_(s.width), height_(s.height), scene_(s.scene), projection_(s.projection) {
    const OptionValues& o = s.options;
    city_ = o.text(placement_option()) == "city";
    if (city_ && s.projection.reversed_z) throw InputError("--placement city: reversed Z is not supported (the box draws test LESS)");
    // (Checked against the defaults, not for presence: a recorded command line spells every option out.)
    if (!city_ && o.text(box_at_option()) != box_at_option().default_value) throw InputError("--box-at needs --placement city");
    if (city_ && o.text(angles_option()) != angles_option().default_value)
      throw InputError("--angles is for --placement own (in the city the observer's path views the box)");
    box_at_ = o.text(box_at_option());
    box_depth_ = *relief::parse_box_depth(o.text(box_depth_option()));
    seed_ = static_cast<std::uint64_t>(o.integer(seed_option()));
    max_radius_ = static_cast<int>(o.integer(max_radius_option()));
    apex_ = parse_number(o.text(frustum_option()), "frustum", 0.0, 1e6);
    box_height_ = parse_number(o.text(box_height_option()), "box-height", 1e-3, 16.0);
    const std::string file = o.text(field_file_option());
    const std::string mesh_source = o.text(field_mesh_option());
    if (file != "none" && mesh_source != "none") throw InputError("give --field-file or --field-mesh, not both");
    if (mesh_source != "none") {
      if (o.has("field") || o.has("field-param")) throw InputError("give --field or --field-mesh, not both");
      mesh::TriMesh m;
      if (mesh_source.rfind("shape:", 0) == 0) {
        const std::string spec = mesh_source.substr(6);
        const std::size_t colon = spec.find(':');
        std::optional<int> param;
        if (colon != std::string::npos) param = static_cast<int>(parse_number(spec.substr(colon + 1), "field-mesh", 1, 1000));
        m = mesh::make_shape(spec.substr(0, colon), param);
      } else {
        m = load_mesh(mesh_source);
      }
      field_ = bake_heightfield(std::move(m), static_cast<int>(o.integer(field_size_option())), box_height_, apex_);
      relief::check_heightfield(field_, fmt::format("the heightfield baked from '{}'", mesh_source));
      description_ = "mesh:" + std::filesystem::path(mesh_source).filename().string();
    } else if (file != "none") {
      if (o.has("field") || o.has("field-param") || o.has("field-size")) throw InputError("give --field or --field-file, not both");
      field_ = read_square(file, "--field-file");
      relief::check_heightfield(field_, fmt::format("the heightfield in '{}'", file));
      description_ = "file:" + std::filesystem::path(file).filename().string();
    } else {
      const int n = static_cast<int>(o.integer(field_size_option()));
      const int param = static_cast<int>(o.integer(field_param_option()));
      field_ = relief::make_heightfield(o.text(field_option()), n, param, seed_);
      description_ = fmt::format("{}:{} seed {}", o.text(field_option()), param, seed_);
    }
    for (float& h : field_.heights) h += 0.0f;  // -0.0 becomes +0.0: one zero, so GL's max and the model's agree bit for bit
    paper_radius_ = o.text(radius_option()) == "paper";
    paper_.epsilon = parse_number(o.text(radius_epsilon_option()), "radius-epsilon", 0.0, 1.0);
    paper_.combine = o.text(radius_combine_option()) == "min" ? relief::RadiusCombine::Min : relief::RadiusCombine::Max;
    if (!paper_radius_ && (paper_.epsilon != 0.0 || paper_.combine != relief::RadiusCombine::Max))
      throw InputError("--radius-epsilon and --radius-combine set the paper's radius: add --radius paper");
    const std::string radius_file = o.text(radius_file_option());
    if (radius_file != "none") {
      // The file's radii replace the computed ones and are held to the strict guarantee.
      if (paper_.epsilon != 0.0 || paper_.combine != relief::RadiusCombine::Max)
        throw InputError("--radius-file gives the radii: it takes no --radius-epsilon or --radius-combine (the file is checked "
                         "against the strict guarantee)");
      paper_radius_ = false;
    }
    if (radius_file != "none") {
      const relief::Heightfield r = read_square(radius_file, "--radius-file");
      radius_ = {r.size, r.heights};
      if (const std::string problem = relief::radius_problem(field_, radius_, max_radius_); !problem.empty())
        throw InputError(fmt::format("--radius-file '{}' does not match the heightfield: {}", radius_file, problem));
    } else if (paper_radius_) {
      radius_ = relief::paper_safety_radius(field_, max_radius_, paper_);
    } else {
      radius_ = relief::safety_radius(field_, max_radius_);
    }
    methods_ = parse_methods(o.text(methods_option()));
    angles_ = parse_angles(o.text(angles_option()));
    params_.linear_steps = static_cast<int>(o.integer(linear_steps_option()));
    params_.binary_steps = static_cast<int>(o.integer(binary_steps_option()));
    params_.root_steps = static_cast<int>(o.integer(root_steps_option()));
    params_.covering = read_covering(o, relief_covering_option());
    tolerance_ = parse_number(o.text(tolerance_option()), "tolerance", 0.0, 1e6);
    if (city_ && apex_ > 0.0) throw InputError("--placement city takes the box, not a --frustum");
    walker_ = std::make_unique<GlReliefWalker>(width_, height_, params_.covering, box_depth_);
    if (city_) {
      pass_ = std::make_unique<ScenePass>(scene_, false);
      target_ = std::make_unique<RenderTarget>(width_, height_);
      glCreateTextures(GL_TEXTURE_2D, 1, &saved_depth_);
      glTextureStorage2D(saved_depth_, 1, GL_DEPTH_COMPONENT32F, width_, height_);
    }
  }

  ~Relief() override { glDeleteTextures(1, &saved_depth_); }
  Relief(const Relief&) = delete;
  Relief& operator=(const Relief&) = delete;

  trace::Properties variant_properties() const override {
    std::string methods;
    for (relief::Method m : methods_) {
      if (!methods.empty()) methods += ',';
      methods += relief::to_string(m);
    }
    return {{"relief_field", description_}, {"relief_methods", methods}, {"relief_placement", city_ ? "city" : "own"}};
  }
  trace::Properties setting_properties() const override {
    return {{"relief_field_size", std::to_string(field_.size)},
            {"relief_box_height", fmt::format("{}", box_height_)},
            {"relief_frustum_apex", fmt::format("{}", apex_)},
            {"relief_angles", join(angles_)},
            {"relief_max_radius", std::to_string(max_radius_)},
            {"relief_radius", paper_radius_ ? "paper" : "strict"},
            {"relief_box_depth", std::string(relief::kBoxDepthNames[static_cast<std::size_t>(box_depth_)])},
            {"relief_radius_epsilon", fmt::format("{}", paper_.epsilon)},
            {"relief_radius_combine", std::string(relief::kRadiusCombineNames[static_cast<std::size_t>(paper_.combine)])},
            {"relief_linear_steps", std::to_string(params_.linear_steps)},
            {"relief_binary_steps", std::to_string(params_.binary_steps)},
            {"relief_root_steps", std::to_string(params_.root_steps)},
            covering_property(params_.covering),
            {"relief_seed", std::to_string(seed_)},
            {"relief_view", "the box [0,1]^2 x [0,relief_box_height] seen from angle k mod count of relief_angles off its up axis, "
                            "azimuth 37 + 61 k + 13 seed degrees, framing the box; rays rebuilt from gl_FragCoord (model/relief/walk.h)"},
            {"observer", city_ ? "the box stands in the scene (relief_box_at); the observer's path and projection view it"
                               : "unused: the relief technique views its box from its own camera; no scene is built and no camera "
                                 "path followed, the projection is ignored, --size is the viewport"},
            {"relief_box_at", box_at_}};
  }

  CapturedFrame render(std::uint32_t index, const CameraPose& pose) override {
    CapturedFrame out;
    scene::Frame& f = out.frame;
    f.begin.frame = index;
    f.begin.mode = scene::TestMode::None;
    double angle = angles_[index % angles_.size()];
    ReliefCamera cam;
    // The observer's camera (placement city): the scene's draws and the box's texel-to-clip.
    const glm::mat4 view = view_matrix(pose), proj = projection_matrix(projection_, static_cast<double>(width_) / height_);
    if (city_) {
      if (index == 0) place_box(pose);
      std::array<double, 16> v{}, p{};
      for (std::size_t k = 0; k < 16; ++k) v[k] = glm::value_ptr(view)[k], p[k] = glm::value_ptr(proj)[k];
      cam = relief_view(v, p, world_to_texel_, width_, height_);
      const glm::dvec3 forward = glm::normalize(glm::dvec3(pose.target - pose.eye));
      angle = glm::degrees(std::acos(std::clamp(-forward.y, -1.0, 1.0)));  // from the box's up axis (world y)
    } else {
      const double azimuth = std::fmod(37.0 + 61.0 * index + 13.0 * static_cast<double>(seed_ % 1000), 360.0);
      cam = relief_camera(field_.size, box_height_, angle, azimuth, width_, height_, apex_);
    }
    for (std::size_t k = 0; k < 16; ++k) {
      f.begin.view[k] = static_cast<float>(cam.world_view[k]);
      f.begin.proj[k] = static_cast<float>(cam.projection[k]);
    }
    for (std::size_t k = 0; k < 3; ++k) f.begin.eye[k] = static_cast<float>(cam.eye_world[k]);

    const auto t0 = std::chrono::steady_clock::now();
    // Placement city: the objects in the frustum, front to back as an engine sorts its opaque draws,
    // split at the box: those whose bounds come nearer the eye than the box's are drawn before it
    // (they may hide box fragments: walks saved by the early test), the others after each box draw
    // (the box's depth may hide them).
    std::vector<std::uint32_t> before, after;
    if (city_) {
      const scene::FrameView fv = scene::FrameView::make(f.begin, width_, height_, projection_.near_m, 0.0, false, false);
      const glm::dvec3 eye(pose.eye);
      const double box_distance = scene::distance_to(box_bounds_, eye);
      for (std::uint32_t o : scene::frustum_objects(scene_.scene, fv))
        (scene::distance_to(scene_.scene.objects[o], eye) < box_distance ? before : after).push_back(o);
    }
    recorder_.begin_frame(16 + before.size() + methods_.size() * (1 + after.size()));
    const glm::mat4 city_view_proj = proj * view;
    const auto draw_scene = [&](const std::vector<std::uint32_t>& objects) {
      pass_->begin(*target_, city_view_proj, false, recorder_);
      for (std::uint32_t o : objects) {
        scene::DrawRecord d;
        d.role = scene::DrawRole::Scene;
        d.object = static_cast<std::int32_t>(o);
        d.state = depth_state(false, true, true);
        pass_->draw_object(recorder_, std::move(d), o);
      }
    };
    if (city_) {  // the scene's depth first: the box draws test against it
      glBindFramebuffer(GL_FRAMEBUFFER, target_->framebuffer());
      target_->clear_depth(false);
      draw_scene(before);
      glCopyImageSubData(target_->depth_texture(), GL_TEXTURE_2D, 0, 0, 0, 0, saved_depth_, GL_TEXTURE_2D, 0, 0, 0, 0, width_, height_, 1);
    }
    walker_->set_field(field_, radius_, recorder_);
    const std::vector<float> levels = walker_->levels();
    std::vector<GlFragments> gl;
    double readback_ms = 0.0;
    for (relief::Method m : methods_) {
      // Every method's box starts from the same depth (box_depth.h): the scene's before it, or clear.
      if (city_) glCopyImageSubData(saved_depth_, GL_TEXTURE_2D, 0, 0, 0, 0, target_->depth_texture(), GL_TEXTURE_2D, 0, 0, 0, 0, width_, height_, 1);
      else walker_->clear_depth();
      gl.push_back(walker_->draw(m, cam.view, params_, recorder_, city_ ? target_->framebuffer() : 0));
      readback_ms += gl.back().readback_ms;
      if (city_) draw_scene(after);
    }
    f.draws = recorder_.collect();
    if (city_) {
      std::memcpy(f.begin.view.data(), glm::value_ptr(view), 64);
      std::memcpy(f.begin.proj.data(), glm::value_ptr(proj), 64);
      f.begin.eye = {pose.eye.x, pose.eye.y, pose.eye.z};
    }
    f.end.gl_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() - readback_ms;

    trace::TechniqueRecord field;
    field.type = trace::kReliefFieldChunk;
    field.decoded = true;
    const auto vec3 = [](const std::array<float, 3>& v) { return std::vector<float>(v.begin(), v.end()); };
    field.fields = {{"size", static_cast<std::uint64_t>(field_.size)},
                    {"levels", static_cast<std::uint64_t>(walker_->level_count())},
                    {"max_radius", static_cast<std::uint64_t>(max_radius_)},
                    {"field", description_},
                    {"heights", field_.heights},
                    {"radius", radius_.radius},
                    {"nbuffer", levels},
                    {"linear_steps", static_cast<std::uint64_t>(params_.linear_steps)},
                    {"binary_steps", static_cast<std::uint64_t>(params_.binary_steps)},
                    {"root_steps", static_cast<std::uint64_t>(params_.root_steps)},
                    {"origin", vec3(cam.view.ray.origin)},
                    {"ray_a", vec3(cam.view.ray.a)},
                    {"ray_b", vec3(cam.view.ray.b)},
                    {"ray_c", vec3(cam.view.ray.c)},
                    {"view_angle", angle},
                    {"frustum_apex", apex_},
                    {"eye_h", cam.view.ray.frustum ? std::vector<float>(cam.view.ray.eye_h.begin(), cam.view.ray.eye_h.end())
                                                   : std::vector<float>{}},
                    {"ray_q", ray_q(cam.view.ray)}};
    f.technique_records.push_back(std::move(field));

    // One RLFF a box draw, in draw order; the capture's own score of each method (the methods share
    // the frame's rays: each pixel's reference is computed once).
    std::map<std::uint32_t, relief::ReferenceHit> references;
    const relief::ReferenceBlocks blocks(field_);
    std::size_t box = 0;
    std::vector<std::uint32_t> depth_draws, depth_crcs;  // RLFD: the depth each box draw left
    for (const scene::DrawRecord& d : f.draws) {
      if (d.role != nbsim::relief::kReliefBoxRole) continue;
      const relief::Method m = methods_[box];
      const GlFragments& g = gl[box++];
      std::uint64_t errors = 0, lookups = 0, hits = 0;
      for (std::size_t k = 0; k < g.pixel.size(); ++k) {
        lookups += g.lookups[k];
        hits += g.hit[k] == trace::kReliefHit;
        const float px = static_cast<float>(g.pixel[k] % static_cast<std::uint32_t>(width_)) + 0.5f;
        const float py = static_cast<float>(g.pixel[k] / static_cast<std::uint32_t>(width_)) + 0.5f;
        if (const auto ray = relief::fragment_ray(cam.view.ray, field_.size, px, py)) {
          const auto [at, fresh] = references.try_emplace(g.pixel[k]);
          if (fresh) at->second = relief::reference_of(field_, *ray, &blocks);
          errors += relief::score_against(at->second, *ray, field_.size, g.hit[k] == trace::kReliefHit, g.t[k], box_height_, tolerance_)
                        .error != relief::HitError::None;
        }
      }
      const std::string name(relief::to_string(m));
      counts_add(out, name + "_fragments", g.pixel.size());
      counts_add(out, name + "_hits", hits);
      counts_add(out, name + "_lookups", lookups);
      counts_add(out, name + "_errors", errors);
      trace::TechniqueRecord r;
      r.type = trace::kReliefFragmentsChunk;
      r.decoded = true;
      r.fields = {{"draw", std::uint64_t{d.index}},
                  {"method", static_cast<std::uint64_t>(m)},
                  {"count", static_cast<std::uint64_t>(g.pixel.size())},
                  {"pixel", g.pixel},
                  {"hit", g.hit},
                  {"t", g.t},
                  {"lookups", g.lookups},
                  {"steps", g.steps},
                  {"bisections", g.bisections}};
      f.technique_records.push_back(std::move(r));
      if (g.depth_crc) depth_draws.push_back(d.index), depth_crcs.push_back(*g.depth_crc);
    }
    if (box_depth_ != relief::BoxDepth::None) {
      trace::TechniqueRecord depth;
      depth.type = trace::kReliefDepthChunk;
      depth.decoded = true;
      depth.fields = {{"texel_to_clip", std::vector<float>(cam.view.texel_to_clip.begin(), cam.view.texel_to_clip.end())},
                      {"draws", depth_draws},
                      {"depth_crc", depth_crcs}};
      f.technique_records.push_back(std::move(depth));
    }
    f.end.frame = index;
    f.end.draws = static_cast<std::uint32_t>(f.draws.size());
    return out;
  }

 private:
  // The box in the city: from --box-at, or 40 m ahead of the first frame's eye on the ground, 16 m a
  // side. Texel space to world: x -> X + x S / N, z (height) -> y = z H, y -> Z - y S / N (the
  // mirror keeps the box's winding), H = box_height x S.
  void place_box(const CameraPose& pose) {
    double x0 = 0, z0 = 0, side = 16.0;
    if (box_at_ == "auto") {
      glm::dvec3 ahead(pose.target.x - pose.eye.x, 0.0, pose.target.z - pose.eye.z);
      if (glm::length(ahead) < 1e-9) ahead = glm::dvec3(1, 0, 0);
      const glm::dvec3 c = glm::dvec3(pose.eye) + 40.0 * glm::normalize(ahead);
      x0 = c.x - side / 2, z0 = c.z + side / 2;
    } else {
      const std::vector<std::string> parts = split(box_at_);
      if (parts.size() != 3) throw InputError(fmt::format("--box-at '{}' is not X,Z,SIZE", box_at_));
      x0 = parse_number(parts[0], "box-at", -1e6, 1e6);
      z0 = parse_number(parts[1], "box-at", -1e6, 1e6);
      side = parse_number(parts[2], "box-at", 1e-3, 1e5);
    }
    const double n = field_.size, h = box_height_ * side;
    glm::dmat4 to_world(0.0);  // [column][row]
    to_world[0][0] = side / n;
    to_world[2][1] = h;
    to_world[1][2] = -side / n;
    to_world[3] = glm::dvec4(x0, 0.0, z0, 1.0);
    box_bounds_.lo = {static_cast<float>(x0), 0.0f, static_cast<float>(z0 - side)};
    box_bounds_.hi = {static_cast<float>(x0 + side), static_cast<float>(h), static_cast<float>(z0)};
    const glm::dmat4 f = glm::inverse(to_world);
    for (std::size_t k = 0; k < 16; ++k) world_to_texel_[k] = glm::value_ptr(f)[k];
    box_at_ = fmt::format("{},{},{}", x0, z0, side);
  }


  static void counts_add(CapturedFrame& out, const std::string& name, std::uint64_t v) { out.counts.emplace_back(name, v); }

  int width_, height_;
  std::uint64_t seed_ = 1;
  int max_radius_ = 16;
  relief::Heightfield field_;
  relief::SafetyRadius radius_;
  bool paper_radius_ = false;         // --radius paper
  relief::PaperRadiusOptions paper_;  // its epsilon and combination
  std::string description_;
  std::vector<relief::Method> methods_;
  std::vector<double> angles_;
  double box_height_ = 0.25, tolerance_ = relief::kDefaultHitTolerance, apex_ = 0.0;
  relief::WalkParams params_;
  const CaptureScene& scene_;
  Projection projection_;
  bool city_ = false;
  std::string box_at_;
  relief::BoxDepth box_depth_ = relief::BoxDepth::Box;
  scene::Aabb box_bounds_;      // the box in world space (placement city)
  GLuint saved_depth_ = 0;      // the scene's depth before the box draws (placement city), restored before each
  std::array<double, 16> world_to_texel_{};
  std::unique_ptr<ScenePass> pass_;
  std::unique_ptr<RenderTarget> target_;
  DrawRecorder recorder_;
  std::unique_ptr<GlReliefWalker> walker_;
};

}  // namespace

const std::vector<OptionSpec>& relief_options() {
  static const std::vector<OptionSpec> options = {field_option(),        field_param_option(), field_size_option(),   field_file_option(),  field_mesh_option(),
                                                  radius_file_option(),  radius_option(), radius_epsilon_option(), radius_combine_option(), max_radius_option(),  methods_option(),      angles_option(),
                                                  box_height_option(),   frustum_option(),     linear_steps_option(), binary_steps_option(), root_steps_option(),
                                                  tolerance_option(),    placement_option(),   box_at_option(),       box_depth_option(),       relief_covering_option(),
                                                  align_option(),        seed_option()};
  return options;
}

BenchPreset relief_bench_preset() {
  // The box is seen from its own camera: no scene is built (relief_technique's no_scene); --size is the viewport.
  // The replay leaves out the exact reference, as the capture's timing leaves out GL's reference pass.
  return {"boxes", "fly", "512x512", {{"field", "fbm"}, {"field-size", "128"}}, "field", {"relief.score=false"}};
}

std::unique_ptr<Technique> make_relief(const TechniqueSetup& setup) { return std::make_unique<Relief>(setup); }

// This technique's row of the capture's table (technique.h).
TechniqueRow relief_technique() {
  return {{"relief",
           "Relief textures: a heightfield in a box, each fragment's ray walked by binary search, the exact cell walk, the "
           "robust search with safety radii (two zero-radius variants) or the N-buffer empty-space walk, scored against an "
           "exact reference (Baboud & Decoret; the N-buffer paper's future work)",
           relief_options()},
          make_relief,
          relief_bench_preset(),
          {},
          [](const OptionValues& o) {
            return o.text(placement_option()) == "city" ? std::string()
                                                        : std::string("the box is seen from its own camera (--angles); --placement city stands it in a scene");
          }};
}

}  // namespace nbsim::capture

// The `ldi` capture technique; see ldi.h.
#include "traces/capture/ldi/ldi.h"

#include <fmt/format.h>

#include <chrono>
#include <numeric>
#include <cstdio>
#include <filesystem>
#include <cmath>
#include <random>
#include <string>

#include "model/common/error.h"
#include "model/mesh/crossings.h"
#include "model/mesh/mesh.h"
#include "model/mesh/shapes.h"
#include "traces/capture/draw_recorder.h"
#include "traces/capture/ldi/build.h"
#include "traces/capture/ldi/clip.h"
#include "traces/capture/ldi/mesh_loader.h"
#include "traces/capture/ldi/test_points.h"
#include "traces/format/ldi/ldi_chunk.h"

namespace nbsim::capture {
namespace {

const OptionSpec& shape_option() {
  static const OptionSpec spec = text_option("shape", "Procedural shape: sphere, knot, nested, coil or box (model/mesh/shapes.h)", "sphere");
  return spec;
}
const OptionSpec& shape_param_option() {
  static const OptionSpec spec =
      integer_option("shape-param", "The shape's parameter (nested: shells, coil: turns); 0 takes the shape's default", 0, 0, 1000);
  return spec;
}
const OptionSpec& mesh_option() {
  static const OptionSpec spec = text_option("mesh", "A closed mesh file read with assimp instead of --shape ('none': use --shape)", "none");
  return spec;
}
const OptionSpec& ldi_size_option() {
  static const OptionSpec spec = integer_option("ldi-size", "Side of the square LDI, texels", 256, 1, ldi::kMaxSideTexels);
  return spec;
}
const OptionSpec& grid_option() {
  static const OptionSpec spec = text_option("grid", "Viewpoint grid s_H x s_V (directions around the vertical axis x elevations)", "8x8");
  return spec;
}
const OptionSpec& max_layers_option() {
  static const OptionSpec spec =
      integer_option("max-layers", "Most layers the peel may store; a deeper LDI is refused", 64, 1, ldi::kMaxLayers);
  return spec;
}
const OptionSpec& points_option() {
  static const OptionSpec spec = integer_option("points", "Test points of the parity test per frame", 4096, 0, 1000000);
  return spec;
}
const OptionSpec& epsilon_option() {
  static const OptionSpec spec = text_option(
      "epsilon", "Near-surface distance of the exact reference, unit-cube units along the ray (points nearer are counted apart)", "1e-5");
  return spec;
}

std::pair<int, int> parse_grid(const std::string& s) {
  int h = 0, v = 0;
  char x = 0, rest = 0;
  if (std::sscanf(s.c_str(), "%d%c%d%c", &h, &x, &v, &rest) != 3 || x != 'x')
    throw InputError(fmt::format("--grid '{}' is not HxV (e.g. 8x8)", s));
  if (h < 1 || v < 1 || h > 1024 || v > 1024)
    throw InputError(fmt::format("--grid {}: each side must be 1 to 1024 (a grid of zero directions has no viewpoint)", s));
  return {h, v};
}

double parse_epsilon(const std::string& s) {
  std::size_t used = 0;
  double e = -1.0;
  try {
    e = std::stod(s, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != s.size() || !(e >= 0.0 && e < 1.0)) throw InputError(fmt::format("--epsilon '{}' is not a number in [0, 1)", s));
  return e;
}

// A uniform random rotation (unit quaternion from three uniforms, Shoemake), column-major 3x3.
std::array<double, 9> random_rotation(std::uint64_t seed, std::uint32_t frame) {
  if (frame == 0) return {1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + frame);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double u1 = u(rng), u2 = u(rng), u3 = u(rng);
  const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
  const double qx = a * std::sin(2 * M_PI * u2), qy = a * std::cos(2 * M_PI * u2);
  const double qz = b * std::sin(2 * M_PI * u3), qw = b * std::cos(2 * M_PI * u3);
  // Row-major r[i][j], stored column-major.
  const double r[3][3] = {{1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)},
                          {2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)},
                          {2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)}};
  std::array<double, 9> m{};
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < 3; ++i) m[c * 3 + i] = r[i][c];
  return m;
}

// The options every ldi capture reads: the shape (or mesh), the build settings, the epsilon.
struct ShapeOptions {
  std::string shape, mesh_file;
  int shape_param = 0;
  mesh::TriMesh mesh;
  LdiBuildConfig config;
  int points = 0;
  double epsilon = 1e-5;
  std::uint64_t seed = 1;
};

ShapeOptions read_shape_options(const OptionValues& o) {
  ShapeOptions r;
  r.mesh_file = o.text(mesh_option());
  r.shape = o.text(shape_option());
  const int param = static_cast<int>(o.integer(shape_param_option()));
  if (r.mesh_file != "none") {
    if (o.has("shape") || o.has("shape-param")) throw InputError("give --shape or --mesh, not both");
    r.mesh = load_mesh(r.mesh_file);
    r.shape = "mesh:" + std::filesystem::path(r.mesh_file).filename().string();
    mesh::require_closed(r.mesh, fmt::format("--mesh '{}'", r.mesh_file));
  } else {
    r.mesh = mesh::make_shape(r.shape, param > 0 ? std::optional<int>(param) : std::nullopt);
    mesh::require_closed(r.mesh, fmt::format("--shape {}", r.shape));
  }
  r.shape_param = param;
  std::tie(r.config.grid_h, r.config.grid_v) = parse_grid(o.text(grid_option()));
  r.config.size_texels = static_cast<int>(o.integer(ldi_size_option()));
  r.config.max_layers = static_cast<int>(o.integer(max_layers_option()));
  r.points = static_cast<int>(o.integer(points_option()));
  r.epsilon = parse_epsilon(o.text(epsilon_option()));
  r.seed = static_cast<std::uint64_t>(o.integer(seed_option()));
  return r;
}

class Ldi final : public Technique {
 public:
  explicit Ldi(ShapeOptions r)
      : shape_(std::move(r.shape)),
        mesh_file_(std::move(r.mesh_file)),
        shape_param_(r.shape_param),
        mesh_(std::move(r.mesh)),
        config_(r.config),
        points_(r.points),
        epsilon_(r.epsilon),
        seed_(r.seed) {}

  trace::Properties variant_properties() const override {
    trace::Properties p = {{"shape", shape_}};
    if (mesh_file_ != "none") p.emplace_back("mesh", mesh_file_);
    if (shape_param_ > 0) p.emplace_back("shape_param", std::to_string(shape_param_));
    return p;
  }
  trace::Properties setting_properties() const override {
    return {{"ldi_size", std::to_string(config_.size_texels)},
            {"grid", fmt::format("{}x{}", config_.grid_h, config_.grid_v)},
            {"max_layers", std::to_string(config_.max_layers)},
            {"points", std::to_string(points_)},
            {"epsilon", fmt::format("{}", epsilon_)},
            {"ldi_seed", std::to_string(seed_)},
            {"mesh_vertices", std::to_string(mesh_.vertices.size())},
            {"mesh_triangles", std::to_string(mesh_.triangles.size())},
            {"ldi_placement", "frame 0 unrotated, later frames a uniform random rotation from ldi_seed and the frame; then "
                              "normalize_to_unit_cube with margin 0"},
            {"ldi_depth", "peel: clip control ZERO_TO_ONE, gl_Position = (ndc x, ndc y, linear depth, 1), layer = gl_FragCoord.z, "
                          "LEQUAL against DEPTH_COMPONENT32F cleared to 1.0, strict > previous layer, no culling"},
            {"observer", "unused: the LDI technique builds no scene, follows no camera path and ignores --size and the projection"}};
  }

  CapturedFrame render(std::uint32_t index, const CameraPose&) override {
    CapturedFrame out;
    scene::Frame& f = out.frame;
    f.begin.frame = index;
    f.begin.mode = scene::TestMode::None;
    const std::array<double, 9> rot = random_rotation(seed_, index);
    mesh::TriMesh m = mesh_;
    for (mesh::Vec3f& p : m.vertices) {
      const double x = p[0], y = p[1], z = p[2];
      for (int i = 0; i < 3; ++i) p[i] = static_cast<float>(rot[i] * x + rot[3 + i] * y + rot[6 + i] * z);
    }
    mesh::normalize_to_unit_cube(m, 0.0);
    mesh::require_closed(m, fmt::format("frame {}: the {} after its rotation and fit into the unit cube", index, shape_));

    recorder_.begin_frame(static_cast<std::size_t>(config_.max_layers) + 1);
    LdiBuild b = build_ldi(m, config_, &recorder_);
    f.draws = recorder_.collect();
    for (std::size_t i = 0; i < b.peel.passes.size() && i < f.draws.size(); ++i) b.peel.passes[i].fragments = f.draws[i].gl.fragments;

    const LdiTestPoints pts = make_test_points(b.peel.ldi, b.crop.rect, points_, seed_ * 1000003ull + index);
    const auto t0 = std::chrono::steady_clock::now();
    const GlVptAnswers gl = gl_vpt(b, pts.x, pts.y, pts.z);
    // GL's time for the passes the model replays: the peel, crop, compression and both parity tests
    // (their textures' upload included); viewpoint selection (b.times.viewpoint_ms) is not replayed.
    f.end.gl_ms = b.times.peel_ms + b.times.crop_ms + b.times.compression_ms +
                  std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const mesh::CrossingReference ref(m, b.map.frame);
    std::vector<std::int32_t> reference = reference_crossings(ref, b.map, pts, epsilon_);

    const VptScore score = score_vpt(gl, reference);
    const std::uint64_t near = score.near_surface, wrong_layers = score.wrong_layers, wrong_ranges = score.wrong_ranges,
                        disagree = score.readers_disagree, fetch_layers = score.fetches_layers, fetch_ranges = score.fetches_ranges;
    std::uint64_t fragments = 0;
    for (const scene::DrawRecord& d : f.draws) fragments += d.gl.fragments;

    const auto& fr = b.map.frame;
    std::vector<float> view;
    for (const mesh::Vec3d* v : {&fr.direction, &fr.right, &fr.up})
      for (double c : *v) view.push_back(static_cast<float>(c));
    std::vector<float> rotation(rot.begin(), rot.end());
    const ldi::CompressedLdi& c = b.compressed;
    trace::TechniqueRecord image;
    image.type = trace::kLdiImageChunk;
    image.decoded = true;
    image.fields = {{"width", static_cast<std::uint64_t>(b.peel.ldi.width())},
                    {"height", static_cast<std::uint64_t>(b.peel.ldi.height())},
                    {"layer_count", static_cast<std::uint64_t>(b.peel.ldi.layer_count())},
                    {"grid_h", static_cast<std::uint64_t>(config_.grid_h)},
                    {"grid_v", static_cast<std::uint64_t>(config_.grid_v)},
                    {"direction", std::uint64_t{b.direction}},
                    {"view", std::move(view)},
                    {"rotation", std::move(rotation)},
                    {"candidate_d", b.candidate_d},
                    {"candidate_coverage", b.candidate_coverage},
                    {"layers", b.peel.ldi.depths()},
                    {"crop_x", std::int64_t{b.crop.rect.x}},
                    {"crop_y", std::int64_t{b.crop.rect.y}},
                    {"crop_w", std::int64_t{b.crop.rect.w}},
                    {"crop_h", std::int64_t{b.crop.rect.h}},
                    {"comp_side", static_cast<std::uint64_t>(c.side)},
                    {"comp_index", std::uint64_t{c.index_texels}},
                    {"comp_ranges", std::uint64_t{c.range_texels}},
                    {"compressed", c.texels}};
    f.technique_records.push_back(std::move(image));
    trace::TechniqueRecord tests;
    tests.type = trace::kLdiTestsChunk;
    tests.decoded = true;
    tests.fields = {{"count", static_cast<std::uint64_t>(pts.x.size())},
                    {"epsilon", epsilon_},
                    {"kind", pts.kind},
                    {"x", pts.x},
                    {"y", pts.y},
                    {"z", pts.z},
                    {"gl_inside_layers", gl.inside_layers},
                    {"gl_fetches_layers", gl.fetches_layers},
                    {"gl_inside_ranges", gl.inside_ranges},
                    {"gl_fetches_ranges", gl.fetches_ranges},
                    {"reference", std::move(reference)}};
    f.technique_records.push_back(std::move(tests));
    trace::TechniqueRecord all;
    all.type = trace::kLdiAllLayersChunk;
    all.decoded = true;
    all.fields = {{"count", static_cast<std::uint64_t>(pts.x.size())}, {"gl_inside_all", gl.inside_all}, {"gl_fetches_all", gl.fetches_all}};
    f.technique_records.push_back(std::move(all));
    out.counts = {{"ldi_layers", static_cast<std::uint64_t>(b.peel.ldi.layer_count())},
                  {"peel_passes", b.peel.passes.size()},
                  {"peel_fragments", fragments},
                  {"m_crop", c.m_crop()},
                  {"m_comp", c.m_comp()},
                  {"test_points", pts.x.size()},
                  {"near_surface_points", near},
                  {"misclassified_layers", wrong_layers},
                  {"misclassified_ranges", wrong_ranges},
                  {"readers_disagree", disagree},
                  {"fetches_layers", fetch_layers},
                  {"fetches_ranges", fetch_ranges},
                  {"fetches_all", std::accumulate(gl.fetches_all.begin(), gl.fetches_all.end(), std::uint64_t{0})}};
    f.end.frame = index;
    f.end.draws = static_cast<std::uint32_t>(f.draws.size());
    return out;
  }

 private:
  std::string shape_, mesh_file_;
  int shape_param_ = 0;
  mesh::TriMesh mesh_;
  LdiBuildConfig config_;
  int points_ = 0;
  double epsilon_ = 1e-5;
  std::uint64_t seed_ = 1;
  DrawRecorder recorder_;
};

}  // namespace

const std::vector<OptionSpec>& ldi_options() {
  static const std::vector<OptionSpec> options = [] {
    std::vector<OptionSpec> v = {shape_option(), shape_param_option(), mesh_option(),    ldi_size_option(), grid_option(),
                                 max_layers_option(), points_option(), epsilon_option(), seed_option()};
    for (const OptionSpec& a : ldi_application_options()) v.push_back(a);
    return v;
  }();
  return options;
}

BenchPreset ldi_bench_preset() {
  // The paper's clipping in the city (clip.h): every scene fragment runs the volume test, three knots
  // along the walk; --mode picks the reader (the paper's, every layer, by default).
  return {"city", "walk", "512x512", {{"application", "clip"}, {"shape", "knot"}, {"ldi-size", "128"}, {"reader", "all"}}, "reader", {}};
}

std::unique_ptr<Technique> make_ldi(const TechniqueSetup& setup) {
  const OptionValues& o = setup.options;
  ShapeOptions r = read_shape_options(o);
  if (!ldi_application_chosen(o)) {
    // (Checked against the defaults, not for presence: a recorded command line spells every option out.)
    for (const OptionSpec& a : ldi_application_options())
      if (a.name != "application" && o.text(a) != a.default_value)
        throw InputError(fmt::format("--{} is for --application clip or lens", a.name));
    return std::make_unique<Ldi>(std::move(r));
  }
  if (o.text(points_option()) != points_option().default_value)
    throw InputError("--points is for --application shape (clip and lens test every scene fragment)");
  return make_ldi_application(setup, {std::move(r.mesh), r.shape, r.config, r.epsilon});
}

// This technique's row of the capture's table (technique.h).
TechniqueRow ldi_technique() {
  return {{"ldi",
           "Layered depth images of a closed shape: viewpoint selection, depth peeling, crop, RG32UI depth-range compression and "
           "the volumetric parity test with three readers against an exact reference (Trapp & Doellner)",
           ldi_options()},
          make_ldi,
          ldi_bench_preset(),
          {},
          [](const OptionValues& o) {
            return ldi_application_chosen(o) ? std::string()
                                             : std::string("an LDI capture renders one shape from its own viewpoints (--application clip "
                                                           "or lens draws a scene)");
          }};
}

}  // namespace nbsim::capture

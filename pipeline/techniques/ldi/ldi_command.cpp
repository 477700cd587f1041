// `nbsim ldi table1`: the layered-depth-image paper's Table 1 (Trapp & Doellner 2008) reproduced on
// Mesa, with the volumetric parity test's misclassification beside it. Per shape and LDI side, on
// one headless GL context (traces/capture/ldi/build.h): viewpoint selection over the grid, the peel,
// the crop and the compression on GL, each timed (wall clock, glFinish-bounded); then the test
// points of the `ldi` capture, classified by GL's parity test with both readers and by the exact
// reference in double precision. One row per (shape, side): vertices, d_min/d_max over the grid's
// directions, the chosen direction's layers, M_crop and M_comp in the paper's units (32-bit values;
// M_comp = 2 w_c^2 counts both channels, as the paper does), C_ratio, the four times, and per
// reader the points misclassified and the texels a test read. Two references: the texel-centre
// one, on the capture's test points (the exact crossings along the point's texel-centre line:
// what GL's rasterization and depth precision get wrong), and "anywhere", on as many points
// uniform in the unit cube (each anywhere in its texel, its exact answer on its own line: the
// LDI's sampling error, which falls with the LDI's side). Writes OUT/ldi.json (a JSON list, the
// report's input) and OUT/ldi.csv; prints the table beside the paper's two rows we have.
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "model/ldi/vpt.h"
#include "model/mesh/mesh.h"
#include "model/mesh/shapes.h"
#include "pipeline/cli/command.h"
#include "pipeline/cli/progress.h"
#include "traces/capture/ldi/build.h"
#include "traces/capture/ldi/mesh_loader.h"
#include "traces/capture/ldi/test_points.h"
#include "traces/gl/context.h"
#include "io/output_folder.h"

namespace nbsim::cli {

namespace {

struct Table1Args {
  // The paper's six rows (by their stand-ins, kPaper) and two hard shapes of nbsim's.
  std::vector<std::string> shapes{"sphere", "beads:12", "beads:43", "beads:33", "knot", "beads:54", "nested:9", "coil:9"};
  std::vector<std::string> meshes;
  std::vector<int> sizes{1024};
  std::string grid = "8x8";
  int points = 4096;
  int max_layers = 64;
  double epsilon = 1e-5;
  std::uint64_t seed = 1;
  std::string out;
  bool json = false;
};

// The paper's Table 1 (Trapp & Doellner 2008, 1024x1024 LDIs, an 8x8 viewpoint grid), a row per
// shape with the project's stand-in for it: the sphere is the paper's (994 vertices); for the
// meshes nbsim does not have, a beads shape (model/mesh/shapes.h: K nested shells and M beads on a
// string) whose d_min and d_max over the grid's views are the paper's row's (d_min = 2K, d_max =
// 2(K + M)); the paper's Knot is our torus knot (its vertex count), its d range is Potato's (beads:33).
// Fixed by the paper.
struct PaperRow {
  const char* shape;  // the stand-in
  const char* label;  // the paper's shape
  int vertices, d_min, d_max;
  double m_crop, m_comp, c_ratio;
  const char* why;  // why this stand-in
};
constexpr PaperRow kPaper[] = {
    {"sphere", "Sphere", 994, 2, 2, 2097152, 3742848, 1.78, "the paper's UV sphere, 994 vertices"},
    {"beads:12", "Complex", 768, 2, 6, 2097152, 3011058, 1.44, "one shell and two beads: d 2 across, 6 along the string"},
    {"beads:43", "Cow", 2903, 8, 14, 3026688, 1204352, 0.39, "four shells and three beads: d 8 to 14"},
    {"beads:33", "Potato", 6146, 6, 12, 5683200, 3317888, 0.58, "three shells and three beads: d 6 to 12 (the Knot's range too)"},
    {"knot", "Knot", 23232, 6, 12, 3143880, 1835528, 0.58, "a torus-knot tube of about the paper's vertex count (23,040)"},
    {"beads:54", "Hebe", 34344, 10, 18, 3358720, 1089288, 0.32, "five shells and four beads: d 10 to 18"},
};

struct Shape {
  std::string name;
  mesh::TriMesh mesh;
};

// "name" or "name:parameter" of model/mesh/shapes.h's table.
Shape make_named(const std::string& spec) {
  const std::size_t colon = spec.find(':');
  std::optional<int> parameter;
  if (colon != std::string::npos) {
    const std::string p = spec.substr(colon + 1);
    std::size_t used = 0;
    int v = 0;
    try {
      v = std::stoi(p, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (p.empty() || used != p.size()) throw InputError(fmt::format("--shapes: '{}' is not NAME or NAME:INTEGER", spec));
    parameter = v;
  }
  Shape s{spec, mesh::make_shape(spec.substr(0, colon), parameter)};
  mesh::require_closed(s.mesh, fmt::format("--shapes {}", spec));
  return s;
}

std::pair<int, int> parse_grid(const std::string& text) {
  int h = 0, v = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &h, &x, &v, &extra) != 3 || x != 'x' || h < 1 || v < 1 || h > 1024 || v > 1024)
    throw InputError(fmt::format("--grid '{}' is not HxV with each of 1 to 1024 directions", text));
  return {h, v};
}

nlohmann::ordered_json measure(const Shape& shape, int size, const Table1Args& a, int grid_h, int grid_v) {
  mesh::TriMesh m = shape.mesh;
  mesh::normalize_to_unit_cube(m, 0.0);
  capture::LdiBuildConfig config;
  config.size_texels = size;
  config.grid_h = grid_h;
  config.grid_v = grid_v;
  config.max_layers = a.max_layers;
  const capture::LdiBuild b = capture::build_ldi(m, config);
  const capture::LdiTestPoints pts = capture::make_test_points(b.peel.ldi, b.crop.rect, a.points, a.seed);
  const capture::GlVptAnswers gl = capture::gl_vpt(b, pts.x, pts.y, pts.z);
  const mesh::CrossingReference ref(m, b.map.frame);
  const std::vector<std::int32_t> reference = capture::reference_crossings(ref, b.map, pts, a.epsilon);

  // The LDI's own error: --points more points uniform in the unit cube (a uniform texel, a uniform
  // offset in (-0.5, 0.5) texel in both directions, a uniform depth), each answered by GL's parity test
  // at its texel and by the exact crossings on its own line.
  std::mt19937_64 rng(a.seed ^ 0x9E3779B97F4A7C15ull);
  std::uniform_real_distribution<double> offset(-0.5, 0.5), depth(0.0, 1.0);
  std::uniform_int_distribution<int> tx(0, size - 1), ty(0, size - 1);
  const capture::OrthoMapping& map = b.map;
  std::vector<std::int32_t> ux(static_cast<std::size_t>(a.points)), uy(ux.size());
  std::vector<float> uz(ux.size());
  std::vector<mesh::Vec3d> where(ux.size());
  for (std::size_t p = 0; p < ux.size(); ++p) {
    ux[p] = tx(rng), uy[p] = ty(rng);
    const double ju = offset(rng) * (map.u1 - map.u0) / map.width, jv = offset(rng) * (map.v1 - map.v0) / map.height;
    uz[p] = static_cast<float>(depth(rng));
    mesh::Vec3d q = map.texel_line_point(ux[p], uy[p]);
    const double along = double(uz[p]) * (map.t1 - map.t0);
    for (int k = 0; k < 3; ++k) q[k] += ju * map.frame.right[k] + jv * map.frame.up[k] + along * map.frame.direction[k];
    where[p] = q;
  }
  const capture::GlVptAnswers uniform = capture::gl_vpt(b, ux, uy, uz);
  std::uint64_t near_anywhere = 0, wrong_anywhere = 0, inside_anywhere = 0, fetch_anywhere_layers = 0, fetch_anywhere_ranges = 0,
                fetch_anywhere_all = 0;
  for (std::size_t p = 0; p < ux.size(); ++p) {
    fetch_anywhere_layers += uniform.fetches_layers[p];
    fetch_anywhere_ranges += uniform.fetches_ranges[p];
    fetch_anywhere_all += uniform.fetches_all[p];
    const mesh::CrossingCount c = ref.count(where[p]);
    if (c.nearest_distance <= a.epsilon) {
      ++near_anywhere;
      continue;
    }
    inside_anywhere += c.beyond & 1u;
    wrong_anywhere += uniform.inside_layers[p] != (c.beyond & 1u) || uniform.inside_ranges[p] != (c.beyond & 1u) ||
                      uniform.inside_all[p] != (c.beyond & 1u);
  }

  // The model's parity test (model/ldi/vpt.h) on GL's LDI and GL's compressed texture, against GL's answers
  // and fetch counts, on every point of both sets.
  const ldi::CroppedLdi cropped = ldi::crop(b.peel.ldi);
  std::uint64_t model_mismatches = 0, readers_differ = 0;
  const auto check = [&](const std::vector<std::int32_t>& x, const std::vector<std::int32_t>& y, const std::vector<float>& z,
                         const capture::GlVptAnswers& g) {
    for (std::size_t p = 0; p < x.size(); ++p) {
      const ldi::VptResult l = ldi::vpt_layers(cropped, x[p], y[p], z[p]), c = ldi::vpt_ranges(b.compressed, x[p], y[p], z[p]),
                           all = ldi::vpt_all_layers(cropped, x[p], y[p], z[p]);
      model_mismatches += (l.inside ? 1u : 0u) != g.inside_layers[p] || static_cast<std::uint32_t>(l.fetches) != g.fetches_layers[p] ||
                          (c.inside ? 1u : 0u) != g.inside_ranges[p] || static_cast<std::uint32_t>(c.fetches) != g.fetches_ranges[p] ||
                          (all.inside ? 1u : 0u) != g.inside_all[p] || static_cast<std::uint32_t>(all.fetches) != g.fetches_all[p];
      readers_differ += l.inside != c.inside || l.inside != all.inside ? 1 : 0;
    }
  };
  check(pts.x, pts.y, pts.z, gl);
  check(ux, uy, uz, uniform);

  const capture::VptScore score = capture::score_vpt(gl, reference);
  const std::uint64_t near = score.near_surface, wrong_layers = score.wrong_layers, wrong_ranges = score.wrong_ranges,
                      fetch_layers = score.fetches_layers, fetch_ranges = score.fetches_ranges, disagree = score.readers_disagree;
  std::uint32_t d_min = 0, d_max = 0;
  for (std::size_t i = 0; i < b.candidate_d.size(); ++i) {
    d_min = i == 0 ? b.candidate_d[i] : std::min(d_min, b.candidate_d[i]);
    d_max = std::max(d_max, b.candidate_d[i]);
  }
  const std::size_t n = reference.size();
  nlohmann::ordered_json r;
  r["shape"] = shape.name;
  r["ldi_size"] = size;
  r["grid"] = fmt::format("{}x{}", grid_h, grid_v);
  r["vertices"] = shape.mesh.vertices.size();
  r["triangles"] = shape.mesh.triangles.size();
  r["d_min"] = d_min;
  r["d_max"] = d_max;
  r["direction"] = b.direction;
  r["layers"] = b.peel.ldi.layer_count();
  r["crop_w"] = b.crop.rect.w;
  r["crop_h"] = b.crop.rect.h;
  r["m_crop"] = b.compressed.m_crop();
  r["m_comp"] = b.compressed.m_comp();
  const std::optional<double> ratio = b.compressed.c_ratio();
  r["c_ratio"] = ratio ? nlohmann::ordered_json(*ratio) : nlohmann::ordered_json(nullptr);
  r["paper_c_ratio"] = nullptr;
  for (const PaperRow& p : kPaper)
    if (shape.name == p.shape) {
      r["paper_c_ratio"] = p.c_ratio, r["paper_row"] = p.label;
      r["paper_vertices"] = p.vertices, r["paper_d_min"] = p.d_min, r["paper_d_max"] = p.d_max;
      r["paper_m_crop"] = p.m_crop, r["paper_m_comp"] = p.m_comp, r["paper_stand_in"] = p.why;
    }
  r["ms_viewpoint"] = b.times.viewpoint_ms;
  r["ms_peel"] = b.times.peel_ms;
  r["ms_crop"] = b.times.crop_ms;
  r["ms_compress"] = b.times.compression_ms;
  r["peel_passes"] = b.peel.passes.size();
  r["points"] = n;
  r["epsilon"] = a.epsilon;
  r["near_surface"] = near;
  r["classified"] = n - near;
  r["misclassified_layers"] = wrong_layers;
  r["misclassified_ranges"] = wrong_ranges;
  r["readers_disagree"] = disagree;
  r["gl_parity_mismatches"] = model_mismatches;
  r["uniform_points"] = ux.size();
  r["classified_anywhere"] = ux.size() - near_anywhere;
  r["inside_anywhere"] = inside_anywhere;
  r["misclassified_anywhere"] = wrong_anywhere;
  const double un = ux.empty() ? 1.0 : static_cast<double>(ux.size());
  r["fetches_anywhere_layers"] = static_cast<double>(fetch_anywhere_layers) / un;
  r["fetches_anywhere_ranges"] = static_cast<double>(fetch_anywhere_ranges) / un;
  r["fetches_anywhere_all"] = static_cast<double>(fetch_anywhere_all) / un;
  // The three readers' answers on every point of both sets (the model's, which equal GL's when
  // gl_parity_mismatches is 0): the same rule read three ways, so 0.
  r["readers_differ"] = readers_differ;
  r["fetches_per_test_layers"] = n ? static_cast<double>(fetch_layers) / static_cast<double>(n) : 0.0;
  r["fetches_per_test_ranges"] = n ? static_cast<double>(fetch_ranges) / static_cast<double>(n) : 0.0;
  std::uint64_t fetch_all = 0;
  for (const std::uint32_t f : gl.fetches_all) fetch_all += f;
  r["fetches_per_test_all"] = n ? static_cast<double>(fetch_all) / static_cast<double>(n) : 0.0;
  return r;
}

std::string cell(const nlohmann::ordered_json& v, int decimals) {
  if (v.is_null()) return "-";
  return fmt::format("{:.{}f}", v.get<double>(), decimals);
}

int run_table1(const Table1Args& a) {
  const auto [grid_h, grid_v] = parse_grid(a.grid);
  if (a.points < 0) throw InputError("--points must be 0 or more");
  if (!(a.epsilon >= 0.0 && a.epsilon < 1.0)) throw InputError(fmt::format("--epsilon {} is not in [0, 1)", a.epsilon));
  for (int s : a.sizes)
    if (s < 1 || s > 16384) throw InputError(fmt::format("--sizes: {} is not an LDI side of 1 to 16384 texels", s));
  // Every shape is made (and its file loaded and checked) before any GL work or output.
  std::vector<Shape> shapes;
  for (const std::string& s : a.shapes) shapes.push_back(make_named(s));
  for (const std::string& f : a.meshes) {
    Shape s{"mesh:" + std::filesystem::path(f).filename().string(), capture::load_mesh(f)};
    mesh::require_closed(s.mesh, fmt::format("--mesh '{}'", f));
    shapes.push_back(std::move(s));
  }
  if (shapes.empty()) throw InputError("no shape: give --shapes or --mesh");
  std::filesystem::path dir;
  if (!a.out.empty()) {
    dir = a.out;
    io::create_output_folder(dir);
  }

  gl::Context context;
  {  // warm-up: the first build in a process compiles every shader; its times would not be the stages'
    mesh::TriMesh warm = mesh::make_shape("sphere");
    mesh::normalize_to_unit_cube(warm, 0.0);
    (void)capture::build_ldi(warm, {.size_texels = 16, .grid_h = 2, .grid_v = 2, .max_layers = 4});
  }
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  ProgressBar progress("ldi table1", static_cast<long long>(shapes.size() * a.sizes.size()));
  for (const Shape& s : shapes)
    for (int size : a.sizes) {
      rows.push_back(measure(s, size, a, grid_h, grid_v));
      progress.update(static_cast<long long>(rows.size()));
    }
  progress.finish();

  if (a.json) {
    fmt::print("{}\n", rows.dump(2));
  } else {
    fmt::print("Table 1 (Trapp & Doellner 2008) on Mesa {}, grid {}: memory in 32-bit values (M_comp = 2 w_c^2), times in ms "
               "on llvmpipe (a warm-up build first); misclass.: of the points not within {} of a surface (texel-centre reference; anywhere: the point anywhere in its texel); fetch L / R: "
               "texels a parity test read, layers (early exit) / compressed / every layer (the paper's reader)\n",
               context.info().renderer, a.grid, a.epsilon);
    fmt::print("{:<12} {:>5} {:>8} {:>9} {:>6} {:>11} {:>11} {:>7} {:>6} {:>9} {:>8} {:>7} {:>9} {:>9} {:>9} {:>9} {:>11} {:>9}\n", "shape",
               "side", "vertices", "d_min/max", "d", "M_crop", "M_comp", "C_ratio", "paper", "viewpoint", "peel", "crop", "compress",
               "misclass.", "anywhere", "fetch L", "fetch R", "fetch P");
    // misclass.: the uncompressed reader's (the compressed one's is the same, or the command fails below);
    // fetch L / R: texels a test read, uncompressed layers / compressed texture
    for (const auto& r : rows)
      fmt::print("{:<12} {:>5} {:>8} {:>9} {:>6} {:>11} {:>11} {:>7} {:>6} {:>9.1f} {:>8.1f} {:>7.2f} {:>9.2f} {:>8.3f}% {:>8.3f}% {:>9.2f} {:>11.2f} "
                 "{:>9.2f}\n",
                 r["shape"].get<std::string>(), r["ldi_size"].get<int>(), r["vertices"].get<std::size_t>(),
                 fmt::format("{}/{}", r["d_min"].get<unsigned>(), r["d_max"].get<unsigned>()), r["layers"].get<int>(),
                 r["m_crop"].get<std::uint64_t>(), r["m_comp"].get<std::uint64_t>(), cell(r["c_ratio"], 3), cell(r["paper_c_ratio"], 2),
                 r["ms_viewpoint"].get<double>(), r["ms_peel"].get<double>(), r["ms_crop"].get<double>(), r["ms_compress"].get<double>(),
                 r["classified"].get<std::uint64_t>() ? 100.0 * r["misclassified_layers"].get<double>() / r["classified"].get<double>() : 0.0,
                 r["classified_anywhere"].get<std::uint64_t>()
                     ? 100.0 * r["misclassified_anywhere"].get<double>() / r["classified_anywhere"].get<double>()
                     : 0.0,
                 r["fetches_per_test_layers"].get<double>(), r["fetches_per_test_ranges"].get<double>(),
                 r["fetches_per_test_all"].get<double>());
  }
  if (!dir.empty()) {
    const std::filesystem::path json = dir / "ldi.json", csv = dir / "ldi.csv";
    {
      std::ofstream f(json.string() + ".part");
      f << rows.dump(2) << "\n";
      if (!f) throw InputError(fmt::format("cannot write '{}'", json.string()));
    }
    std::filesystem::rename(json.string() + ".part", json);
    std::ofstream c(csv);
    bool header = true;
    for (const auto& r : rows) {
      std::string keys, values;
      for (const auto& [k, v] : r.items()) {
        keys += (keys.empty() ? "" : ",") + k;
        values += (values.empty() ? "" : ",") + (v.is_string() ? v.get<std::string>() : v.is_null() ? std::string() : v.dump());
      }
      if (header) c << keys << "\n", header = false;
      c << values << "\n";
    }
    if (!c) throw InputError(fmt::format("cannot write '{}'", csv.string()));
  }
  // Compression is lossless, so both readers must give the same answers, and the model's parity test is
  // GL's: a disagreement anywhere is a failure.
  int status = 0;
  for (const auto& r : rows) {
    if (r["readers_disagree"].get<std::uint64_t>() != 0) {
      fmt::print(stderr, "ldi table1: {} at {}: the compressed and uncompressed parity tests disagree on {} points\n",
                 r["shape"].get<std::string>(), r["ldi_size"].get<int>(), r["readers_disagree"].get<std::uint64_t>());
      status = 1;
    }
    if (r["gl_parity_mismatches"].get<std::uint64_t>() != 0) {
      fmt::print(stderr, "ldi table1: {} at {}: the model's parity test differs from GL's (answer or fetches) on {} points\n",
                 r["shape"].get<std::string>(), r["ldi_size"].get<int>(), r["gl_parity_mismatches"].get<std::uint64_t>());
      status = 1;
    }
  }
  return status;
}

}  // namespace

void add_ldi_commands(CLI::App& app, Action& action) {
  auto* ldi = app.add_subcommand("ldi", "Layered depth images (Trapp & Doellner): Table 1 and the parity test's accuracy on Mesa");
  ldi->require_subcommand(1);
  auto a = std::make_shared<Table1Args>();
  auto* t = ldi->add_subcommand(
      "table1", "Table 1 on llvmpipe: viewpoint selection, peel, crop and compression per shape and LDI side, and the parity "
                "test's misclassification against the exact reference");
  t->add_option("--shapes", a->shapes, "Procedural shapes, NAME or NAME:PARAMETER (model/mesh/shapes.h: sphere, knot, nested:K, coil:T)")
      ->delimiter(',')
      ->capture_default_str();
  t->add_option("--mesh", a->meshes, "A closed mesh file (any format assimp reads); repeat for more");
  t->add_option("--sizes", a->sizes, "LDI sides, texels (comma-separated)")->delimiter(',')->capture_default_str();
  t->add_option("--grid", a->grid, "Viewpoint grid s_H x s_V")->capture_default_str();
  t->add_option("--points", a->points, "Test points per shape and side")->check(CLI::Range(0, 1 << 24))->capture_default_str();
  t->add_option("--max-layers", a->max_layers, "Most layers a peel may find (a deeper shape is refused)")
      ->check(CLI::Range(1, 2048))
      ->capture_default_str();
  t->add_option("--epsilon", a->epsilon, "Near-surface distance of the exact reference, unit-cube units")->capture_default_str();
  t->add_option("--seed", a->seed, "Seed of the test points")->capture_default_str();
  t->add_option("--out", a->out, "Folder for ldi.json (the report's input) and ldi.csv");
  t->add_flag("--json", a->json, "Print the rows as JSON instead of the text table");
  t->footer(
      "Exit status: 0; 1 when the compressed and uncompressed parity tests disagree anywhere (compression is lossless),\n"
      "or the model's parity test (model/ldi/vpt.h) on GL's LDI differs from GL's in an answer or a fetch count;\n"
      "2 for bad arguments, a shape or mesh that is not closed, or an LDI deeper than --max-layers.\n"
      "The paper's rows beside ours: Sphere (994 vertices, d = 2, C_ratio 1.78) on sphere, Hebe (d up to 18, 0.32) on nested:9.");
  t->callback([&action, a] { action = [a] { return run_table1(*a); }; });
}

}  // namespace nbsim::cli

// `nbsim nbuffer query|build|coverage`: the N-buffer core from the command line.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <numeric>
#include <vector>

#include "model/common/error.h"
#include "model/common/names.h"
#include "model/nbuffer/nbuffer.h"
#include "pipeline/cli/command.h"
#include "io/image_io.h"
#include "pipeline/scenes/demo_scene.h"
#include "io/output_folder.h"

namespace nbsim::cli {

namespace {

namespace fs = std::filesystem;
using ojson = nlohmann::ordered_json;

// Tunable. Largest side of the built-in scene (query and build): a full N-buffer of WxH has
// ceil(log2(max(W, H))) float levels of W x H, so 4096x4096 holds 12 x 64 MiB = 768 MiB (Table 1's
// largest size is 1024x1024).
constexpr int kMaxSceneSide = 4096;
// Tunable. Largest box side of `coverage` (each box size is one CSV row: 4096x4096 is 16.7 M rows,
// about 0.6 GB of CSV) and the most pixels of its image (64 M pixels: 192 MiB of RGB).
constexpr int kMaxCoverageSide = 4096;
constexpr long long kMaxCoveragePixels = 64LL << 20;

// Where the depth comes from: a file, or the built-in scene.
struct DepthSource {
  std::string file;
  std::string scene;
  std::string size = "512x512";
  unsigned seed = 1;

  void add_options(CLI::App* cmd) {
    auto* f = cmd->add_option("--depth", file, "Single-channel float depth image (EXR, TIFF, PFM, ...), values in [0,1], y up");
    auto* s = cmd->add_option("--scene", scene, "Built-in depth scene instead of a file")->check(CLI::IsMember({"city"}));
    f->excludes(s);
    cmd->add_option("--size", size, fmt::format("Size of the built-in scene, WxH, each side at most {}", kMaxSceneSide))
        ->capture_default_str();
    cmd->add_option("--seed", seed, "Seed of the built-in scene")->capture_default_str();
  }

  DepthImage load() const {
    if (!file.empty()) return io::read_depth(file);
    if (scene.empty()) throw InputError("no depth given: pass --depth FILE or --scene city");
    const auto [w, h] = parse_size(size, "--size");
    if (w > kMaxSceneSide || h > kMaxSceneSide)
      throw InputError(fmt::format("--size {} is too large: the built-in scene is at most {}x{}", size, kMaxSceneSide, kMaxSceneSide));
    return scenes::city_depth(w, h, seed);
  }
};

// N-buffer options shared by query and build.
struct NBufferOptions {
  std::string op = "max";
  std::string format = "f32";
  int max_level = -1;
  std::string levels = "square";
  int max_aspect_log2 = -1;

  void add_options(CLI::App* cmd) {
    cmd->add_option("--op", op, "Farthest is max (depth func LESS) or min (reversed Z, min-litmaps)")
        ->check(CLI::IsMember(name_list(kFarOpNames)))
        ->capture_default_str();
    cmd->add_option("--format", format, "Level storage: f32, u24 or u16 unorm (rounded toward far)")
        ->check(CLI::IsMember(name_list(kStorageFormatNames)))
        ->capture_default_str();
    cmd->add_option("--max-level", max_level, "Build levels 0..K only (partial build, square levels); -1 builds all")
        ->check(CLI::Range(-1, 30))
        ->capture_default_str();
    cmd->add_option("--levels", levels,
                    "square: 2^i x 2^i neighbourhoods (the paper's); rect: 2^i x 2^j (the paper's future work, every "
                    "rectangle exact in at most four lookups)")
        ->check(CLI::IsMember(name_list(kLevelShapeNames)))
        ->capture_default_str();
    cmd->add_option("--max-aspect-log2", max_aspect_log2, "--levels rect: only levels whose sides differ by at most 2^K; -1 all")
        ->check(CLI::Range(-1, 14))
        ->capture_default_str();
  }

  NBufferConfig config() const {
    return {op == "max" ? FarOp::Max : FarOp::Min, *parse_storage_format(format), max_level,
            *parse_enum_name<LevelShape>(kLevelShapeNames, levels), max_aspect_log2};
  }
};

int run_query(const DepthSource& src, const NBufferOptions& nbo, const CoveringSpec& covering,
              const std::vector<std::string>& rect_texts) {
  std::vector<Rect> rects;
  for (const auto& t : rect_texts) rects.push_back(parse_rect(t));
  const DepthImage depth = src.load();
  const NBuffer nb(depth, nbo.config());
  for (const Rect& r : rects)  // refuse before printing anything, so no answer is half-written
    if (clip(r, nb.width(), nb.height()).empty())
      throw InputError(fmt::format("rectangle {},{},{},{} lies outside the {}x{} image", r.x, r.y, r.w, r.h,
                                   nb.width(), nb.height()));
  for (const Rect& r : rects) {
    const QueryResult q = nb.query(r, covering);
    ojson texels = ojson::array();
    for (const Texel& t : q.read()) texels.push_back({t.x, t.y});
    const Rect c = clip(r, nb.width(), nb.height());
    ojson line;
    line["rect"] = {r.x, r.y, r.w, r.h};
    line["covering"] = nb.has_rect_levels() ? "rect/" + std::string(to_string(covering.align)) : covering_name(covering);
    line["level"] = q.level;
    const auto [ei, ej] = nb.level_exponents(q.level);
    line["neighbourhood"] = fmt::format("{}x{}", 1 << ei, 1 << ej);
    line["texels"] = texels;
    line["value"] = tidy(q.value);
    line["case"] = to_string(covering_case(c.w, c.h));
    line["complete"] = q.complete;
    fmt::print("{}\n", line.dump());
  }
  return 0;
}

// `nbuffer memory`: the level count and bytes of an N-buffer, computed (nothing is allocated).
int run_memory(const std::string& size, const NBufferOptions& nbo) {
  const auto [w, h] = parse_size(size, "--size");
  const NBufferConfig c = nbo.config();
  if (c.shape == LevelShape::Rect && c.max_aspect_log2 == 0)
    throw InputError("--max-aspect-log2 0 would be the square levels: give -1 or at least 1, or --levels square");
  std::vector<std::string> labels;
  if (c.shape == LevelShape::Rect) {
    for (const auto& [i, j] : rect_levels(w, h, c.max_aspect_log2)) labels.push_back(fmt::format("{}x{}", 1 << i, 1 << j));
  } else {
    const int full = nbuffer_level_count(w, h);
    const int n = c.max_level < 0 ? full : std::min(c.max_level, full - 1) + 1;
    for (int i = 0; i < n; ++i) labels.push_back(std::to_string(i));
  }
  const long long pixels = static_cast<long long>(w) * h, n = static_cast<long long>(labels.size());
  ojson line;
  line["size"] = fmt::format("{}x{}", w, h);
  line["levels"] = nbo.levels;
  line["max_aspect_log2"] = c.shape == LevelShape::Rect ? ojson(c.max_aspect_log2) : ojson(nullptr);
  line["format"] = nbo.format;
  line["level_count"] = n;
  line["level_labels"] = labels;
  line["storage_bytes"] = n * pixels * nbsim::storage_bytes(c.format);
  line["memory_bytes"] = n * pixels * 4;
  line["within_limit"] = n * pixels * 4 <= kMaxNBufferBytes;
  fmt::print("{}\n", line.dump());
  return 0;
}

int run_build(const DepthSource& src, const NBufferOptions& nbo, const fs::path& out) {
  const DepthImage depth = src.load();
  const NBuffer nb(depth, nbo.config());
  io::create_output_folder(out, "output directory");
  // One grey ramp for every level (level 0's range), so the levels can be compared by eye.
  const auto [lo, hi] = std::minmax_element(depth.texels.begin(), depth.texels.end());
  ojson levels = ojson::array();
  for (int i = 0; i < nb.level_count(); ++i) {
    const DepthImage level = nb.level_image(i);
    const std::string stem = fmt::format("level_{:02d}", i);
    io::write_depth(level, out / (stem + ".exr"));
    io::write_preview(level, out / (stem + ".png"), *lo, *hi);
    const auto [llo, lhi] = std::minmax_element(level.texels.begin(), level.texels.end());
    const auto [ei, ej] = nb.level_exponents(i);
    levels.push_back({{"level", i}, {"label", nb.level_label(i)}, {"width", 1 << ei}, {"height", 1 << ej}, {"min", tidy(*llo)}, {"max", tidy(*lhi)},
                      {"exr", stem + ".exr"}, {"png", stem + ".png"}});
  }
  ojson summary;
  summary["size"] = fmt::format("{}x{}", nb.width(), nb.height());
  summary["op"] = nbo.op;
  summary["format"] = nbo.format;
  summary["levels_full"] = nb.full_level_count();
  summary["levels_built"] = nb.level_count();
  summary["storage_bytes"] = nb.storage_bytes();
  summary["levels"] = levels;
  std::ofstream(out / "levels.json") << summary.dump(2) << "\n";
  fmt::print("wrote {} levels of a {}x{} N-buffer ({} {}, {:.1f} MiB) to {}\n", nb.level_count(), nb.width(),
             nb.height(), nbo.op, nbo.format, static_cast<double>(nb.storage_bytes()) / (1 << 20), out.string());
  return 0;
}

// Viridis, sampled at five points and interpolated: perceptually ordered and colour-blind safe.
std::array<std::uint8_t, 3> colour(double t) {
  static constexpr double stops[5][3] = {{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
  t = std::clamp(t, 0.0, 1.0) * 4.0;
  const int i = std::min(static_cast<int>(t), 3);
  const double f = t - i;
  std::array<std::uint8_t, 3> c{};
  for (int k = 0; k < 3; ++k) c[k] = static_cast<std::uint8_t>(std::lround(stops[i][k] + f * (stops[i + 1][k] - stops[i][k])));
  return c;
}

// A covering measured by `coverage`: its name in the CSV and on the image, and, for a w x h box
// at the origin, the level it reads, its lookups and the pixels it reads beyond the box.
struct CoverageVariant {
  std::string name;
  std::string title;
  std::function<Covering(const Rect&)> cover;
};

std::vector<CoverageVariant> coverage_variants() {
  // Box sizes never exceed the image, so no covering clamps: an unbounded top level.
  constexpr int top = 30;
  return {
      {"paper", "the paper's five cases (at most 4 lookups)", [](const Rect& r) { return cover(r, {CoveringKind::Paper}, top); }},
      {"corners", "corner squares of side 2^floor(log2 max) (at most 4)",
       [](const Rect& r) { return cover(r, {CoveringKind::Corners}, top); }},
      {"one", "one square (1 lookup)", [](const Rect& r) { return cover(r, {CoveringKind::One}, top); }},
      {"rect", "rectangle levels, every one (at most 4, exact)", [](const Rect& r) { return cover_rect(r, top, top, -1, CoveringAlign::Top); }},
      {"rect_aspect1", "rectangle levels with sides at most 2x apart (at most 4)",
       [](const Rect& r) { return cover_rect(r, top, top, 1, CoveringAlign::Top); }},
  };
}

int run_coverage(const std::string& size, const fs::path& png, fs::path csv, int scale) {
  const auto [bw, bh] = parse_size(size, "--size");
  if (bw > kMaxCoverageSide || bh > kMaxCoverageSide)
    throw InputError(fmt::format("--size {} is too large: at most {}x{} box sizes", size, kMaxCoverageSide, kMaxCoverageSide));
  const std::vector<CoverageVariant> variants = coverage_variants();
  const int panels = static_cast<int>(variants.size());
  // The image's size, checked before anything is written: a panel of (box sizes x scale) pixels per
  // variant, gaps and a colour ramp.
  if (scale < 1) scale = std::max(1, 512 / std::max(bw, bh));
  const int gap = 8 * scale, pw = bw * scale, ph = bh * scale, ramp = std::max(12, ph / 16);
  const long long iw_ll = static_cast<long long>(panels) * pw + static_cast<long long>(panels - 1) * gap;
  const long long ih_ll = static_cast<long long>(ph) + gap + ramp;
  if (iw_ll * ih_ll > kMaxCoveragePixels)
    throw InputError(fmt::format("--size {} with --scale {} makes a {}x{} image: at most {} M pixels (lower --scale)", size, scale,
                                 iw_ll, ih_ll, kMaxCoveragePixels >> 20));
  const int iw = static_cast<int>(iw_ll), ih = static_cast<int>(ih_ll);
  if (csv.empty()) csv = fs::path(png).replace_extension(".csv");
  for (const fs::path& f : {fs::path(png), csv})
    if (f.has_parent_path()) io::create_output_folder(f.parent_path());
  const std::size_t n = static_cast<std::size_t>(bw) * static_cast<std::size_t>(bh);
  std::vector<std::vector<double>> ratio(variants.size());
  for (auto& r : ratio) r.reserve(n);
  // Per case of Fig. 3: boxes, and per variant the sum of extra / area and the boxes read exactly.
  std::array<long long, kCoveringCaseNames.size()> boxes{};
  std::vector<std::array<double, kCoveringCaseNames.size()>> case_extra(variants.size());
  std::vector<long long> exact(variants.size(), 0), lookups(variants.size(), 0);
  std::ofstream out(csv);
  if (!out) throw InputError(fmt::format("cannot write '{}'", csv.string()));
  out << "w,h,area,case";
  for (const CoverageVariant& v : variants) out << fmt::format(",{0}_level,{0}_lookups,{0}_extra_px", v.name);
  out << "\n";
  for (int h = 1; h <= bh; ++h) {
    for (int w = 1; w <= bw; ++w) {
      const Rect r{0, 0, w, h};
      const auto kase = static_cast<std::size_t>(covering_case(w, h));
      ++boxes[kase];
      out << fmt::format("{},{},{},{}", w, h, r.area(), kCoveringCaseNames[kase]);
      for (std::size_t i = 0; i < variants.size(); ++i) {
        const Covering c = variants[i].cover(r);
        const long long extra = covered_area(c) - r.area();
        const double rel = static_cast<double>(extra) / static_cast<double>(r.area());
        ratio[i].push_back(rel);
        case_extra[i][kase] += rel;
        exact[i] += extra == 0;
        lookups[i] += c.count;
        out << fmt::format(",{},{},{}", c.level, c.count, extra);
      }
      out << "\n";
    }
  }
  if (!out.flush()) throw InputError(fmt::format("cannot write '{}'", csv.string()));

  // One panel per variant, x = box width, y = box height (y up), then a colour ramp. Colour =
  // log2(1 + extra / area), scaled by the largest value of every panel.
  double vmax = 0.0;
  for (const auto& r : ratio) vmax = std::max(vmax, std::log2(1.0 + *std::max_element(r.begin(), r.end())));
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(iw) * static_cast<std::size_t>(ih) * 3, 255);
  auto put = [&](int x, int y, std::array<std::uint8_t, 3> c) {
    std::copy(c.begin(), c.end(), rgb.begin() + 3 * (static_cast<std::ptrdiff_t>(y) * iw + x));
  };
  for (int p = 0; p < panels; ++p)
    for (int y = 0; y < ph; ++y)
      for (int x = 0; x < pw; ++x) {
        const std::size_t k = static_cast<std::size_t>(y / scale) * static_cast<std::size_t>(bw) + static_cast<std::size_t>(x / scale);
        put(p * (pw + gap) + x, ramp + gap + y,
            colour(vmax > 0 ? std::log2(1.0 + ratio[static_cast<std::size_t>(p)][k]) / vmax : 0.0));
      }
  for (int y = 0; y < ramp; ++y)
    for (int x = 0; x < iw; ++x) put(x, y, colour(static_cast<double>(x) / std::max(1, iw - 1)));
  io::write_rgb8(iw, ih, rgb, png);

  const double count = static_cast<double>(n);
  fmt::print("coverage of every box size from 1x1 to {}x{} ({} sizes)\n", bw, bh, n);
  for (std::size_t i = 0; i < variants.size(); ++i) {
    const double mean = std::accumulate(ratio[i].begin(), ratio[i].end(), 0.0) / count;
    fmt::print("  {:<12} mean extra {:7.1f}% of the box, worst {:.1f}x the box, exact for {:5.1f}% of sizes, {:.2f} lookups a box  "
               "({})\n",
               variants[i].name, 100 * mean, *std::max_element(ratio[i].begin(), ratio[i].end()),
               100.0 * static_cast<double>(exact[i]) / count, static_cast<double>(lookups[i]) / count, variants[i].title);
  }
  fmt::print("  the cases of Fig. 3 (share of box sizes; mean extra area of each covering in that case):\n");
  for (std::size_t c = 0; c < boxes.size(); ++c) {
    fmt::print("    {:<17} {:5.1f}%", kCoveringCaseNames[c], 100.0 * static_cast<double>(boxes[c]) / count);
    for (std::size_t i = 0; i < variants.size(); ++i)
      fmt::print("  {} {:6.1f}%", variants[i].name,
                 boxes[c] ? 100.0 * case_extra[i][c] / static_cast<double>(boxes[c]) : 0.0);
    fmt::print("\n");
  }
  std::string order;
  for (const CoverageVariant& v : variants) order += (order.empty() ? "" : " | ") + v.name;
  fmt::print("  wrote {} (panels, left to right: {}; x = width, y = height, colour = log2(1 + extra/area) up to {:.2f})\n",
             png.string(), order, vmax);
  fmt::print("  wrote {}\n", csv.string());
  return 0;
}

}  // namespace

void add_nbuffer_commands(CLI::App& app, Action& action) {
  auto* nb = app.add_subcommand("nbuffer", "N-buffer core: query rectangles, build levels, coverage map (Fig. 4)");
  nb->require_subcommand(1);

  {
    auto* cmd = nb->add_subcommand("query", "Answer rectangles with a covering of at most four squares (Fig. 3); one JSON line each");
    auto src = std::make_shared<DepthSource>();
    auto nbo = std::make_shared<NBufferOptions>();
    auto covering = std::make_shared<std::string>("paper");
    auto align = std::make_shared<std::string>("top");
    auto rects = std::make_shared<std::vector<std::string>>();
    src->add_options(cmd);
    nbo->add_options(cmd);
    cmd->add_option("--covering", *covering,
                    "paper: the paper's five cases (Fig. 3); corners: squares of side 2^floor(log2 max(w,h)) at the corners; "
                    "one: a single square")
        ->check(CLI::IsMember(name_list(kCoveringKindNames)))
        ->capture_default_str();
    cmd->add_option("--align", *align, "Squares taller than the rectangle are flush with its top (the paper's) or its bottom")
        ->check(CLI::IsMember(name_list(kCoveringAlignNames)))
        ->capture_default_str();
    cmd->add_option("--rect", *rects, "Rectangle X,Y,W,H in pixels, y up (repeatable)")->required()->allow_extra_args(false);
    cmd->footer("Prints {\"rect\":[x,y,w,h],\"covering\":\"paper/top\",\"level\":i,\"neighbourhood\":\"WxH\",\"texels\":[[x,y],...],\n"
                "\"value\":v,\"case\":c,\"complete\":b} per rectangle (neighbourhood: the pixels each texel read holds, 2^i x 2^i,\n"
                "or 2^i x 2^j with --levels rect); case is the rectangle's case of Fig. 3 (four_quadrants, two_side_by_side,\n"
                "two_stacked, four_in_a_row, four_in_a_column). Rectangles partly outside the image are clipped; empty or fully\n"
                "outside ones are refused (exit 2).");
    cmd->callback([&action, src, nbo, covering, align, rects] {
      action = [=] {
        return run_query(*src, *nbo, {*parse_covering_kind(*covering), *parse_covering_align(*align)}, *rects);
      };
    });
  }
  {
    auto* cmd = nb->add_subcommand("build", "Build every level and write each as EXR plus a PNG preview");
    auto src = std::make_shared<DepthSource>();
    auto nbo = std::make_shared<NBufferOptions>();
    auto out = std::make_shared<std::string>();
    src->add_options(cmd);
    nbo->add_options(cmd);
    cmd->add_option("--out", *out, "Output directory (level_NN.exr, level_NN.png, levels.json)")->required();
    cmd->callback([&action, src, nbo, out] { action = [=] { return run_build(*src, *nbo, *out); }; });
  }
  {
    auto* cmd = nb->add_subcommand("memory", "The levels an N-buffer of a size has and the memory they take, without building it");
    auto size = std::make_shared<std::string>("512x512");
    auto nbo = std::make_shared<NBufferOptions>();
    cmd->add_option("--size", *size, "Image size, WxH")->capture_default_str();
    nbo->add_options(cmd);
    cmd->footer("Prints {\"size\":\"WxH\",\"levels\":\"square|rect\",\"max_aspect_log2\":k,\"format\":f,\"level_count\":n,\n"
                "\"level_labels\":[...],\"storage_bytes\":b,\"memory_bytes\":m,\"within_limit\":bool}: storage_bytes in the\n"
                "storage format, memory_bytes as the model holds them (floats); above the limit the model refuses the N-buffer.");
    cmd->callback([&action, size, nbo] { action = [=] { return run_memory(*size, *nbo); }; });
  }
  {
    auto* cmd = nb->add_subcommand("coverage",
                                   "Figure 4: extra pixels each covering (paper, corners, one, rectangle levels) reads, for every box size");
    auto size = std::make_shared<std::string>("256x256");
    auto out = std::make_shared<std::string>();
    auto csv = std::make_shared<std::string>();
    auto scale = std::make_shared<int>(0);
    cmd->add_option("--size", *size,
                    fmt::format("Largest box, WxH: every box from 1x1 to WxH is covered; each side at most {}", kMaxCoverageSide))
        ->capture_default_str();
    cmd->add_option("--out", *out, "False-colour image (PNG or any format OpenImageIO writes)")->required();
    cmd->add_option("--csv", *csv, "CSV of the same numbers (default: the image path with .csv)");
    cmd->add_option("--scale", *scale,
                    fmt::format("Pixels per box size in the image (default: fit about 512 px); the image is at most {} M pixels",
                                kMaxCoveragePixels >> 20))
        ->check(CLI::Range(0, 16));
    cmd->callback([&action, size, out, csv, scale] { action = [=] { return run_coverage(*size, *out, *csv, *scale); }; });
  }
}

}  // namespace nbsim::cli

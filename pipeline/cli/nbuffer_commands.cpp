// `nbsim nbuffer query|build|coverage`: the N-buffer core from the command line.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numeric>

#include "model/common/error.h"
#include "model/common/names.h"
#include "model/nbuffer/nbuffer.h"
#include "pipeline/cli/command.h"
#include "pipeline/io/image_io.h"
#include "pipeline/scenes/demo_scene.h"
#include "pipeline/io/output_folder.h"

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

  void add_options(CLI::App* cmd) {
    cmd->add_option("--op", op, "Farthest is max (depth func LESS) or min (reversed Z, min-litmaps)")
        ->check(CLI::IsMember(name_list(kFarOpNames)))
        ->capture_default_str();
    cmd->add_option("--format", format, "Level storage: f32, u24 or u16 unorm (rounded toward far)")
        ->check(CLI::IsMember(name_list(kStorageFormatNames)))
        ->capture_default_str();
    cmd->add_option("--max-level", max_level, "Build levels 0..K only (partial build); -1 builds all")
        ->check(CLI::Range(-1, 30))
        ->capture_default_str();
  }

  NBufferConfig config() const {
    return {op == "max" ? FarOp::Max : FarOp::Min, *parse_storage_format(format), max_level};
  }
};

int run_query(const DepthSource& src, const NBufferOptions& nbo, const std::string& covering,
              const std::vector<std::string>& rect_texts) {
  std::vector<Rect> rects;
  for (const auto& t : rect_texts) rects.push_back(parse_rect(t));
  const DepthImage depth = src.load();
  const NBuffer nb(depth, nbo.config());
  for (const Rect& r : rects)  // refuse before printing anything, so no answer is half-written
    if (clip(r, nb.width(), nb.height()).empty())
      throw InputError(fmt::format("rectangle {},{},{},{} lies outside the {}x{} image", r.x, r.y, r.w, r.h,
                                   nb.width(), nb.height()));
  const CoveringKind kind = *parse_covering_kind(covering);
  for (const Rect& r : rects) {
    const QueryResult q = nb.query(r, kind);
    ojson texels = ojson::array();
    for (const Texel& t : q.read()) texels.push_back({t.x, t.y});
    ojson line;
    line["rect"] = {r.x, r.y, r.w, r.h};
    line["level"] = q.level;
    line["texels"] = texels;
    line["value"] = tidy(q.value);
    line["case"] = to_string(cover(clip(r, nb.width(), nb.height()), kind, nb.full_level_count() - 1).kase);
    line["complete"] = q.complete;
    fmt::print("{}\n", line.dump());
  }
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
    levels.push_back({{"level", i}, {"side", 1 << i}, {"min", tidy(*llo)}, {"max", tidy(*lhi)},
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

int run_coverage(const std::string& size, const fs::path& png, fs::path csv, int scale) {
  const auto [bw, bh] = parse_size(size, "--size");
  if (bw > kMaxCoverageSide || bh > kMaxCoverageSide)
    throw InputError(fmt::format("--size {} is too large: at most {}x{} box sizes", size, kMaxCoverageSide, kMaxCoverageSide));
  // The image's size, checked before anything is written: two panels of (box sizes x scale) pixels,
  // a gap and a colour ramp.
  if (scale < 1) scale = std::max(1, 512 / std::max(bw, bh));
  const int gap = 8 * scale, pw = bw * scale, ph = bh * scale, ramp = std::max(12, ph / 16);
  const int iw = 2 * pw + gap, ih = ph + gap + ramp;
  if (static_cast<long long>(iw) * ih > kMaxCoveragePixels)
    throw InputError(fmt::format("--size {} with --scale {} makes a {}x{} image: at most {} M pixels (lower --scale)", size, scale, iw,
                                 ih, kMaxCoveragePixels >> 20));
  if (csv.empty()) csv = fs::path(png).replace_extension(".csv");
  // Box sizes never exceed the image, so the covering never clamps: use an unbounded top level.
  const int top = 30;
  std::vector<double> one_ratio, four_ratio;
  one_ratio.reserve(static_cast<std::size_t>(bw) * bh);
  four_ratio.reserve(one_ratio.capacity());
  std::ofstream out(csv);
  if (!out) throw InputError(fmt::format("cannot write '{}'", csv.string()));
  out << "w,h,area,one_level,one_extra_px,four_level,four_lookups,four_case,four_extra_px\n";
  long long exact = 0;
  std::array<long long, 5> cases{};
  for (int h = 1; h <= bh; ++h) {
    for (int w = 1; w <= bw; ++w) {
      const Rect r{0, 0, w, h};
      const Covering one = cover_one(r, top), four = cover_four(r, top);
      const long long extra1 = covered_area(one) - r.area(), extra4 = covered_area(four) - r.area();
      one_ratio.push_back(static_cast<double>(extra1) / static_cast<double>(r.area()));
      four_ratio.push_back(static_cast<double>(extra4) / static_cast<double>(r.area()));
      exact += extra4 == 0;
      ++cases[static_cast<std::size_t>(four.kase)];
      out << fmt::format("{},{},{},{},{},{},{},{},{}\n", w, h, r.area(), one.level, extra1, four.level, four.count,
                         to_string(four.kase), extra4);
    }
  }
  if (!out.flush()) throw InputError(fmt::format("cannot write '{}'", csv.string()));

  // Two panels (one square | four squares), x = box width, y = box height (y up), then a colour
  // ramp. Colour = log2(1 + extra / area), scaled by the largest value of both panels.
  const double vmax = std::log2(1.0 + std::max(*std::max_element(one_ratio.begin(), one_ratio.end()),
                                               *std::max_element(four_ratio.begin(), four_ratio.end())));
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(iw) * ih * 3, 255);
  auto put = [&](int x, int y, std::array<std::uint8_t, 3> c) {
    std::copy(c.begin(), c.end(), rgb.begin() + 3 * (static_cast<std::ptrdiff_t>(y) * iw + x));
  };
  for (int y = 0; y < ph; ++y) {
    for (int x = 0; x < pw; ++x) {
      const std::size_t k = static_cast<std::size_t>(y / scale) * bw + static_cast<std::size_t>(x / scale);
      put(x, ramp + gap + y, colour(vmax > 0 ? std::log2(1.0 + one_ratio[k]) / vmax : 0.0));
      put(pw + gap + x, ramp + gap + y, colour(vmax > 0 ? std::log2(1.0 + four_ratio[k]) / vmax : 0.0));
    }
  }
  for (int y = 0; y < ramp; ++y)
    for (int x = 0; x < iw; ++x) put(x, y, colour(static_cast<double>(x) / (iw - 1)));
  io::write_rgb8(iw, ih, rgb, png);

  auto mean = [](const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size()); };
  auto worst = [](const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); };
  const double n = static_cast<double>(one_ratio.size());
  fmt::print("coverage of every box size from 1x1 to {}x{} ({} sizes)\n", bw, bh, one_ratio.size());
  fmt::print("  one square  : mean extra {:7.1f}% of the box, worst {:.0f}x the box\n", 100 * mean(one_ratio), worst(one_ratio));
  fmt::print("  four squares: mean extra {:7.1f}% of the box, worst {:.0f}x the box, exact for {:.1f}% of sizes\n",
             100 * mean(four_ratio), worst(four_ratio), 100.0 * static_cast<double>(exact) / n);
  fmt::print("  four-square cases:");
  for (std::size_t c = 0; c < cases.size(); ++c)
    fmt::print(" {} {:.1f}%", to_string(static_cast<CoveringCase>(c)), 100.0 * static_cast<double>(cases[c]) / n);
  fmt::print("\n  wrote {} (left: one square, right: four squares; x = width, y = height, colour = log2(1 + extra/area) up to {:.2f})\n",
             png.string(), vmax);
  fmt::print("  wrote {}\n", csv.string());
  return 0;
}

}  // namespace

void add_nbuffer_commands(CLI::App& app, Action& action) {
  auto* nb = app.add_subcommand("nbuffer", "N-buffer core: query rectangles, build levels, coverage map (Fig. 4)");
  nb->require_subcommand(1);

  {
    auto* cmd = nb->add_subcommand("query", "Answer rectangles with the four-square (or one-square) covering; one JSON line each");
    auto src = std::make_shared<DepthSource>();
    auto nbo = std::make_shared<NBufferOptions>();
    auto covering = std::make_shared<std::string>("four");
    auto rects = std::make_shared<std::vector<std::string>>();
    src->add_options(cmd);
    nbo->add_options(cmd);
    cmd->add_option("--covering", *covering, "four: at most four squares of one level; one: a single larger square")
        ->check(CLI::IsMember({"four", "one"}))
        ->capture_default_str();
    cmd->add_option("--rect", *rects, "Rectangle X,Y,W,H in pixels, y up (repeatable)")->required()->allow_extra_args(false);
    cmd->footer("Prints {\"rect\":[x,y,w,h],\"level\":i,\"texels\":[[x,y],...],\"value\":v,\"case\":c,\"complete\":b} per rectangle.\n"
                "Rectangles partly outside the image are clipped; empty or fully outside ones are refused (exit 2).");
    cmd->callback([&action, src, nbo, covering, rects] {
      action = [=] { return run_query(*src, *nbo, *covering, *rects); };
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
    auto* cmd = nb->add_subcommand("coverage", "Figure 4: extra pixels read by one square and by four squares, for every box size");
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

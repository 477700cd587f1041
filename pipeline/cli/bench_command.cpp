// `nbsim bench nbuffer`: times the N-buffer core (pipeline/bench) and prints one JSON line per
// result, with ratios against baselines measured in the same run.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "model/common/names.h"
#include "model/scene/frame.h"
#include "model/common/error.h"
#include "pipeline/bench/nbuffer_bench.h"
#include "model/config/schema.h"
#include "pipeline/bench/replay_bench.h"
#include "pipeline/sim/gpu.h"
#include "pipeline/cli/command.h"
#include "traces/capture/paths.h"
#include "traces/capture/scenes.h"
#include "traces/capture/technique.h"

namespace nbsim::cli {

namespace {

using ojson = nlohmann::ordered_json;

struct BenchArgs {
  std::vector<std::string> only;
  double min_time_s = 0.05;
  int repetitions = 3;
  std::string json_out;
};

int run_nbuffer_bench(const BenchArgs& args) {
  bench::NBufferBenchOptions options;
  if (!args.only.empty()) {
    options.build = options.query = options.update = false;
    for (const std::string& s : args.only) {
      if (s == "build") options.build = true;
      else if (s == "query") options.query = true;
      else if (s == "update") options.update = true;
      else throw InputError(fmt::format("bad --only '{}': expected build, query or update", s));
    }
  }
  options.min_time_s = args.min_time_s;
  options.repetitions = args.repetitions;
  options.progress = isatty(fileno(stderr)) != 0;

  std::ofstream json_file;
  if (!args.json_out.empty()) {  // open before the long run, so a bad path fails at once
    json_file.open(args.json_out);
    if (!json_file) throw InputError(fmt::format("cannot write '{}'", args.json_out));
  }
  ojson all = ojson::array();
  bench::run_nbuffer_bench(options, [&](const ojson& line) {
    fmt::print("{}\n", line.dump());
    std::fflush(stdout);
    all.push_back(line);
  });
  if (json_file.is_open()) {
    json_file << all.dump(2) << "\n";
    if (!json_file.flush()) throw InputError(fmt::format("cannot write '{}'", args.json_out));
  }
  return 0;
}

constexpr const char* nbuffer_footer =
    "Prints one JSON object per line (times: median over --repetitions of thread CPU time per iteration):\n"
    "  {\"bench\":\"build\",\"size\":\"WxH\",\"levels\":L,\"build_ms\":t,\"copy_ms\":c,\"ratio\":t/c}\n"
    "    for 256x256, 512x512, 640x480, 1024x1024 (the built-in city scene). build_ms: a full NBuffer build\n"
    "    (f32, max) into an allocated N-buffer. copy_ms: the bytes a naive level-by-level build reads and\n"
    "    writes, streamed: L-1 memcpy's of a W*H float plane, plane i to plane i+1, measured in the same run.\n"
    "  {\"bench\":\"build_rect\",\"size\":\"WxH\",\"levels\":P,\"bytes\":b,\"square_levels\":L,\"square_bytes\":s,\"build_ms\":t,\n"
    "   \"square_build_ms\":u,\"ratio_vs_square\":t/u}  the rectangle levels (2^i x 2^j, every one) at the same sizes.\n"
    "  {\"bench\":\"query\",\"size\":\"1024x1024\",\"method\":m,\"queries_per_s\":q,\"ratio_vs_corners\":r}\n"
    "    m = paper | corners | one (N-buffer coverings), rect (rectangle levels), hiz (Hi-Z pyramid), brute (scan\n"
    "    every pixel of the rect);\n"
    "    4096 fixed-seed random rects, sides log-uniform in 1..512.\n"
    "  {\"bench\":\"update\",\"size\":\"1024x1024\",\"dirty\":\"SxS\",\"update_ms\":u,\"rebuild_ms\":b,\"ratio\":u/b,\n"
    "   \"texels_recomputed\":n}  for S = 1, 8, 64, 256: NBuffer::update of a centred rect whose depths\n"
    "    alternate between the scene's and nearer ones; b = a full build; n = texels recomputed, all levels.\n"
    "Absolute times are noisy on shared machines: compare the ratios. Progress goes to stderr when it is a terminal.";

}  // namespace

void add_bench_commands(CLI::App& app, Action& action) {
  auto* bench = app.add_subcommand("bench", "Micro-benchmarks of the model's cores (JSON lines)");
  bench->require_subcommand(1);
  auto* cmd = bench->add_subcommand("nbuffer", "Time N-buffer build (Table 1), queries and incremental updates");
  auto args = std::make_shared<BenchArgs>();
  cmd->add_option("--only", args->only, "Run only these sections: build, query, update (repeatable or comma list)")
      ->delimiter(',')
      ->check(CLI::IsMember({"build", "query", "update"}));
  cmd->add_option("--min-time", args->min_time_s, "Minimum seconds per benchmark and repetition (Google Benchmark)")
      ->check(CLI::Range(0.001, 60.0))
      ->capture_default_str();
  cmd->add_option("--repetitions", args->repetitions, "Runs of each section; the median time is reported")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd->add_option("--json-out", args->json_out, "Also write every line, as one JSON array, to this file");
  cmd->footer(nbuffer_footer);
  cmd->callback([&action, args] { action = [args] { return run_nbuffer_bench(*args); }; });
  {
    auto* rep = bench->add_subcommand("replay", "Simulator speed: capture with llvmpipe, replay the same frames, ratio of the two");
    auto ro = std::make_shared<bench::ReplayBenchOptions>();
    struct Given {
      std::string size, scene, path, mode;
      std::map<std::string, std::string> values;   // capture options by name
      std::map<std::string, CLI::Option*> options;
    };
    auto g = std::make_shared<Given>();
    rep->add_option("--technique", ro->technique, "Technique captured and replayed (a row of nbsim capture --help)")->capture_default_str();
    rep->add_option("--frames", ro->frames, "Frames")->check(CLI::Range(1, 10000))->capture_default_str();
    CLI::Option* size = rep->add_option("--size", g->size, "Viewport, WxH (default: the technique's bench preset)");
    CLI::Option* scene = rep->add_option("--scene", g->scene, "Scene (default: the technique's bench preset)");
    CLI::Option* path = rep->add_option("--path", g->path, "Camera path (default: the technique's bench preset)");
    CLI::Option* mode = rep->add_option("--mode", g->mode, "The technique's variant: the value of its bench preset's mode option");
    rep->add_option("--set", ro->sets, "Override one model config key of the replay, unit.field=value (repeatable)");
    rep->add_option("--repetitions", ro->repetitions,
                    "Capture-and-replay pairs run one after the other; the pair of median ratio is reported (the host's speed drifts)")
        ->check(CLI::Range(1, 100))
        ->capture_default_str();
    // Every capture option of every technique, scene and camera path, passed on to the capture
    // over the technique's preset (the capture refuses one its technique, scene and path lack).
    std::vector<const capture::PluginInfo*> plugins;
    for (const auto& r : capture::technique_table()) plugins.push_back(&r.info);
    for (const auto& r : capture::scene_table()) plugins.push_back(&r.info);
    for (const auto& r : capture::path_table()) plugins.push_back(&r.info);
    for (const capture::PluginInfo* info : plugins)
      for (const capture::OptionSpec& spec : info->options) {
        if (g->options.count(spec.name) || spec.name == "mode") continue;
        std::string readers;
        for (const capture::PluginInfo* other : plugins)
          for (const capture::OptionSpec& s : other->options)
            if (s.name == spec.name) readers += (readers.empty() ? "" : ", ") + other->name;
        g->options[spec.name] = rep->add_option("--" + spec.name, g->values[spec.name], fmt::format("{} [{}]", spec.help, readers))
                                    ->group("Capture options (over the technique's bench preset)");
      }
    std::string presets;
    for (const auto& r : capture::technique_table()) {
      std::string opts;
      for (const auto& [k, v] : r.bench.options.values()) opts += fmt::format(" --{} {}", k, v);
      presets += fmt::format("  {:<18} --scene {} --path {} --size {}{}{}\n", r.info.name, r.bench.scene, r.bench.path, r.bench.size, opts,
                             r.bench.mode_option.empty() || r.bench.mode_option == "mode" ? "" : fmt::format(" (--mode sets --{})", r.bench.mode_option));
    }
    rep->footer("Prints one JSON object: gl_ms (llvmpipe's technique passes, as the capture times them: not its reference\n"
                "passes), replay_ms (the SystemC model), ratio replay/gl, depth_tests_per_s and cycles_per_s of the model,\n"
                "measured in the same run (of --repetitions capture-and-replay pairs, the pair of median ratio; ratios: every\n"
                "pair's); the capture options used (options), and <technique>_summary: the replay's\n"
                "technique totals. Each technique's bench preset (what is captured unless told otherwise):\n" + presets);
    rep->callback([&action, ro, g, size, scene, path, mode] {
      if (size->count()) ro->size = g->size;
      if (scene->count()) ro->scene = g->scene;
      if (path->count()) ro->path = g->path;
      if (mode->count()) ro->mode = g->mode;
      for (const auto& [name, option] : g->options)
        if (option->count()) ro->options[name] = g->values[name];
      action = [ro] {
        if (ro->size) parse_size(*ro->size, "--size");
        {  // a bad config key is refused before anything is captured
          config::Schema schema;
          pipeline::GpuConfig c;
          pipeline::GpuConfig::describe(schema, c);
          for (const std::string& set : ro->sets) schema.set(set);
        }
        fmt::print("{}\n", bench::run_replay_bench(*ro).dump());
        return 0;
      };
    });
  }
}

}  // namespace nbsim::cli

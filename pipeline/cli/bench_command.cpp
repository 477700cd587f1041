// `nbsim bench nbuffer`: times the N-buffer core (pipeline/bench) and prints one JSON line per
// result, with ratios against baselines measured in the same run.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "model/common/names.h"
#include "model/scene/frame.h"
#include "model/common/error.h"
#include "pipeline/bench/nbuffer_bench.h"
#include "pipeline/bench/replay_bench.h"
#include "pipeline/cli/command.h"

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
    rep->add_option("--size", ro->size, "Viewport, WxH")->capture_default_str();
    rep->add_option("--frames", ro->frames, "Frames")->check(CLI::Range(1, 10000))->capture_default_str();
    rep->add_option("--technique", ro->technique, "Technique captured and replayed")
        ->check(CLI::IsMember(std::vector<std::string>(std::begin(bench::kReplayBenchTechniques), std::end(bench::kReplayBenchTechniques))))
        ->capture_default_str();
    rep->add_option("--mode", ro->mode,
                    "Capture test mode: occlusion_culling's (oq, oq_hier, nb, nb_hier, none; default oq), particles' "
                    "(none, center, nb, hiz; default nb) or shadows' (infinite, culled, clamped; default clamped)");
    rep->add_option("--scene", ro->scene, "Scene: city (default); shadows also terrain or boxes (flown over)");
    rep->add_option("--particles", ro->particles, "Particles a frame (technique particles)")->capture_default_str();
    rep->add_option("--sprite", ro->sprite, "Sprite size: 16, 24 or atten (technique particles)")->capture_default_str();
    rep->add_option("--shape", ro->shape, "Shape peeled (technique ldi; default knot): sphere, knot, nested, coil");
    rep->add_option("--ldi-size", ro->ldi_size, "LDI side, texels (technique ldi)")->check(CLI::Range(1, 4096))->capture_default_str();
    rep->add_option("--field", ro->field, "Heightfield (technique relief; default fbm): fbm, walls, spikes, saddle, step");
    rep->add_option("--field-size", ro->field_size, "Heightfield side, texels (technique relief)")
        ->check(CLI::Range(2, 1024))
        ->capture_default_str();
    rep->footer("Prints one JSON object: gl_ms (llvmpipe's technique passes; particles: scene, partial N-buffer or Hi-Z\n"
                "build and the culled particle draws, not the reference pass), replay_ms (the SystemC model), ratio\n"
                "replay/gl, depth_tests_per_s and cycles_per_s of the model, measured in the same run; for particles\n"
                "also particles_summary (the replay's particles totals), for shadows shadows_summary (fill, casters\n"
                "culled, mask pixels differing, N-buffer cost). Shadows: gl_ms spans the observer's depth, the litmaps,\n"
                "both N-buffers, the CPU's per-caster work and the volumes, not the reference pass; the model replays\n"
                "the observer and volume draws and builds both N-buffers, and takes the litmaps as GL made them.\n"
                "Ldi: gl_ms spans viewpoint selection, the peel, crop, compression and GL's parity tests (not the exact\n"
                "reference on the CPU); the model replays the peel passes, crops, compresses and runs both parity tests;\n"
                "--size is ignored (the LDI is --ldi-size square).\n"
                "Relief: gl_ms spans the N-buffer build and every method's box draw with its per-fragment read-back (not\n"
                "the exact reference on the CPU); the model rasterizes each box draw and walks every fragment's ray with\n"
                "the texel cache and the exact reference's scoring; --size is the viewport.");
    rep->callback([&action, ro] {
      action = [ro] {
        parse_size(ro->size, "--size");
        if (ro->technique != "particles" && (ro->particles != bench::ReplayBenchOptions{}.particles ||
                                             ro->sprite != bench::ReplayBenchOptions{}.sprite))
          throw InputError("--particles and --sprite need --technique particles");
        if (ro->technique != "ldi" && (!ro->shape.empty() || ro->ldi_size != bench::ReplayBenchOptions{}.ldi_size))
          throw InputError("--shape and --ldi-size need --technique ldi");
        if (ro->technique != "relief" && (!ro->field.empty() || ro->field_size != bench::ReplayBenchOptions{}.field_size))
          throw InputError("--field and --field-size need --technique relief");
        fmt::print("{}\n", bench::run_replay_bench(*ro).dump());
        return 0;
      };
    });
  }
}

}  // namespace nbsim::cli

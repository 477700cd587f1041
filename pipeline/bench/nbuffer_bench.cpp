// The N-buffer micro-benchmarks behind `nbsim bench nbuffer`; see nbuffer_bench.h for what each
// line means. Google Benchmark times; a custom reporter collects the runs instead of printing them.
#include "pipeline/bench/nbuffer_bench.h"

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "model/common/depth.h"
#include "model/common/error.h"
#include "model/common/rect.h"
#include "model/hiz/pyramid.h"
#include "model/nbuffer/nbuffer.h"
#include "pipeline/scenes/demo_scene.h"

namespace nbsim::bench {

namespace {

using ojson = nlohmann::ordered_json;

constexpr std::uint32_t scene_seed = 1;     // city_depth seed of every benchmark. Fixed.
constexpr std::uint32_t rect_seed = 2005;   // seed of the random query rectangles. Fixed.
constexpr int query_count = 4096;           // rectangles per query iteration. Tunable.
constexpr int query_max_side_log2 = 9;      // query sides are log-uniform in 1 .. 2^9 = 512 px. Fixed.

// Four significant digits: enough for timings whose run-to-run noise is a few percent.
double sig4(double v) {
  if (v == 0.0 || !std::isfinite(v)) return v;
  const double scale = std::pow(10.0, 3 - static_cast<int>(std::floor(std::log10(std::fabs(v)))));
  return std::round(v * scale) / scale;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Collects CPU seconds per iteration of every run by benchmark name; prints nothing but progress.
class Collector final : public benchmark::BenchmarkReporter {
 public:
  Collector(bool progress, int total) : progress_(progress), total_(total) {}

  bool ReportContext(const Context&) override { return true; }

  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      if (run.run_type != Run::RT_Iteration) continue;
      const std::string& name = run.run_name.function_name;
      if (run.error_occurred) {
        if (error_.empty()) error_ = name + ": " + run.error_message;
        continue;
      }
      seconds_[name].push_back(run.cpu_accumulated_time / static_cast<double>(std::max<std::int64_t>(run.iterations, 1)));
      ++done_;
      if (progress_) std::fprintf(stderr, "\rnbsim bench: %d/%d %-32s", done_, total_, name.c_str());
    }
  }

  void finish_progress() const {
    if (progress_) std::fprintf(stderr, "\r%-60s\r", "");
  }
  const std::string& error() const noexcept { return error_; }

  // Median seconds per iteration of `name` over its repetitions.
  double seconds(const std::string& name) const {
    const auto it = seconds_.find(name);
    if (it == seconds_.end() || it->second.empty()) throw std::runtime_error("benchmark " + name + " did not run");
    return median(it->second);
  }
  double ms(const std::string& name) const { return 1e3 * seconds(name); }

 private:
  bool progress_;
  int total_;
  int done_ = 0;
  std::string error_;
  std::map<std::string, std::vector<double>> seconds_;
};

// One section: register its benchmarks, run them `repetitions` times (interleaved), collect.
class Section {
 public:
  explicit Section(const NBufferBenchOptions& o) : options_(o) {}
  Section(const Section&) = delete;
  Section& operator=(const Section&) = delete;
  ~Section() { benchmark::ClearRegisteredBenchmarks(); }

  // `setup` runs untimed before each timed loop (e.g. to put shared state back); `body` is timed.
  template <class Setup, class Body>
  void add(const std::string& name, Setup setup, Body body) {
    benchmark::RegisterBenchmark(name.c_str(), [setup, body](benchmark::State& state) mutable {
      setup();
      for (auto _ : state) body();
    })->MinTime(options_.min_time_s);
    ++count_;
  }
  template <class Body>
  void add(const std::string& name, Body body) {
    add(name, [] {}, std::move(body));
  }

  const Collector& run() {
    collector_ = std::make_unique<Collector>(options_.progress, count_ * options_.repetitions);
    for (int r = 0; r < options_.repetitions; ++r) benchmark::RunSpecifiedBenchmarks(collector_.get());
    collector_->finish_progress();
    if (!collector_->error().empty()) throw std::runtime_error("benchmark failed: " + collector_->error());
    return *collector_;
  }

 private:
  const NBufferBenchOptions& options_;
  int count_ = 0;
  std::unique_ptr<Collector> collector_;
};

std::string size_text(int w, int h) { return fmt::format("{}x{}", w, h); }

constexpr NBufferConfig bench_config{FarOp::Max, StorageFormat::F32, -1};

void run_build(const NBufferBenchOptions& options, const std::function<void(const ojson&)>& emit) {
  struct Case {
    int w, h;
    DepthImage depth;
    NBuffer nb;
    std::vector<float, LevelAllocator<float>> planes;  // L planes of W*H floats for the copy baseline, in the levels' kind of memory
  };
  const std::pair<int, int> sizes[] = {{256, 256}, {512, 512}, {640, 480}, {1024, 1024}};
  std::vector<std::unique_ptr<Case>> cases;
  Section section(options);
  for (const auto& [w, h] : sizes) {
    auto c = std::make_unique<Case>(Case{w, h, scenes::city_depth(w, h, scene_seed), NBuffer(w, h, bench_config), {}});
    c->nb.build(c->depth);  // touch every page once, outside the timing
    const std::size_t n = c->depth.size();
    c->planes.assign(static_cast<std::size_t>(c->nb.level_count()) * n, 0.0f);
    std::copy(c->depth.texels.begin(), c->depth.texels.end(), c->planes.begin());
    Case* p = c.get();
    section.add("build/" + size_text(w, h), [p] {
      p->nb.build(p->depth);
      benchmark::ClobberMemory();
    });
    section.add("copy/" + size_text(w, h), [p, n] {
      float* base = p->planes.data();
      for (int i = 0; i + 1 < p->nb.level_count(); ++i)
        std::memcpy(base + (static_cast<std::size_t>(i) + 1) * n, base + static_cast<std::size_t>(i) * n, n * sizeof(float));
      benchmark::ClobberMemory();
    });
    cases.push_back(std::move(c));
  }
  // Rectangle levels (nbuffer.h LevelShape::Rect): every level, built the same way, their cost and
  // memory against the square levels'.
  struct RectCase {
    int w, h;
    NBuffer nb;
    const DepthImage* depth;
  };
  std::vector<std::unique_ptr<RectCase>> rect_cases;
  NBufferConfig rect_config = bench_config;
  rect_config.shape = LevelShape::Rect;
  for (const auto& c : cases) {
    auto r = std::make_unique<RectCase>(RectCase{c->w, c->h, NBuffer(c->w, c->h, rect_config), &c->depth});
    r->nb.build(c->depth);
    RectCase* p = r.get();
    section.add("build_rect/" + size_text(c->w, c->h), [p] {
      p->nb.build(*p->depth);
      benchmark::ClobberMemory();
    });
    rect_cases.push_back(std::move(r));
  }
  const Collector& results = section.run();
  for (const auto& c : cases) {
    const std::string size = size_text(c->w, c->h);
    const double build_ms = results.ms("build/" + size), copy_ms = results.ms("copy/" + size);
    ojson line;
    line["bench"] = "build";
    line["size"] = size;
    line["levels"] = c->nb.level_count();
    line["build_ms"] = sig4(build_ms);
    line["copy_ms"] = sig4(copy_ms);
    line["ratio"] = sig4(build_ms / copy_ms);
    emit(line);
  }
  for (const auto& r : rect_cases) {
    const std::string size = size_text(r->w, r->h);
    const double rect_ms = results.ms("build_rect/" + size), square_ms = results.ms("build/" + size);
    const NBuffer square(r->w, r->h, bench_config);
    ojson line;
    line["bench"] = "build_rect";
    line["size"] = size;
    line["levels"] = r->nb.level_count();
    line["bytes"] = r->nb.storage_bytes();
    line["square_levels"] = square.level_count();
    line["square_bytes"] = square.storage_bytes();
    line["build_ms"] = sig4(rect_ms);
    line["square_build_ms"] = sig4(square_ms);
    line["ratio_vs_square"] = sig4(rect_ms / square_ms);
    emit(line);
  }
}

void run_query(const NBufferBenchOptions& options, const std::function<void(const ojson&)>& emit) {
  constexpr int size = 1024;
  const DepthImage depth = scenes::city_depth(size, size, scene_seed);
  const NBuffer nb(depth, bench_config);
  const HiZPyramid hiz(depth, {bench_config.op, bench_config.format});
  std::vector<Rect> rects;
  rects.reserve(query_count);
  std::mt19937 rng(rect_seed);
  std::uniform_real_distribution<double> log_side(0.0, query_max_side_log2);
  auto side = [&] { return static_cast<int>(std::lround(std::exp2(log_side(rng)))); };
  for (int i = 0; i < query_count; ++i) {
    const int w = side(), h = side();
    const int x = std::uniform_int_distribution<int>(0, size - w)(rng);
    const int y = std::uniform_int_distribution<int>(0, size - h)(rng);
    rects.push_back({x, y, w, h});
  }

  Section section(options);
  NBufferConfig rect_config = bench_config;
  rect_config.shape = LevelShape::Rect;
  const NBuffer rect(depth, rect_config);
  section.add("query/rect", [&] {
    float acc = 0.0f;
    for (const Rect& r : rects) acc += rect.query(r).value;
    benchmark::DoNotOptimize(acc);
  });
  // The three coverings (model/nbuffer/covering.h), each with the paper's top alignment.
  for (const CoveringKind kind : {CoveringKind::Paper, CoveringKind::Corners, CoveringKind::One}) {
    section.add("query/" + std::string(to_string(kind)), [&, kind] {
      float acc = 0.0f;
      for (const Rect& r : rects) acc += nb.query(r, {kind, CoveringAlign::Top}).value;
      benchmark::DoNotOptimize(acc);
    });
  }
  section.add("query/hiz", [&] {
    float acc = 0.0f;
    for (const Rect& r : rects) acc += hiz.query(r).value;
    benchmark::DoNotOptimize(acc);
  });
  section.add("query/brute", [&] {
    float acc = 0.0f;
    for (const Rect& r : rects) {
      const Rect c = clip(r, depth.width, depth.height);
      float v = neutral_depth(bench_config.op);
      for (int y = c.y; y < c.y1(); ++y) {
        const float* row = depth.texels.data() + static_cast<std::size_t>(y) * depth.width;
        for (int x = c.x; x < c.x1(); ++x) v = farther(bench_config.op, v, row[x]);
      }
      acc += v;
    }
    benchmark::DoNotOptimize(acc);
  });
  const Collector& results = section.run();
  const double corners_qps = query_count / results.seconds("query/corners");
  for (const char* method : {"paper", "corners", "one", "rect", "hiz", "brute"}) {
    const double qps = query_count / results.seconds(std::string("query/") + method);
    ojson line;
    line["bench"] = "query";
    line["size"] = size_text(size, size);
    line["method"] = method;
    line["queries_per_s"] = std::llround(sig4(qps));
    line["ratio_vs_corners"] = sig4(qps / corners_qps);
    emit(line);
  }
}

void run_update(const NBufferBenchOptions& options, const std::function<void(const ojson&)>& emit) {
  constexpr int size = 1024;
  struct Case {
    int side;
    Rect rect;
    DepthImage nearer;  // the original depth with the rect's depths halved
    long long recomputed;
  };
  const DepthImage depth = scenes::city_depth(size, size, scene_seed);
  // One N-buffer shared by every benchmark of the section; `current` says which image it holds.
  NBuffer nb(depth, bench_config);
  const DepthImage* current = &depth;
  Rect current_rect;
  std::vector<std::unique_ptr<Case>> cases;
  Section section(options);
  for (const int s : {1, 8, 64, 256}) {
    auto c = std::make_unique<Case>(Case{s, {(size - s) / 2, (size - s) / 2, s, s}, depth, 0});
    for (int y = c->rect.y; y < c->rect.y1(); ++y)
      for (int x = c->rect.x; x < c->rect.x1(); ++x) c->nearer.at(x, y) *= 0.5f;
    c->recomputed = nb.update(c->nearer, c->rect).total_recomputed();
    nb.update(depth, c->rect);
    Case* p = c.get();
    auto restore = [&nb, &current, &current_rect, &depth, p] {
      if (current != &depth && current != &p->nearer) nb.update(depth, current_rect);
      if (current != &p->nearer) current = &depth;
      current_rect = p->rect;
    };
    section.add("update/" + size_text(s, s), restore, [&nb, &current, &depth, p] {
      current = current == &depth ? &p->nearer : &depth;
      benchmark::DoNotOptimize(nb.update(*current, p->rect));
    });
    cases.push_back(std::move(c));
  }
  section.add("rebuild", [&nb, &current, &depth] {
    nb.build(depth);
    current = &depth;
    benchmark::ClobberMemory();
  });
  const Collector& results = section.run();
  // The alternation must have kept the N-buffer equal to a full build of the image it holds.
  const NBuffer reference(*current, bench_config);
  for (int i = 0; i < nb.level_count(); ++i)
    NBSIM_CHECK(std::equal(nb.level(i).begin(), nb.level(i).end(), reference.level(i).begin()),
                "benchmarked updates diverged from a full build at level " + std::to_string(i));
  const double rebuild_ms = results.ms("rebuild");
  for (const auto& c : cases) {
    const double update_ms = results.ms("update/" + size_text(c->side, c->side));
    ojson line;
    line["bench"] = "update";
    line["size"] = size_text(size, size);
    line["dirty"] = size_text(c->side, c->side);
    line["update_ms"] = sig4(update_ms);
    line["rebuild_ms"] = sig4(rebuild_ms);
    line["ratio"] = sig4(update_ms / rebuild_ms);
    line["texels_recomputed"] = c->recomputed;
    line["texels_per_s"] = std::llround(sig4(static_cast<double>(c->recomputed) / (update_ms * 1e-3)));
    emit(line);
  }
}

}  // namespace

void run_nbuffer_bench(const NBufferBenchOptions& options, const std::function<void(const ojson&)>& emit) {
  if (options.build) run_build(options, emit);
  if (options.query) run_query(options, emit);
  if (options.update) run_update(options, emit);
}

}  // namespace nbsim::bench

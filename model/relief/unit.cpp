// ReliefUnit: the relief technique's frame program, timing, texel cache and counters; see unit.h.
#include "model/relief/unit.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "model/common/error.h"
#include "model/sim/quantum.h"

namespace nbsim::relief {

namespace {

constexpr double kMinRate = 0.01, kMaxRate = 4096.0;
constexpr int kMaxLatency = 100000;

std::uint64_t ceil_div(double work, double per_cycle) {
  if (work <= 0.0) return 0;
  return static_cast<std::uint64_t>(std::ceil(work / per_cycle));
}

memory::CacheConfig cache_config(const ReliefUnitConfig& c) {
  memory::CacheConfig m;
  m.size_bytes = c.cache_bytes;
  m.line_bytes = c.cache_line_bytes;
  m.ways = c.cache_ways;
  return m;
}

}  // namespace

void ReliefUnitConfig::describe(config::Schema& s, ReliefUnitConfig& c) {
  s.add("relief.setup_triangles_per_cycle", c.setup_triangles_per_cycle, "triangles/cycle", "box triangles through setup a cycle",
        kMinRate, kMaxRate);
  s.add("relief.blocks_per_cycle", c.blocks_per_cycle, "blocks/cycle", "4x4 blocks of a box draw the rasterizer hands on a cycle",
        kMinRate, kMaxRate);
  s.add("relief.tests_per_cycle", c.tests_per_cycle, "tests/cycle", "early depth tests of a box draw a cycle", kMinRate, kMaxRate);
  s.add("relief.lanes", c.lanes, "walkers", "ray walkers of the ray-walk unit working at once", 1, 4096);
  s.add("relief.cycles_per_lookup", c.cycles_per_lookup, "cycles", "a walker's cycles a texel lookup served by the cache", 0.0, 1e4);
  s.add("relief.cycles_per_step", c.cycles_per_step, "cycles", "a walker's cycles a step (linear, radius, cell or N-buffer step)", 0.0,
        1e4);
  s.add("relief.cycles_per_bisection", c.cycles_per_bisection, "cycles", "a walker's cycles a bisection", 0.0, 1e4);
  s.add("relief.draw_latency_cycles", c.draw_latency_cycles, "cycles", "fill and drain of one box draw", 0, kMaxLatency);
  s.add("relief.cache_bytes", c.cache_bytes, "bytes", "heightfield texel cache (heights, radii, N-buffer levels); 0: every lookup misses",
        0, 1 << 26);
  s.add("relief.cache_line_bytes", c.cache_line_bytes, "bytes", "texel cache line", 4, 4096);
  s.add("relief.cache_ways", c.cache_ways, "ways", "texel cache associativity", 1, 64);
  s.add("relief.hit_tolerance_texels", c.hit_tolerance_texels, "texels",
        "a hit farther than this from the exact reference's is a hit error (the height axis in texel units)", 0.0, 1e6);
  s.add("relief.score", c.score,
        "score every walk against the exact reference (hit errors); false skips the reference, as the capture's timing leaves out "
        "GL's own reference pass: the hit-error counts are then null (unscored_draws counts the draws)");
}

void ReliefUnitConfig::validate() const {
  const auto rate = [](const char* key, double v) {
    if (!(v >= kMinRate && v <= kMaxRate)) throw InputError(fmt::format("{} is {}, not in [{}, {}]", key, v, kMinRate, kMaxRate));
  };
  rate("relief.setup_triangles_per_cycle", setup_triangles_per_cycle);
  rate("relief.blocks_per_cycle", blocks_per_cycle);
  rate("relief.tests_per_cycle", tests_per_cycle);
  if (lanes < 1 || lanes > 4096) throw InputError(fmt::format("relief.lanes is {}, not in [1, 4096]", lanes));
  for (const auto& [key, v] : {std::pair{"relief.cycles_per_lookup", cycles_per_lookup}, std::pair{"relief.cycles_per_step", cycles_per_step},
                               std::pair{"relief.cycles_per_bisection", cycles_per_bisection}})
    if (!(v >= 0.0 && v <= 1e4)) throw InputError(fmt::format("{} is {}, not in [0, 10000]", key, v));
  if (draw_latency_cycles < 0 || draw_latency_cycles > kMaxLatency)
    throw InputError(fmt::format("relief.draw_latency_cycles is {}, not in [0, {}]", draw_latency_cycles, kMaxLatency));
  if (cache_bytes < 0 || cache_bytes > (1 << 26)) throw InputError(fmt::format("relief.cache_bytes is {}, not in [0, 67108864]", cache_bytes));
  if (cache_line_bytes < 4 || cache_line_bytes > 4096 || (cache_line_bytes & (cache_line_bytes - 1)) != 0)
    throw InputError(fmt::format("relief.cache_line_bytes is {}, not a power of two in [4, 4096]", cache_line_bytes));
  if (cache_ways < 1 || cache_ways > 64) throw InputError(fmt::format("relief.cache_ways is {}, not in [1, 64]", cache_ways));
  if (!(hit_tolerance_texels >= 0.0 && hit_tolerance_texels <= 1e6))
    throw InputError(fmt::format("relief.hit_tolerance_texels is {}, not in [0, 1e6]", hit_tolerance_texels));
}

ReliefUnit::ReliefUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const ReliefUnitConfig& config,
                       memory::Channel& memory, int width, int height, double box_height, bool fused_interpolation,
                       CoveringSpec covering, BoxDepth box_depth)
    : sim::Unit(name, registry),
      config_((config.validate(), config)),
      memory_(memory),
      client_(memory.add_client("relief")),
      box_height_(box_height),
      replay_(width, height, fused_interpolation, covering, box_depth),
      cache_(cache_config(config_)),
      frames_(stats().counter("frames", "frames", "frames replayed")),
      scene_draws_(stats().counter("scene_draws", "draws", "scene draws before and after the boxes (placement city)")),
      scene_depth_tests_(stats().counter("scene_depth_tests", "tests", "depth tests of the scene draws (charged at relief.tests_per_cycle)")),
      scene_mismatches_(stats().counter("scene_mismatches", "draws", "scene draws whose samples passed differ from GL's (expected 0)")),
      box_draws_(stats().counter("box_draws", "draws", "relief_box draws replayed")),
      unscored_draws_(stats().counter("unscored_draws", "draws", "box draws whose walks were not scored (relief.score false)")),
      cache_hits_(stats().counter("cache_hits", "lookups", "lookups the texel cache served")),
      cache_misses_(stats().counter("cache_misses", "lookups", "lookups that missed the texel cache (a line read each)")),
      memory_bytes_(stats().counter("memory_bytes", "bytes", "texel cache line reads on the channel (client relief)")),
      memory_stall_cycles_(stats().counter("memory_stall_cycles", "cycles", "cycles waiting for the channel after the work was done")),
      cycles_(stats().counter("cycles", "cycles", "cycles of every box draw (memory stalls included)")),
      radius_texels_(stats().counter("radius_texels", "texels", "safety-radius texels of the frames' heightfields (N * N a frame)")),
      radius_sum_(stats().counter("radius_sum", "texels", "their radii summed (whole texels)")),
      radius_zero_(stats().counter("radius_zero", "texels", "of those, texels with radius 0")) {
  if (!(box_height > 0.0 && std::isfinite(box_height)))
    throw InputError(fmt::format("the relief trace's box height is {}; it must be a positive number", box_height));
  replay_.set_scoring(config_.score);
  for (Method m : kAllMethods) {
    const std::string p = std::string(to_string(m)) + "_";
    const std::string of = std::string(" (") + std::string(to_string(m)) + ")";
    PerMethod& c = per_method_[static_cast<std::size_t>(m)];
    const auto counter = [&](const char* counter_name, const char* unit, const std::string& what) {
      return &stats().counter(p + counter_name, unit, what + of);
    };
    c.draws = counter("draws", "draws", "box draws");
    c.rasterized = counter("rasterized", "fragments", "the model's box fragments before the early depth test");
    c.fragments = counter("fragments", "fragments", "the model's fragments after the early depth test (the walks run)");
    c.gl_fragments = counter("gl_fragments", "fragments", "GL's fragment counter of the box draws (after the early test)");
    c.samples = counter("samples", "samples", "the model's hits (fragments kept)");
    c.gl_samples = counter("gl_samples", "samples", "GL's samples passed of the box draws");
    c.pixel_mismatches = counter("pixel_mismatches", "fragments", "pixels walked by the model or GL but not both (expected 0)");
    c.walk_mismatches = counter("walk_mismatches", "fragments",
                                "fragments whose hit, t, lookups, steps or bisections differ from GL's (expected 0)");
    c.lookups = counter("lookups", "lookups", "the model's texel lookups");
    c.gl_lookups = counter("gl_lookups", "lookups", "GL's texel lookups (RLFF) of the fragments both walked");
    c.steps = counter("steps", "steps", "walk steps");
    c.bisections = counter("bisections", "bisections", "bisections");
    c.hits = counter("hits", "fragments", "fragments whose walk hit");
    c.capped = counter("capped", "fragments", "walks that reached the iteration cap (counted as misses; expected 0)");
    c.reference_hits = counter("reference_hits", "fragments", "fragments whose exact reference ray hits");
    c.wrong_hit = counter("wrong_hit", "fragments", "hit where the reference misses");
    c.wrong_miss = counter("wrong_miss", "fragments", "missed where the reference hits");
    c.far_hit = counter("far_hit", "fragments", "hit farther than the tolerance from the reference's hit");
    c.errors = counter("errors", "fragments", "hit errors: wrong hit, wrong miss or far hit");
    c.distance_microtexels = counter("distance_microtexels", "1e-6 texels",
                                     "distance from the reference's hit summed over fragments where both hit");
    c.cycles = counter("cycles", "cycles", "cycles of the box draws");
    c.cache_misses = counter("cache_misses", "lookups", "texel cache misses");
    c.storage_bytes = counter("storage_bytes", "bytes",
                              "bytes of the textures the method reads (heights; radii or N-buffer levels), 4 a texel; the largest field's");
    c.depth_written = counter("depth_written", "texels", "depth values the box draws wrote (relief_box_depth box or exact)");
    c.depth_mismatches = counter("depth_mismatches", "draws", "box draws after which the depth buffer differs from GL's (expected 0)");
    c.scene_after_draws = counter("scene_after_draws", "draws", "scene draws after the box draws (placement city)");
    c.scene_after_samples = counter("scene_after_samples", "samples", "samples those scene draws passed");
    c.scene_hidden = counter("scene_hidden", "fragments", "fragments of those scene draws the box's depth hid");
    c.levels_eager_texels = counter("levels_eager_texels", "texels", "N-buffer level texels above 0 a full build per frame computes (nbuffer)");
    c.levels_on_demand_texels = counter("levels_on_demand_texels", "texels",
                                        "level texels above 0 an on-demand build computes for the texels the walks read (nbuffer)");
    c.levels_on_demand_mismatches = counter("levels_on_demand_mismatches", "texels",
                                            "read level texels whose on-demand value differs from the full build's (expected 0)");
  }
}

std::uint64_t ReliefUnit::draw_cycles(const BoxDrawCounts& d, const ReliefUnitConfig& c) {
  const std::uint64_t setup = ceil_div(static_cast<double>(d.triangles), c.setup_triangles_per_cycle);
  const std::uint64_t walk = ceil_div(static_cast<double>(d.blocks), c.blocks_per_cycle);
  const std::uint64_t tests = ceil_div(static_cast<double>(d.depth_tests), c.tests_per_cycle);
  const double work = static_cast<double>(d.lookups) * c.cycles_per_lookup + static_cast<double>(d.steps) * c.cycles_per_step +
                      static_cast<double>(d.bisections) * c.cycles_per_bisection;
  const std::uint64_t rays = std::max(ceil_div(work, c.lanes), ceil_div(static_cast<double>(d.longest_walk) * c.cycles_per_lookup, 1.0));
  return std::max({setup, walk, tests, rays}) + static_cast<std::uint64_t>(c.draw_latency_cycles);
}

void ReliefUnit::on_draw(void* self, const BoxDrawCounts& d) { static_cast<ReliefUnit*>(self)->account(d); }

// One box draw's timing and counters, right after its walks (its cache outcomes are draw_*_).
void ReliefUnit::account(const BoxDrawCounts& d) {
  PerMethod& c = per_method_[static_cast<std::size_t>(d.method)];
  const std::uint64_t bytes = cache_.draw_misses * static_cast<std::uint64_t>(config_.cache_line_bytes);
  label_with([&] { return fmt::format("relief box, {}, {} fragments", to_string(d.method), d.fragments); });
  const std::uint64_t start = sim::local_cycles();
  const std::uint64_t mem_done = bytes ? memory_.transfer(start, bytes, client_) : start;
  work(draw_cycles(d, config_));
  memory_stall_cycles_ += sim::spend_until(mem_done);
  const std::uint64_t spent = sim::local_cycles() - start;
  memory_bytes_ += bytes;
  cycles_ += spent;
  cache_hits_ += cache_.draw_hits;
  cache_misses_ += cache_.draw_misses;
  ++box_draws_;
  if (!d.scored) ++unscored_draws_;
  *c.draws += 1, *c.rasterized += d.rasterized, *c.fragments += d.fragments, *c.gl_fragments += d.gl_fragments, *c.samples += d.samples, *c.gl_samples += d.gl_samples;
  *c.pixel_mismatches += d.pixel_mismatches, *c.walk_mismatches += d.walk_mismatches;
  *c.lookups += d.lookups, *c.gl_lookups += d.gl_lookups, *c.steps += d.steps, *c.bisections += d.bisections;
  *c.hits += d.hits, *c.capped += d.capped, *c.reference_hits += d.reference_hits;
  *c.wrong_hit += d.wrong_hit, *c.wrong_miss += d.wrong_miss, *c.far_hit += d.far_hit, *c.errors += d.errors();
  *c.distance_microtexels += static_cast<std::uint64_t>(std::llround(d.distance_sum * 1e6));
  *c.cycles += spent;
  *c.cache_misses += cache_.draw_misses;
  c.storage_bytes->raise_to(d.storage_bytes);
  *c.depth_written += d.depth_written, *c.depth_mismatches += d.depth_mismatches;
  *c.levels_eager_texels += d.levels_eager_texels, *c.levels_on_demand_texels += d.levels_on_demand_texels;
  *c.levels_on_demand_mismatches += d.levels_on_demand_mismatches;
  *c.scene_after_draws += d.scene_after_draws, *c.scene_after_samples += d.scene_after_samples, *c.scene_hidden += d.scene_hidden;
  cache_.draw_misses = cache_.draw_hits = 0;
}

void ReliefUnit::run_frame(const std::shared_ptr<const scene::Frame>& f, cp::CommandProcessor&) {
  cache_.invalidate();  // a frame's textures are its own
  cache_.draw_misses = cache_.draw_hits = 0;
  const ReliefFrameCounts k = replay_.run_frame(*f, config_.hit_tolerance_texels, box_height_, &cache_, this, &ReliefUnit::on_draw);
  ++frames_;
  radius_texels_ += static_cast<std::uint64_t>(k.size) * static_cast<std::uint64_t>(k.size);
  radius_sum_ += k.radius_sum;
  radius_zero_ += k.radius_zero;
  // The scene's depth (placement city): its depth tests through the same test lanes, charged after
  // the frame's box draws (the frame's total is what a sweep reads).
  if (k.scene_draws) {
    scene_draws_ += k.scene_draws;
    scene_mismatches_ += k.scene_mismatches;
    scene_depth_tests_ += k.scene_depth_tests;
    const std::uint64_t spent = ceil_div(static_cast<double>(k.scene_depth_tests), config_.tests_per_cycle);
    work(spent);
    cycles_ += spent;
  }
}

}  // namespace nbsim::relief

// DepthUnit; see unit.h.
#include "model/depth/unit.h"

#include <algorithm>
#include <array>

namespace nbsim::depth {

namespace {

// The stencil test's per-draw counters and the statistics they add to, one row each.
struct StencilStat {
  std::uint64_t raster::StencilCounters::*field;
  const char* name;
  const char* unit;
  const char* description;
};
constexpr std::array<StencilStat, 6> kStencilStats = {{
    {&raster::StencilCounters::tests, "stencil_tests", "tests", "stencil comparisons against the stencil buffer"},
    {&raster::StencilCounters::passed, "stencil_passed", "fragments", "fragments that passed the stencil test"},
    {&raster::StencilCounters::depth_failed, "stencil_depth_failed", "fragments",
     "fragments that passed the stencil test and failed the depth test"},
    {&raster::StencilCounters::back_facing, "stencil_back_facing", "fragments", "stencil tests with the back face's state"},
    {&raster::StencilCounters::written, "stencil_written", "samples", "stencil values stored (an op other than keep)"},
    {&raster::StencilCounters::changed, "stencil_changed", "samples", "stored stencil values that changed"},
}};

}  // namespace

void DepthUnitConfig::describe(config::Schema& s, DepthUnitConfig& c) {
  s.add("depth.tests_per_cycle", c.tests_per_cycle, "tests/cycle", "depth comparisons a cycle", 0.01, 4096.0);
  s.add("depth.latency_cycles", c.latency_cycles, "cycles", "latency of a block through the unit", 0, 100000);
  s.add("depth.clear_cycles", c.clear_cycles, "cycles", "cost of a fast clear of the depth buffer", 0, 100000000);
  s.add("depth.cache_size_bytes", c.cache.size_bytes, "bytes", "depth cache size (0: no cache)", 0, 1 << 30);
  s.add("depth.cache_line_bytes", c.cache.line_bytes, "bytes", "depth cache line; 256 holds an 8x8 tile", 256, 256);
  s.add("depth.cache_ways", c.cache.ways, "ways", "depth cache associativity", 1, 64);
  s.add("depth.stencil_cache_size_bytes", c.stencil_cache.size_bytes, "bytes", "stencil cache size (0: no cache)", 0, 1 << 30);
  s.add("depth.stencil_cache_line_bytes", c.stencil_cache.line_bytes, "bytes", "stencil cache line; 64 holds an 8x8 tile", 64, 64);
  s.add("depth.stencil_cache_ways", c.stencil_cache.ways, "ways", "stencil cache associativity", 1, 64);
  s.add("depth.fused_interpolation", c.fused_interpolation, "depth plane evaluated with FMA, as llvmpipe on FMA hosts");
}

DepthUnit::DepthUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const DepthUnitConfig& config,
                     int width_px, int height_px, memory::Channel& memory, ResultSink& sink)
    : sim::Unit(name, registry),
      config_(config),
      width_(width_px),
      height_(height_px),
      tiles_x_((width_px + 7) / 8),
      buffer_(width_px, height_px, 1.0f),
      stencil_(width_px, height_px, 0),
      test_(buffer_, stencil_, config.fused_interpolation),
      cache_(config.cache),
      stencil_cache_(config.stencil_cache),
      memory_(memory),
      client_(memory.add_client("depth")),
      stencil_client_(memory.add_client("stencil")),
      sink_(sink),
      fragments_(stats().counter("fragments", "fragments", "rasterized fragments received")),
      tests_(stats().counter("depth_tests", "tests", "depth comparisons against the buffer")),
      passed_(stats().counter("passed", "samples", "fragments that passed the depth test and, when on, the stencil test (GL_SAMPLES_PASSED)")),
      written_(stats().counter("written", "samples", "depth values written")),
      hits_(stats().counter("cache_hits", "accesses", "depth cache hits (one access per 4x4 block)")),
      misses_(stats().counter("cache_misses", "accesses", "depth cache misses")),
      writebacks_(stats().counter("cache_writebacks", "lines", "dirty lines written back")),
      stall_(stats().counter("memory_stall_cycles", "cycles", "cycles waiting for memory after the tests were done")),
      clears_(stats().counter("clears", "clears", "fast clears")),
      stencil_draws_(stats().counter("stencil_draws", "draws", "draws with the stencil test on")),
      stencil_unmodelled_(stats().counter(
          "stencil_draws_unmodelled", "draws",
          "stencil draws whose fragment shader may discard or writes depth: replayed as if it kept every fragment at "
          "its interpolated depth (model/raster/stencil_test.h)")),
      stencil_hits_(stats().counter("stencil_cache_hits", "accesses", "stencil cache hits (one access per 4x4 block of a stencil draw)")),
      stencil_misses_(stats().counter("stencil_cache_misses", "accesses", "stencil cache misses")),
      stencil_writebacks_(stats().counter("stencil_cache_writebacks", "lines", "dirty stencil lines written back")),
      stencil_read_bytes_(stats().counter("stencil_read_bytes", "bytes", "stencil tiles read from memory (cache misses)")),
      stencil_write_bytes_(stats().counter("stencil_write_bytes", "bytes", "stencil tiles written back to memory")) {
  for (const StencilStat& st : kStencilStats) stencil_counts_.push_back(&stats().counter(st.name, st.unit, st.description));
  SC_HAS_PROCESS(DepthUnit);
  SC_THREAD(run);
}

Rect DepthUnit::test(const raster::BlockBatch& b, DrawResult& r) {
  const scene::DrawRecord& d = b.work->record();
  const scene::DepthState& s = d.state;
  const raster::DepthState state{static_cast<raster::DepthFunc>(s.func), s.test, s.write && s.test};
  // Throws InputError for a func or op outside GL's eight (a trace's are checked when read).
  const raster::StencilState stencil = d.stencil.test ? raster::stencil_state(d.stencil) : raster::StencilState{};
  std::uint64_t miss_bytes = 0, stencil_read = 0, stencil_write = 0;
  int x0 = width_, y0 = height_, x1 = 0, y1 = 0;
  for (const raster::Block& blk : b.blocks) {
    const std::uint64_t before = r.depth.written, stencil_before = r.stencil.written;
    const bool front = b.front_facing.empty() || b.front_facing[blk.plane] != 0;
    test_.test_block(b.planes[blk.plane], front, blk.x, blk.y, blk.mask, state, stencil, r.depth, r.stencil);
    if (r.depth.written != before) {
      x0 = std::min(x0, blk.x), y0 = std::min(y0, blk.y);
      x1 = std::max(x1, blk.x + 4), y1 = std::max(y1, blk.y + 4);
    }
    const std::uint64_t tile = static_cast<std::uint64_t>((blk.y >> 3) * tiles_x_ + (blk.x >> 3));
    const memory::Cache::Result c = cache_.access(tile * 256u, r.depth.written != before);
    if (!c.hit) miss_bytes += 256, ++r.cache_misses;
    if (c.writeback) miss_bytes += 256;
    if (stencil.test) {  // the stencil plane: 64-byte tiles, touched only by stencil draws
      const memory::Cache::Result sc = stencil_cache_.access(tile * 64u, r.stencil.written != stencil_before);
      if (!sc.hit) stencil_read += 64;
      if (sc.writeback) stencil_write += 64;
    }
  }
  r.memory_bytes = miss_bytes;
  r.stencil_memory_bytes = stencil_read + stencil_write;
  stencil_read_bytes_ += stencil_read;
  stencil_write_bytes_ += stencil_write;
  if (stencil.test) {
    ++stencil_draws_;
    if (d.discards || d.writes_depth) ++stencil_unmodelled_;
  }
  return x1 > x0 && y1 > y0 ? clip(Rect{x0, y0, x1 - x0, y1 - y0}, width_, height_) : Rect{};
}

void DepthUnit::run() {
  sim::guard_thread([this] { serve(); });
}

void DepthUnit::serve() {
  for (;;) {
    const raster::BlockBatchPtr b = sim::blocking([&] { return in.read(); });
    const cp::Work& w = *b->work;
    label_with([&] { return cp::timeline_label(w); });  // names the clear's or the draw's span
    switch (w.kind) {
      case cp::WorkKind::FrameBegin:
        std::fill(buffer_.texels.begin(), buffer_.texels.end(), raster::stored_depth(test_.depth_format(), w.clear_depth));
        cache_.invalidate();  // a fast clear: cached tiles are dropped, not written back
        std::fill(stencil_.texels.begin(), stencil_.texels.end(), std::uint8_t{0});  // GL's default glClearStencil(0)
        stencil_cache_.invalidate();
        ++clears_;
        if (listener_) listener_->depth_cleared(w.clear_depth);
        work(static_cast<std::uint64_t>(config_.clear_cycles));
        break;
      case cp::WorkKind::Draw: {
        DrawResult r;
        r.geometry = b->geometry;
        r.setup = b->setup;
        r.tiles = b->tiles;
        const std::uint64_t h0 = cache_.hits(), m0 = cache_.misses(), wb0 = cache_.writebacks();
        const std::uint64_t sh0 = stencil_cache_.hits(), sm0 = stencil_cache_.misses(), swb0 = stencil_cache_.writebacks();
        const Rect dirty = test(*b, r);
        if (listener_ && !dirty.empty()) listener_->depth_written(w, buffer_, dirty);
        fragments_ += r.depth.fragments;
        tests_ += r.depth.depth_tests;
        passed_ += r.depth.passed;
        written_ += r.depth.written;
        hits_ += cache_.hits() - h0;
        misses_ += cache_.misses() - m0;
        writebacks_ += cache_.writebacks() - wb0;
        for (std::size_t i = 0; i < kStencilStats.size(); ++i) *stencil_counts_[i] += r.stencil.*kStencilStats[i].field;
        stencil_hits_ += stencil_cache_.hits() - sh0;
        stencil_misses_ += stencil_cache_.misses() - sm0;
        stencil_writebacks_ += stencil_cache_.writebacks() - swb0;
        const std::uint64_t start = sim::local_cycles();
        // Stencil and depth are tested side by side, a fragment a lane: the larger count sets the time.
        const std::uint64_t compute = sim::batch_cycles(std::max(r.depth.depth_tests, r.stencil.tests), config_.tests_per_cycle,
                                                        config_.latency_cycles);
        const std::uint64_t mem_done = r.memory_bytes ? memory_.transfer(start, r.memory_bytes, client_) : start;
        const std::uint64_t stencil_done =
            r.stencil_memory_bytes ? memory_.transfer(start, r.stencil_memory_bytes, stencil_client_) : start;
        work(compute);
        stall_ += sim::spend_until(std::max(mem_done, stencil_done));
        r.done_cycle = sim::local_cycles();
        if (listener_) listener_->draw_finished(w, r);
        sink_.draw_done(w, r);
        break;
      }
      case cp::WorkKind::Snapshot: sink_.snapshot(w, buffer_); break;
      case cp::WorkKind::FrameEnd:
        sink_.stencil_at_frame_end(w, stencil_);
        sink_.frame_done(w, sim::local_cycles());
        break;
      case cp::WorkKind::Stop: sink_.stopped(sim::local_cycles()); return;
    }
  }
}

}  // namespace nbsim::depth

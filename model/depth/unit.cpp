// DepthUnit; see unit.h.
#include "model/depth/unit.h"

#include <algorithm>

namespace nbsim::depth {

void DepthUnitConfig::describe(config::Schema& s, DepthUnitConfig& c) {
  s.add("depth.tests_per_cycle", c.tests_per_cycle, "tests/cycle", "depth comparisons a cycle", 0.01, 4096.0);
  s.add("depth.latency_cycles", c.latency_cycles, "cycles", "latency of a block through the unit", 0, 100000);
  s.add("depth.clear_cycles", c.clear_cycles, "cycles", "cost of a fast clear of the depth buffer", 0, 100000000);
  s.add("depth.cache_size_bytes", c.cache.size_bytes, "bytes", "depth cache size (0: no cache)", 0, 1 << 30);
  s.add("depth.cache_line_bytes", c.cache.line_bytes, "bytes", "depth cache line; 256 holds an 8x8 tile", 256, 256);
  s.add("depth.cache_ways", c.cache.ways, "ways", "depth cache associativity", 1, 64);
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
      test_(buffer_, config.fused_interpolation),
      cache_(config.cache),
      memory_(memory),
      client_(memory.add_client("depth")),
      sink_(sink),
      fragments_(stats().counter("fragments", "fragments", "rasterized fragments received")),
      tests_(stats().counter("depth_tests", "tests", "depth comparisons against the buffer")),
      passed_(stats().counter("passed", "samples", "fragments that passed the depth test")),
      written_(stats().counter("written", "samples", "depth values written")),
      hits_(stats().counter("cache_hits", "accesses", "depth cache hits (one access per 4x4 block)")),
      misses_(stats().counter("cache_misses", "accesses", "depth cache misses")),
      writebacks_(stats().counter("cache_writebacks", "lines", "dirty lines written back")),
      stall_(stats().counter("memory_stall_cycles", "cycles", "cycles waiting for memory after the tests were done")),
      clears_(stats().counter("clears", "clears", "fast clears")) {
  SC_HAS_PROCESS(DepthUnit);
  SC_THREAD(run);
}

Rect DepthUnit::test(const raster::BlockBatch& b, DrawResult& r) {
  const scene::DepthState& s = b.work->record().state;
  const raster::DepthState state{static_cast<raster::DepthFunc>(s.func), s.test, s.write && s.test};
  std::uint64_t miss_bytes = 0;
  int x0 = width_, y0 = height_, x1 = 0, y1 = 0;
  for (const raster::Block& blk : b.blocks) {
    const std::uint64_t before = r.depth.written;
    test_.test_block(b.planes[blk.plane], blk.x, blk.y, blk.mask, state, r.depth);
    if (r.depth.written != before) {
      x0 = std::min(x0, blk.x), y0 = std::min(y0, blk.y);
      x1 = std::max(x1, blk.x + 4), y1 = std::max(y1, blk.y + 4);
    }
    const std::uint64_t line = static_cast<std::uint64_t>((blk.y >> 3) * tiles_x_ + (blk.x >> 3)) * 256u;
    const memory::Cache::Result c = cache_.access(line, r.depth.written != before);
    if (!c.hit) miss_bytes += 256, ++r.cache_misses;
    if (c.writeback) miss_bytes += 256;
  }
  r.memory_bytes = miss_bytes;
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
        std::fill(buffer_.texels.begin(), buffer_.texels.end(), w.clear_depth);
        cache_.invalidate();  // a fast clear: cached tiles are dropped, not written back
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
        const Rect dirty = test(*b, r);
        if (listener_ && !dirty.empty()) listener_->depth_written(w, buffer_, dirty);
        fragments_ += r.depth.fragments;
        tests_ += r.depth.depth_tests;
        passed_ += r.depth.passed;
        written_ += r.depth.written;
        hits_ += cache_.hits() - h0;
        misses_ += cache_.misses() - m0;
        writebacks_ += cache_.writebacks() - wb0;
        const std::uint64_t start = sim::local_cycles();
        const std::uint64_t compute = sim::batch_cycles(r.depth.depth_tests, config_.tests_per_cycle, config_.latency_cycles);
        const std::uint64_t mem_done = r.memory_bytes ? memory_.transfer(start, r.memory_bytes, client_) : start;
        work(compute);
        stall_ += sim::spend_until(mem_done);
        r.done_cycle = sim::local_cycles();
        if (listener_) listener_->draw_finished(w, r);
        sink_.draw_done(w, r);
        break;
      }
      case cp::WorkKind::Snapshot: sink_.snapshot(w, buffer_); break;
      case cp::WorkKind::FrameEnd: sink_.frame_done(w, sim::local_cycles()); break;
      case cp::WorkKind::Stop: sink_.stopped(sim::local_cycles()); return;
    }
  }
}

}  // namespace nbsim::depth

// DepthUnit: the stencil test and the early depth test (model/raster/stencil_test.h, depth_test.h)
// behind a depth cache, a stencil cache and the shared memory channel (model/memory/memory.h). The
// depth buffer is stored in 8x8-pixel tiles of 32-bit depth, one 256-byte cache line each; the
// 8-bit stencil buffer is a separate plane of 8x8-pixel tiles, one 64-byte line each, read and
// written only by draws with the stencil test on. Both are cleared at each frame's start (depth
// to the trace's clear value, stencil to 0, GL's default glClearStencil). It is the last unit of
// the replay pipeline: it reports each draw's counters, the frame's depth snapshots, the stencil
// buffer at each frame's end and the end of each frame to a ResultSink.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "model/config/schema.h"
#include "model/common/rect.h"
#include "model/memory/memory.h"
#include "model/raster/depth_test.h"
#include "model/raster/stencil_test.h"
#include "model/raster/unit.h"
#include "model/sim/unit.h"

namespace nbsim::depth {

struct DepthUnitConfig {
  double tests_per_cycle = 16.0;  // depth comparisons a cycle; tunable
  int latency_cycles = 10;        // tunable
  int clear_cycles = 64;          // a fast clear of the whole buffer; tunable
  memory::CacheConfig cache{32 * 1024, 256, 4};  // 256-byte lines = 8x8 pixels of 32-bit depth
  memory::CacheConfig stencil_cache{8 * 1024, 64, 4};  // 64-byte lines = 8x8 pixels of 8-bit stencil
  bool fused_interpolation = true;  // depth plane evaluated with FMA, as llvmpipe on FMA hosts; fidelity knob

  static void describe(config::Schema& s, DepthUnitConfig& c);
};

// What the depth unit measured for one draw.
struct DrawResult {
  geometry::GeometryCounters geometry;
  raster::SetupCounters setup;
  raster::TileCounters tiles;
  raster::DepthCounters depth;
  raster::StencilCounters stencil;  // zero unless the draw has the stencil test on
  std::uint64_t cache_misses = 0;
  std::uint64_t memory_bytes = 0;          // depth tiles read and written back
  std::uint64_t stencil_memory_bytes = 0;  // stencil tiles read and written back
  std::uint64_t done_cycle = 0;  // when the depth unit finished the draw
};

class ResultSink {
 public:
  virtual ~ResultSink() = default;
  virtual void draw_done(const cp::Work& work, const DrawResult& result) = 0;
  virtual void snapshot(const cp::Work& work, const DepthImage& depth) = 0;
  // The stencil buffer at the frame's end, just before frame_done (all zero when no draw of the
  // frame had the stencil test on).
  virtual void stencil_at_frame_end(const cp::Work& work, const raster::StencilImage& stencil) {
    (void)work, (void)stencil;
  }
  virtual void frame_done(const cp::Work& work, std::uint64_t cycle) = 0;
  virtual void stopped(std::uint64_t cycle) = 0;
};

// Culling modes: the cull stage (model/cull/unit.h) listens to the depth unit. It hears of every
// clear, of the rectangle each draw may have changed (the 4x4 blocks that wrote a depth), and of
// each draw's result before the ResultSink does. Calls come from the depth unit's thread.
class DepthListener {
 public:
  virtual ~DepthListener() = default;
  virtual void depth_cleared(float depth) = 0;
  virtual void depth_written(const cp::Work& work, const DepthImage& depth, const Rect& dirty) = 0;
  virtual void draw_finished(const cp::Work& work, const DrawResult& result) = 0;
};

class DepthUnit : public sim::Unit {
 public:
  sc_core::sc_fifo_in<raster::BlockBatchPtr> in;

  DepthUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const DepthUnitConfig& config, int width_px,
            int height_px, memory::Channel& memory, ResultSink& sink);

  const DepthImage& buffer() const noexcept { return buffer_; }
  const raster::StencilImage& stencil() const noexcept { return stencil_; }
  // The depth buffer's format (the trace's depth_format; Float32 unless set); call before the run.
  void set_depth_format(raster::DepthFormat format) noexcept { test_.set_depth_format(format); }
  void set_listener(DepthListener* l) noexcept { listener_ = l; }

 private:
  void run();    // SC_THREAD: serve() under sim::guard_thread
  void serve();
  // Tests one draw's blocks; returns the bounding rectangle of the blocks that wrote a depth.
  Rect test(const raster::BlockBatch& b, DrawResult& r);
  DepthListener* listener_ = nullptr;
  DepthUnitConfig config_;
  int width_, height_, tiles_x_;
  DepthImage buffer_;
  raster::StencilImage stencil_;
  raster::DepthStencilTest test_;
  memory::Cache cache_, stencil_cache_;
  memory::Channel& memory_;
  int client_, stencil_client_;
  ResultSink& sink_;
  stats::Counter &fragments_, &tests_, &passed_, &written_, &hits_, &misses_, &writebacks_, &stall_, &clears_;
  stats::Counter &stencil_draws_, &stencil_unmodelled_, &stencil_hits_, &stencil_misses_, &stencil_writebacks_,
      &stencil_read_bytes_, &stencil_write_bytes_;
  std::vector<stats::Counter*> stencil_counts_;  // one per raster::StencilCounters field (unit.cpp's table)
};

}  // namespace nbsim::depth

// DepthUnit: the early depth test (model/raster/depth_test.h) behind a depth cache and the shared
// memory channel (model/memory/memory.h). The depth buffer is stored in 8x8-pixel tiles, one cache
// line each. It is the last unit of the replay pipeline: it reports each draw's counters, the
// frame's depth snapshots and the end of each frame to a ResultSink.
#pragma once

#include <cstdint>
#include <memory>

#include "model/config/schema.h"
#include "model/common/rect.h"
#include "model/memory/memory.h"
#include "model/raster/depth_test.h"
#include "model/raster/unit.h"
#include "model/sim/unit.h"

namespace nbsim::depth {

struct DepthUnitConfig {
  double tests_per_cycle = 16.0;  // depth comparisons a cycle; tunable
  int latency_cycles = 10;        // tunable
  int clear_cycles = 64;          // a fast clear of the whole buffer; tunable
  memory::CacheConfig cache{32 * 1024, 256, 4};  // 256-byte lines = 8x8 pixels of 32-bit depth
  bool fused_interpolation = true;  // depth plane evaluated with FMA, as llvmpipe on FMA hosts; fidelity knob

  static void describe(config::Schema& s, DepthUnitConfig& c);
};

// What the depth unit measured for one draw.
struct DrawResult {
  geometry::GeometryCounters geometry;
  raster::SetupCounters setup;
  raster::TileCounters tiles;
  raster::DepthCounters depth;
  std::uint64_t cache_misses = 0;
  std::uint64_t memory_bytes = 0;
  std::uint64_t done_cycle = 0;  // when the depth unit finished the draw
};

class ResultSink {
 public:
  virtual ~ResultSink() = default;
  virtual void draw_done(const cp::Work& work, const DrawResult& result) = 0;
  virtual void snapshot(const cp::Work& work, const DepthImage& depth) = 0;
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
  raster::EarlyDepthTest test_;
  memory::Cache cache_;
  memory::Channel& memory_;
  int client_;
  ResultSink& sink_;
  stats::Counter &fragments_, &tests_, &passed_, &written_, &hits_, &misses_, &writebacks_, &stall_, &clears_;
};

}  // namespace nbsim::depth

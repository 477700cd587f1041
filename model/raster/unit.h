// RasterUnit: the SystemC wrapper of triangle and point setup and the tile rasterizer
// (model/raster/setup.h, point_setup.h, rasterizer.h). A draw's triangles become 4x4 blocks of covered pixels with the depth plane they
// belong to; the unit costs triangles / setup rate plus blocks / block rate cycles, pipelined.
#pragma once

#include <memory>
#include <ostream>
#include <vector>

#include "model/config/schema.h"
#include "model/geometry/unit.h"
#include "model/raster/primitive_tester.h"
#include "model/raster/point_setup.h"
#include "model/raster/rasterizer.h"
#include "model/raster/setup.h"
#include "model/sim/unit.h"

namespace nbsim::raster {

struct RasterUnitConfig {
  double setup_triangles_per_cycle = 1.0;  // tunable
  double blocks_per_cycle = 1.0;           // 4x4 blocks a cycle (16 pixels); tunable
  int latency_cycles = 20;                 // tunable

  static void describe(config::Schema& s, RasterUnitConfig& c);
};

// One 4x4 block of covered pixels: (x, y) its lower-left pixel, bit i + 4 j = pixel (x+i, y+j).
struct Block {
  std::int32_t x = 0, y = 0;
  std::uint16_t mask = 0;
  std::uint32_t plane = 0;  // index into BlockBatch::planes
};

// Raster -> depth: one draw's blocks, the depth planes of its triangles, and its counters.
struct BlockBatch {
  cp::WorkPtr work;
  geometry::GeometryCounters geometry;
  SetupCounters setup;
  TileCounters tiles;
  std::vector<DepthPlane> planes;
  std::vector<std::uint8_t> front_facing;  // per plane: 1 when its primitive is front-facing (the stencil face)
  std::vector<Block> blocks;
};
using BlockBatchPtr = std::shared_ptr<const BlockBatch>;
inline std::ostream& operator<<(std::ostream& os, const BlockBatchPtr& b) {
  return os << "blocks(" << (b ? b->blocks.size() : 0) << ")";
}

class RasterUnit : public sim::Unit {
 public:
  sc_core::sc_fifo_in<geometry::TriangleBatchPtr> in;
  sc_core::sc_fifo_out<BlockBatchPtr>& out;

  RasterUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const RasterUnitConfig& config, int width_px,
             int height_px);

  // cull.granularity=primitive: the draws `tester` asks for have their accepted triangles tested
  // between setup and the tile walk, and the hidden ones dropped (primitive_tester.h). Null: none.
  void set_primitive_tester(PrimitiveTester* tester) noexcept { tester_ = tester; }

 private:
  void run();    // SC_THREAD: serve() under sim::guard_thread
  void serve();
  RasterUnitConfig config_;
  sim::DelayLine<BlockBatchPtr> delay_;
  TriangleSetup setup_;
  PointSetup point_setup_;
  Rasterizer rasterizer_;
  PrimitiveTester* tester_ = nullptr;
  std::vector<SetupPrimitive> prims_;  // one draw's accepted triangles, when a tester tests them
  std::vector<char> hidden_;
  stats::Counter &triangles_, &accepted_, &blocks_, &pixels_;
  stats::VectorCounter& tiles_;
};

}  // namespace nbsim::raster

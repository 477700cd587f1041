// GeometryUnit: the SystemC wrapper of the geometry core (model/geometry/geometry.h): clipping
// as Mesa's draw module does it, the viewport transform and the draw module's face cull, one draw
// at a time: a draw occupies it for triangles / triangles_per_cycle cycles and leaves it
// latency_cycles later (pipelined). A point-sprite draw counts its points as primitives (centre
// clipping; the prims_* counters then count points).
#pragma once

#include <memory>
#include <ostream>
#include <vector>

#include "model/config/schema.h"
#include "model/cp/work.h"
#include "model/geometry/geometry.h"
#include "model/sim/unit.h"

namespace nbsim::geometry {

struct GeometryUnitConfig {
  double triangles_per_cycle = 1.0;  // clip and cull throughput; tunable
  int latency_cycles = 40;           // vertex fetch to setup; tunable
  int batch_triangles = 85;          // llvmpipe's draw-module batch (see GeometryConfig); fidelity knob
  bool fused_viewport = true;        // FMA in the viewport transform (as llvmpipe on FMA hosts); fidelity knob

  static void describe(config::Schema& s, GeometryUnitConfig& c);
};

// Geometry -> raster: the window-space triangles, or points for a point-sprite draw, of one piece
// of work (none for markers).
struct TriangleBatch {
  cp::WorkPtr work;
  std::vector<WindowTriangle> triangles;
  std::vector<WindowPoint> points;
  GeometryCounters counters;
};
using TriangleBatchPtr = std::shared_ptr<const TriangleBatch>;
inline std::ostream& operator<<(std::ostream& os, const TriangleBatchPtr& b) {
  return os << "triangles(" << (b ? b->triangles.size() : 0) << ")";
}

class GeometryUnit : public sim::Unit {
 public:
  sc_core::sc_fifo_in<cp::WorkPtr> in;
  sc_core::sc_fifo_out<TriangleBatchPtr>& out;  // leaves latency_cycles after the work is done

  GeometryUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const GeometryUnitConfig& config,
               int width_px, int height_px);

 private:
  void run();    // SC_THREAD: serve() under sim::guard_thread
  void serve();
  GeometryUnitConfig config_;
  sim::DelayLine<TriangleBatchPtr> delay_;
  GeometryStage stage_;
  stats::Counter &prims_in_, &prims_out_, &clipped_, &rejected_, &culled_, &draws_;
};

}  // namespace nbsim::geometry

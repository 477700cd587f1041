// RasterUnit; see unit.h.
#include "model/raster/unit.h"

#include <bit>

namespace nbsim::raster {

void RasterUnitConfig::describe(config::Schema& s, RasterUnitConfig& c) {
  s.add("raster.setup_triangles_per_cycle", c.setup_triangles_per_cycle, "triangles/cycle", "triangle setup throughput", 0.01, 1024.0);
  s.add("raster.blocks_per_cycle", c.blocks_per_cycle, "4x4 blocks/cycle", "rasterizer throughput", 0.01, 1024.0);
  s.add("raster.latency_cycles", c.latency_cycles, "cycles", "latency from setup to the depth unit", 0, 100000);
}

RasterUnit::RasterUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const RasterUnitConfig& config,
                       int width_px, int height_px)
    : sim::Unit(name, registry),
      out(delay_.out),
      config_(config),
      delay_("delay", 64),
      setup_(SetupConfig{width_px, height_px}),
      point_setup_(SetupConfig{width_px, height_px}),
      rasterizer_(width_px, height_px),
      triangles_(stats().counter("triangles", "triangles", "triangles entering setup")),
      accepted_(stats().counter("accepted", "triangles", "triangles that produced coverage tests")),
      blocks_(stats().counter("blocks", "4x4 blocks", "blocks with covered pixels sent to the depth unit")),
      pixels_(stats().counter("fragments", "fragments", "rasterized fragments")),
      tiles_(stats().vector("tiles", "64x64 tiles", "tiles of binned triangles by class", {"empty", "partial", "full"})) {
  SC_HAS_PROCESS(RasterUnit);
  SC_THREAD(run);
}

void RasterUnit::run() {
  sim::guard_thread([this] { serve(); });
}

void RasterUnit::serve() {
  for (;;) {
    const geometry::TriangleBatchPtr in_batch = sim::blocking([&] { return in.read(); });
    auto b = std::make_shared<BlockBatch>();
    b->work = in_batch->work;
    b->geometry = in_batch->counters;
    SetupTriangle t;
    const geometry::FaceState face = b->work->kind == cp::WorkKind::Draw
                                         ? geometry::FaceState{static_cast<geometry::CullFace>(b->work->record().state.cull),
                                                               b->work->record().state.front_ccw}
                                         : geometry::FaceState{};
    std::uint64_t pixels = 0;
    const auto walk = [&](const SetupTriangle& s) {
      const auto plane = static_cast<std::uint32_t>(b->planes.size());
      b->planes.push_back(s.depth);
      b->front_facing.push_back(s.front_facing ? 1 : 0);
      rasterizer_.rasterize(s, b->tiles, [&](int x, int y, std::uint16_t mask) {
        b->blocks.push_back({x, y, mask, plane});
        pixels += static_cast<std::uint64_t>(std::popcount(mask));
      });
    };
    if (tester_ && b->work->kind == cp::WorkKind::Draw && tester_->tests_primitives(*b->work)) {
      // Per-primitive culling: set up the whole draw, have the tester query its triangles (this
      // thread waits for the query unit), walk the survivors in their order. Setup cycles are
      // still spent on the dropped triangles; their tile walk and depth tests are saved.
      prims_.clear();
      for (const geometry::WindowTriangle& w : in_batch->triangles)
        if (setup_.setup(w, face, t, b->setup) == SetupResult::Accepted) prims_.push_back({&w, t});
      hidden_.assign(prims_.size(), 0);
      tester_->test_primitives(*b->work, prims_, hidden_);
      for (std::size_t i = 0; i < prims_.size(); ++i)
        if (!hidden_[i]) walk(prims_[i].setup);
    } else {
      for (const geometry::WindowTriangle& w : in_batch->triangles)
        if (setup_.setup(w, face, t, b->setup) == SetupResult::Accepted) walk(t);
    }
    // Point sprites (a point draw has no triangles): their squares are walked like triangles; a
    // primitive tester is not asked about them.
    for (const geometry::WindowPoint& p : in_batch->points)
      if (point_setup_.setup(p, t, b->setup) == SetupResult::Accepted) walk(t);
    triangles_ += b->setup.triangles;
    accepted_ += b->setup.accepted;
    blocks_ += b->blocks.size();
    pixels_ += pixels;
    tiles_.add(0, b->tiles.tiles_empty);
    tiles_.add(1, b->tiles.tiles_partial);
    tiles_.add(2, b->tiles.tiles_full);
    label_with([&] { return cp::timeline_label(*b->work); });
    work(sim::batch_cycles(b->setup.triangles + b->setup.points, config_.setup_triangles_per_cycle, 0) +
         sim::batch_cycles(b->blocks.size(), config_.blocks_per_cycle, 0));
    const bool stop = b->work->kind == cp::WorkKind::Stop;
    delay_.send(b, b->work->kind == cp::WorkKind::Draw ? static_cast<std::uint64_t>(config_.latency_cycles) : 0);
    if (stop) return;
  }
}

}  // namespace nbsim::raster

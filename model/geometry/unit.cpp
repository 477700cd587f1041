// GeometryUnit; see unit.h.
#include "model/geometry/unit.h"

namespace nbsim::geometry {

namespace {

GeometryConfig stage_config(const GeometryUnitConfig& c, int w, int h) {
  GeometryConfig g;
  g.width_px = w;
  g.height_px = h;
  g.batch_triangles = c.batch_triangles;
  g.fused_viewport = c.fused_viewport;
  return g;
}

GeometryState state_of(const scene::DepthState& s) {
  GeometryState g;
  g.clip = s.clip == scene::ClipControl::ZeroToOne ? ClipControl::ZeroToOne : ClipControl::NegativeOneToOne;
  g.face.cull = static_cast<CullFace>(s.cull);
  g.face.front_ccw = s.front_ccw;
  g.depth_clamp = s.depth_clamp;
  return g;
}

}  // namespace

void GeometryUnitConfig::describe(config::Schema& s, GeometryUnitConfig& c) {
  s.add("geometry.triangles_per_cycle", c.triangles_per_cycle, "triangles/cycle", "clip and cull throughput", 0.01, 1024.0);
  s.add("geometry.latency_cycles", c.latency_cycles, "cycles", "latency of a draw through the unit", 0, 100000);
  s.add("geometry.batch_triangles", c.batch_triangles, "triangles",
        "triangles per draw-module batch (llvmpipe: 85); changes clipper counts of big draws", 1, 1 << 20);
  s.add("geometry.fused_viewport", c.fused_viewport, "viewport transform with one fused multiply-add, as llvmpipe on FMA hosts");
}

GeometryUnit::GeometryUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const GeometryUnitConfig& config,
                           int width_px, int height_px)
    : sim::Unit(name, registry),
      out(delay_.out),
      config_(config),
      delay_("delay", 64),
      stage_(stage_config(config, width_px, height_px)),
      prims_in_(stats().counter("prims_in", "triangles", "triangles entering clipping")),
      prims_out_(stats().counter("prims_out", "triangles", "triangles handed to setup")),
      clipped_(stats().counter("clipped", "triangles", "triangles that crossed a frustum plane")),
      rejected_(stats().counter("trivially_rejected", "triangles", "triangles outside one frustum plane")),
      culled_(stats().counter("face_culled", "triangles", "triangles dropped by the face cull")),
      draws_(stats().counter("draws", "draws", "draws processed")) {
  SC_HAS_PROCESS(GeometryUnit);
  SC_THREAD(run);
}

void GeometryUnit::run() {
  sim::guard_thread([this] { serve(); });
}

void GeometryUnit::serve() {
  for (;;) {
    const cp::WorkPtr w = sim::blocking([&] { return in.read(); });
    auto batch = std::make_shared<TriangleBatch>();
    batch->work = w;
    if (w->kind == cp::WorkKind::Draw) {
      const scene::DrawRecord& d = w->record();
      if (d.topology == scene::Topology::Points)
        stage_.process_points(d.clip_positions, d.point_sizes, state_of(d.state), batch->points, batch->counters);
      else
        stage_.process(d.clip_positions, state_of(d.state), batch->triangles, batch->counters);
      const GeometryCounters& k = batch->counters;
      prims_in_ += k.prims_in;
      prims_out_ += k.prims_out;
      clipped_ += k.clipped;
      rejected_ += k.trivially_rejected;
      culled_ += k.draw_culled;
      ++draws_;
      label_with([&] { return cp::timeline_label(*w); });
      work(sim::batch_cycles(k.prims_in, config_.triangles_per_cycle, 0));
    }
    delay_.send(batch, w->kind == cp::WorkKind::Draw ? static_cast<std::uint64_t>(config_.latency_cycles) : 0);
    if (w->kind == cp::WorkKind::Stop) return;
  }
}

}  // namespace nbsim::geometry

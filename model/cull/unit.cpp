// CullUnit: the cull stage's frame program, query units and counters; see unit.h.
#include "model/cull/unit.h"

#include <fmt/format.h>

#include <algorithm>

#include "model/common/error.h"
#include "model/common/names.h"
#include "model/raster/depth_test.h"

namespace nbsim::cull {

void CullUnitConfig::describe(config::Schema& s, CullUnitConfig& c) {
  s.add("cull.mode", c.mode,
        "trace replays the recorded draws; the others cull every candidate object themselves: none (draw all), oq, "
        "oq_hier (occlusion queries, flat or over the BVH), nb, nb_hier (N-buffer unit), hiz_tile, hiz_pyramid",
        name_list(kCullModeNames));
  s.add("cull.granularity", c.granularity,
        "object tests the bounds of candidate objects; primitive also tests every triangle of the objects drawn, "
        "between setup and the tile walk, and drops the hidden ones (modes nb, nb_hier, hiz_tile, hiz_pyramid only)",
        name_list(kGranularityNames));
  s.add("cull.bounds_tests_per_cycle", c.bounds_tests_per_cycle, "tests/cycle", "object or node bounds projected a cycle",
        0.01, 1024.0);
  s.add("cull.bounds_latency_cycles", c.bounds_latency_cycles, "cycles", "latency of a batch of bounds tests", 0, 100000);
}

CullMode CullUnitConfig::parsed_mode() const {
  const auto m = parse_cull_mode(mode);
  if (!m) throw InputError(fmt::format("cull.mode: unknown mode '{}'", mode));
  return *m;
}

std::optional<query::Kind> CullUnitConfig::structure_kind() const {
  switch (parsed_mode()) {
    case CullMode::Nb:
    case CullMode::NbHier: return query::Kind::NBuffer;
    case CullMode::HizTile: return query::Kind::TileHiZ;
    case CullMode::HizPyramid: return query::Kind::HiZPyramid;
    default: return std::nullopt;
  }
}

Granularity CullUnitConfig::parsed_granularity() const {
  const auto g = parse_granularity(granularity);
  if (!g) throw InputError(fmt::format("cull.granularity: unknown granularity '{}' (object or primitive)", granularity));
  if (*g == Granularity::Primitive && !supports_primitive_granularity(parsed_mode()))
    throw InputError(fmt::format(
        "cull.granularity=primitive needs a depth-query structure to test triangles against: cull.mode nb, nb_hier, "
        "hiz_tile or hiz_pyramid, not '{}'",
        mode));
  return *g;
}

CullUnit::CullUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const CullUnitConfig& config,
                   const CullSetup& setup, const DepthImage& depth_buffer, query::Structure* structure)
    : sim::Unit(name, registry),
      config_(config),
      mode_(config.parsed_mode()),
      granularity_(config.parsed_granularity()),
      setup_(setup),
      depth_buffer_(depth_buffer),
      structure_(structure),
      frames_(stats().counter("frames", "frames", "frames culled")),
      candidates_(stats().counter("candidates", "objects", "objects in the frustum that are not occluders")),
      bounds_tests_(stats().counter("bounds_tests", "tests", "object and BVH node bounds tested")),
      node_tests_(stats().counter("node_tests", "tests", "of those, BVH node bounds")),
      lookups_(stats().counter("lookups", "texels", "N-buffer or Hi-Z texels compared against (query depth tests)")),
      box_depth_tests_(stats().counter("box_depth_tests", "tests", "depth tests of occlusion-query boxes")),
      update_texels_(stats().counter("update_texels", "texels", "N-buffer or Hi-Z texels recomputed or rebuilt")),
      culled_(stats().counter("culled", "objects", "candidates not found visible")),
      undrawable_(stats().counter("undrawable", "objects", "found visible but without recorded geometry in the trace")),
      false_culls_(stats().counter("false_culls", "objects", "culled candidates that ground truth shows visible")),
      check_(setup.width_px, setup.height_px),
      primitive_tests_(stats().counter("primitive_tests", "triangles",
                                       "triangles of drawn candidates tested before the tile walk (cull.granularity=primitive)")),
      primitives_culled_(stats().counter("primitives_culled", "triangles", "of those, found hidden and dropped")),
      primitive_lookups_(stats().counter("primitive_lookups", "texels",
                                         "N-buffer or Hi-Z texels compared against for the triangles (query depth tests)")),
      primitive_fragments_culled_(stats().counter("primitive_fragments_culled", "fragments",
                                                  "fragments (and depth tests) the dropped triangles would have cost")),
      primitive_false_culls_(stats().counter("primitive_false_culls", "triangles",
                                             "dropped triangles with a fragment passing against the occluders' depth")) {
  if (mode_ == CullMode::Trace) throw InputError("cull.mode=trace replays the recorded draws: no cull stage");
  if (!setup_.scene || setup_.scene->objects.empty())
    throw InputError(fmt::format("cull.mode={} needs the trace's scene objects (SCEN chunk)", to_string(mode_)));
  const std::optional<query::Kind> kind = config.structure_kind();
  NBSIM_CHECK(kind.has_value() == (structure_ != nullptr) && (!kind || *kind == structure_->structure_kind()),
              fmt::format("cull.mode={} was given the wrong query structure", to_string(mode_)));
}

CullUnit::~CullUnit() = default;

std::uint64_t CullUnit::issue(cp::CommandProcessor& cp, std::shared_ptr<cp::Work> w, bool wants_result) {
  w->ticket = ++issued_;
  if (wants_result) results_[w->ticket] = {};
  cp.issue_draw(std::move(w));
  return issued_;
}

void CullUnit::wait_all() {
  sim::blocking([&] {
    while (completed_ < issued_ || clears_ < frames_begun_) wait(completed_event_);
  });
  sim::catch_up(heard_cycle_);  // decoupled: not before the depth unit's local time of the last result
}

void CullUnit::draw_finished(const cp::Work& w, const depth::DrawResult& r) {
  ++completed_;
  const auto it = results_.find(w.ticket);
  if (it != results_.end()) it->second = {r.depth.depth_tests, r.depth.passed};
  heard_cycle_ = std::max(heard_cycle_, r.done_cycle);
  completed_event_.notify(sc_core::SC_ZERO_TIME);
}

void CullUnit::depth_cleared(float depth) {
  heard_cycle_ = std::max(heard_cycle_, sim::local_cycles());  // the depth unit's thread
  ++clears_;
  completed_event_.notify(sc_core::SC_ZERO_TIME);
  if (structure_) pending_clear_texels_ += structure_->cleared(depth);
}

void CullUnit::depth_written(const cp::Work& w, const DepthImage& depth, const Rect& dirty) {
  if (!w.feeds_cull) return;
  if (structure_) pending_update_texels_ += structure_->changed(depth, dirty);
}

void CullUnit::prepare(CullReport& r) {
  if (structure_) pending_update_texels_ += structure_->prepare(depth_buffer_);
  r.update_texels += pending_update_texels_;
  r.clear_texels += pending_clear_texels_;
  update_texels_ += pending_update_texels_;
  pending_update_texels_ = pending_clear_texels_ = 0;
}

void CullUnit::test_boxes(cp::CommandProcessor& cp, const std::shared_ptr<const scene::Frame>& f, const scene::FrameView& v,
                          const std::vector<scene::TestItem>& items, std::vector<scene::BoundsTest>& tests,
                          std::vector<std::uint64_t>& cost, CullReport& r) {
  const scene::SceneObjects& s = *setup_.scene;
  std::vector<std::uint64_t> tickets(items.size());
  for (std::size_t i = 0; i < items.size(); ++i) {
    auto d = std::make_shared<scene::DrawRecord>();
    d->role = items[i].node >= 0 ? scene::DrawRole::NodeQuery : scene::DrawRole::BoundsQuery;
    d->object = items[i].object;
    d->node = items[i].node;
    d->state.func = setup_.depth_func;
    d->state.write = false;
    d->state.test = true;
    d->state.cull = scene::CullFace::Back;
    d->state.front_ccw = true;
    d->state.clip = setup_.zero_to_one ? scene::ClipControl::ZeroToOne : scene::ClipControl::NegativeOneToOne;
    const scene::Aabb& b = items[i].node >= 0 ? s.node_bounds[static_cast<std::size_t>(items[i].node)]
                                              : s.objects[static_cast<std::size_t>(items[i].object)];
    scene::box_clip_positions(b, v, d->clip_positions);
    d->has_bounds = true;
    d->bounds = tests[i];
    auto w = std::make_shared<cp::Work>();
    w->frame = f;
    w->own = std::move(d);
    tickets[i] = issue(cp, std::move(w), true);
  }
  wait_all();  // the occlusion query's round trip: results are needed before the next decision
  for (std::size_t i = 0; i < items.size(); ++i) {
    const auto it = results_.find(tickets[i]);
    NBSIM_CHECK(it != results_.end(), "an occlusion query's result went missing");
    r.box_depth_tests += it->second.depth_tests;
    cost[i] = it->second.depth_tests;
    tests[i].visible = tests[i].crosses_near || it->second.passed > 0;
    results_.erase(it);
  }
}

void CullUnit::test_lookups(const std::vector<scene::TestItem>& items, std::vector<scene::BoundsTest>& tests,
                            std::vector<std::uint64_t>& cost, CullReport& r) {
  for (std::size_t i = 0; i < items.size(); ++i) {
    scene::BoundsTest& t = tests[i];
    if (t.crosses_near) {
      t.visible = true;
      continue;
    }
    if (t.w <= 0 || t.h <= 0) {  // off-screen bounds: nothing to draw
      t.visible = false;
      continue;
    }
    NBSIM_CHECK(structure_ != nullptr, "a lookup mode without its query structure");
    const query::Answer a = structure_->query(Rect{t.x, t.y, t.w, t.h}, t.nearest_depth);
    r.lookups += a.lookups;
    r.update_texels += a.update_texels;
    update_texels_ += a.update_texels;
    t.visible = !a.hidden;
    cost[i] = a.lookups;
    r.max_lookups = std::max(r.max_lookups, a.lookups);
  }
}

bool CullUnit::tests_primitives(const cp::Work& w) const {
  if (granularity_ != Granularity::Primitive || w.kind != cp::WorkKind::Draw || w.own || w.feeds_cull) return false;
  const scene::DrawRecord& d = w.record();
  if (d.role != scene::DrawRole::Visible || !d.state.test) return false;
  // "Strictly farther than all the depth stored" proves that the fragments fail only these tests.
  using F = scene::DepthFunc;
  return setup_.op == FarOp::Max ? d.state.func == F::Less || d.state.func == F::Lequal
                                 : d.state.func == F::Greater || d.state.func == F::Gequal;
}

void CullUnit::test_primitives(const cp::Work& w, std::span<const raster::SetupPrimitive> prims, std::vector<char>& hidden) {
  const auto it = reports_.find(w.frame.get());
  NBSIM_CHECK(it != reports_.end(), "a triangle was tested after its frame's report was dropped");
  CullReport& r = *it->second;
  prim_index_.clear(), prim_rects_.clear(), prim_nearest_.clear();
  for (std::size_t i = 0; i < prims.size(); ++i) {
    const PrimitiveQuery q = primitive_query(*prims[i].window, prims[i].setup, setup_.op, setup_.fused_interpolation);
    if (!q.testable) continue;
    prim_index_.push_back(i);
    prim_rects_.push_back(q.rect);
    prim_nearest_.push_back(q.nearest);
  }
  NBSIM_CHECK(structure_ != nullptr, "per-primitive culling without a query structure");
  structure_->query_batch(prim_rects_, prim_nearest_, prim_answers_);
  std::uint64_t lookups = 0, update = 0;
  for (std::size_t k = 0; k < prim_index_.size(); ++k) {
    const query::Answer& a = prim_answers_[k];
    lookups += a.lookups;
    update += a.update_texels;
    hidden[prim_index_[k]] = a.hidden ? 1 : 0;
  }
  r.update_texels += update;
  update_texels_ += update;

  // The check, off the clock (false_cull_check.h).
  const auto func = static_cast<raster::DepthFunc>(w.record().state.func);
  std::uint64_t culled = 0, fragments = 0, false_culls = 0;
  for (std::size_t i = 0; i < prims.size(); ++i) {
    if (!hidden[i]) continue;
    ++culled;
    const FalseCullCheck::Result c = check_.check(prims[i].setup, func, setup_.fused_interpolation);
    fragments += c.fragments;
    false_culls += c.passes ? 1 : 0;
  }
  r.primitive_tests += prim_index_.size();
  r.primitives_culled += culled;
  r.primitive_lookups += lookups;
  r.primitive_fragments_culled += fragments;
  r.primitive_false_culls += false_culls;
  primitive_tests_ += prim_index_.size();
  primitives_culled_ += culled;
  primitive_lookups_ += lookups;
  primitive_fragments_culled_ += fragments;
  primitive_false_culls_ += false_culls;
}

std::shared_ptr<const cp::FrameResult> CullUnit::run_frame(const std::shared_ptr<const scene::Frame>& f, cp::CommandProcessor& cp) {
  ++frames_begun_;  // the command processor has sent this frame's FrameBegin (a clear)
  auto report = std::make_shared<CullReport>();
  CullReport& r = *report;
  r.mode = mode_;
  const scene::SceneObjects& s = *setup_.scene;
  const scene::FrameView v = scene::FrameView::make(f->begin, setup_.width_px, setup_.height_px, setup_.near_m, setup_.nearest_margin,
                                      setup_.zero_to_one, setup_.op == FarOp::Min);
  const std::vector<std::uint32_t> in_frustum = scene::frustum_objects(s, v);

  // The recorded geometry of each object (an Occluder or Visible draw), and this frame's occluders.
  std::vector<std::int64_t> geometry(s.objects.size(), -1);
  std::vector<char> is_occluder(s.objects.size(), 0);
  for (std::size_t i = 0; i < f->draws.size(); ++i) {
    const scene::DrawRecord& d = f->draws[i];
    if (d.object < 0 || static_cast<std::size_t>(d.object) >= s.objects.size() || d.clip_positions.empty()) continue;
    if (d.role != scene::DrawRole::Occluder && d.role != scene::DrawRole::Visible) continue;
    geometry[static_cast<std::size_t>(d.object)] = static_cast<std::int64_t>(i);
    if (d.role == scene::DrawRole::Occluder) is_occluder[static_cast<std::size_t>(d.object)] = 1;
  }

  // 1. The occluders, in the recorded order; their depth writes feed the cull structure.
  for (std::size_t i = 0; i < f->draws.size(); ++i) {
    const scene::DrawRecord& d = f->draws[i];
    if (d.role != scene::DrawRole::Occluder || d.clip_positions.empty()) continue;
    auto w = std::make_shared<cp::Work>();
    w->frame = f;
    w->draw = static_cast<std::uint32_t>(i);
    w->feeds_cull = true;
    issue(cp, std::move(w), false);
  }
  cp.issue_snapshot(f, scene::DepthWhich::AfterOccluders);
  wait_all();
  prepare(r);
  // Every earlier frame's draws have left the pipeline: from here on the raster unit tests only
  // this frame's triangles, against the occluders' depth.
  reports_.clear();
  if (granularity_ == Granularity::Primitive) {
    reports_[f.get()] = report;
    check_.set_occluder_depth(depth_buffer_);
  }

  // 2. Bounds tests of the candidates.
  const scene::BatchTester tester = [&](const std::vector<scene::TestItem>& items, std::vector<scene::BoundsTest>& tests) {
    r.bounds_tests += items.size();
    for (const scene::TestItem& it : items) r.node_tests += it.node >= 0 ? 1 : 0;
    for (const scene::BoundsTest& t : tests) r.crossing_near += t.crosses_near ? 1 : 0;
    if (mode_ == CullMode::None) {
      for (std::size_t i = 0; i < items.size(); ++i) {
        tests[i].visible = true;
        r.tests.push_back({items[i].object, items[i].node, tests[i], 0});
      }
      return;
    }
    label_with([&] { return fmt::format("{} bounds tests", items.size()); });
    work(sim::batch_cycles(items.size(), config_.bounds_tests_per_cycle, config_.bounds_latency_cycles));
    std::vector<std::uint64_t> cost(items.size(), 0);
    if (mode_ == CullMode::Oq || mode_ == CullMode::OqHier)
      test_boxes(cp, f, v, items, tests, cost, r);
    else
      test_lookups(items, tests, cost, r);
    for (std::size_t i = 0; i < items.size(); ++i) r.tests.push_back({items[i].object, items[i].node, tests[i], cost[i]});
  };
  const std::vector<char> visible = scene::find_visible(s, v, in_frustum, is_occluder, hierarchical(mode_), tester);

  // 3. The objects found visible, with the geometry the trace recorded for them.
  const scene::GroundTruth* truth = f->truth ? &*f->truth : nullptr;
  r.has_truth = truth && truth->visible_pixels.size() >= s.objects.size();
  r.in_frustum = in_frustum.size();
  for (auto o : in_frustum) {
    if (is_occluder[o]) {
      ++r.occluders;
      continue;
    }
    ++r.candidates;
    const bool truly_visible = r.has_truth && truth->visible_pixels[o] > 0;
    if (r.has_truth && !truly_visible) ++r.candidates_not_visible;
    if (!visible[o]) {
      ++r.culled;
      if (truly_visible) ++r.false_culls;
      continue;
    }
    ++r.found_visible;
    if (geometry[o] < 0) {
      ++r.undrawable;
      continue;
    }
    auto w = std::make_shared<cp::Work>();
    w->frame = f;
    w->draw = static_cast<std::uint32_t>(geometry[o]);
    issue(cp, std::move(w), false);
  }
  ++frames_;
  candidates_ += r.candidates;
  bounds_tests_ += r.bounds_tests;
  node_tests_ += r.node_tests;
  lookups_ += r.lookups;
  box_depth_tests_ += r.box_depth_tests;
  culled_ += r.culled;
  undrawable_ += r.undrawable;
  false_culls_ += r.false_culls;
  return report;
}

}  // namespace nbsim::cull

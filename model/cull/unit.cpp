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
      in_frustum_(stats().counter("in_frustum", "objects", "objects in the view frustum")),
      occluders_(stats().counter("occluders", "objects", "of those, drawn first (the recorded occluder draws)")),
      candidates_(stats().counter("candidates", "objects", "objects in the frustum that are not occluders")),
      bounds_tests_(stats().counter("bounds_tests", "tests", "object and BVH node bounds tested")),
      node_tests_(stats().counter("node_tests", "tests", "of those, BVH node bounds")),
      crossing_near_(stats().counter("crossing_near", "tests", "bounds tests crossing the near plane (never culled)")),
      found_visible_(stats().counter("found_visible", "objects", "candidates found visible")),
      culled_(stats().counter("culled", "objects", "candidates not found visible")),
      undrawable_(stats().counter("undrawable", "objects", "found visible but without recorded geometry in the trace")),
      frames_with_truth_(stats().counter("frames_with_truth", "frames", "frames whose ground truth covers the scene")),
      candidates_not_visible_(
          stats().counter("candidates_not_visible", "objects", "candidates with no visible pixel (ground truth)")),
      false_culls_(stats().counter("false_culls", "objects", "culled candidates that ground truth shows visible")),
      box_depth_tests_(stats().counter("box_depth_tests", "tests", "depth tests of occlusion-query boxes")),
      lookups_(stats().counter("lookups", "texels", "N-buffer or Hi-Z texels compared against for bounds (query depth tests)")),
      max_lookups_(stats().maximum("max_lookups", "texels", "most texels one bounds test compared against")),
      update_texels_(stats().counter("update_texels", "texels", "N-buffer or Hi-Z texels recomputed or rebuilt")),
      clear_texels_(stats().counter("clear_texels", "texels", "N-buffer texels filled by fast clears (not counted as work)")),
      primitive_tests_(stats().counter("primitive_tests", "triangles",
                                       "triangles of drawn candidates tested before the tile walk (cull.granularity=primitive)")),
      primitives_culled_(stats().counter("primitives_culled", "triangles", "of those, found hidden and dropped")),
      primitive_lookups_(stats().counter("primitive_lookups", "texels",
                                         "N-buffer or Hi-Z texels compared against for the triangles (query depth tests)")),
      primitive_fragments_culled_(stats().counter("primitive_fragments_culled", "fragments",
                                                  "fragments (and depth tests) the dropped triangles would have cost")),
      primitive_false_culls_(stats().counter("primitive_false_culls", "triangles",
                                             "dropped triangles with a fragment passing against the occluders' depth")),
      check_(setup.width_px, setup.height_px) {
  // Derived when the statistics are dumped: the paper-comparable count (docs/architecture.md,
  // "Definitions": depth test).
  stats().formula("query_depth_tests", "tests",
                  "depth tests spent on visibility queries: box fragments, and texels compared for bounds and triangles",
                  [this] { return static_cast<double>(query_depth_tests()); });
  stats().formula("culling_efficiency", "", "culled / candidates_not_visible (1 when every candidate was visible)", [this] {
    return candidates_not_visible_.value() ? static_cast<double>(culled_.value()) / static_cast<double>(candidates_not_visible_.value())
                                           : 1.0;
  });
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

void CullUnit::prepare() {
  if (structure_) pending_update_texels_ += structure_->prepare(depth_buffer_);
  update_texels_ += pending_update_texels_;
  clear_texels_ += pending_clear_texels_;
  pending_update_texels_ = pending_clear_texels_ = 0;
}

void CullUnit::test_boxes(cp::CommandProcessor& cp, const std::shared_ptr<const scene::Frame>& f, const scene::FrameView& v,
                          const std::vector<scene::TestItem>& items, std::vector<scene::BoundsTest>& tests,
                          std::vector<std::uint64_t>& cost) {
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
    box_depth_tests_ += it->second.depth_tests;
    cost[i] = it->second.depth_tests;
    tests[i].visible = tests[i].crosses_near || it->second.passed > 0;
    results_.erase(it);
  }
}

void CullUnit::test_lookups(const std::vector<scene::TestItem>& items, std::vector<scene::BoundsTest>& tests,
                            std::vector<std::uint64_t>& cost) {
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
    lookups_ += a.lookups;
    update_texels_ += a.update_texels;
    t.visible = !a.hidden;
    cost[i] = a.lookups;
    max_lookups_.raise_to(a.lookups);
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
  primitive_tests_ += prim_index_.size();
  primitives_culled_ += culled;
  primitive_lookups_ += lookups;
  primitive_fragments_culled_ += fragments;
  primitive_false_culls_ += false_culls;
}

void CullUnit::set_test_log(std::ostream* log) {
  test_log_ = log;
  if (test_log_) *test_log_ << kBoundsTestLogHeader << "\n";
}

std::uint64_t CullUnit::query_depth_tests() const noexcept {
  return box_depth_tests_.value() + lookups_.value() + primitive_lookups_.value();
}

void CullUnit::run_frame(const std::shared_ptr<const scene::Frame>& f, cp::CommandProcessor& cp) {
  ++frames_begun_;  // the command processor has sent this frame's FrameBegin (a clear)
  const scene::SceneObjects& s = *setup_.scene;
  const scene::FrameView v = scene::FrameView::make(f->begin, setup_.width_px, setup_.height_px, setup_.near_m,
                                                    setup_.nearest_margin, setup_.zero_to_one, setup_.op == FarOp::Min);
  const std::vector<std::uint32_t> in_frustum = scene::frustum_objects(s, v);
  const scene::GroundTruth* truth = f->truth ? &*f->truth : nullptr;
  const bool has_truth = truth && truth->visible_pixels.size() >= s.objects.size();

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

  // 1. The occluders, in the recorded order; their depth writes feed the query structure.
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
  // Every earlier frame has left the pipeline once this returns, its statistics final: from here
  // on everything this unit counts is this frame's until its FrameEnd, and the raster unit tests
  // only this frame's triangles, against the occluders' depth.
  wait_all();
  prepare();
  if (granularity_ == Granularity::Primitive) check_.set_occluder_depth(depth_buffer_);

  // 2. Bounds tests of the candidates, each logged with its decision and cost.
  const scene::BatchTester tester = [&](const std::vector<scene::TestItem>& items, std::vector<scene::BoundsTest>& tests) {
    bounds_tests_ += items.size();
    for (const scene::TestItem& it : items) node_tests_ += it.node >= 0 ? 1 : 0;
    for (const scene::BoundsTest& t : tests) crossing_near_ += t.crosses_near ? 1 : 0;
    std::vector<std::uint64_t> cost(items.size(), 0);
    if (mode_ == CullMode::None) {
      for (scene::BoundsTest& t : tests) t.visible = true;
    } else {
      label_with([&] { return fmt::format("{} bounds tests", items.size()); });
      work(sim::batch_cycles(items.size(), config_.bounds_tests_per_cycle, config_.bounds_latency_cycles));
      if (mode_ == CullMode::Oq || mode_ == CullMode::OqHier)
        test_boxes(cp, f, v, items, tests, cost);
      else
        test_lookups(items, tests, cost);
    }
    if (test_log_)
      for (std::size_t i = 0; i < items.size(); ++i)
        write_bounds_test(*test_log_, f->begin.frame, mode_, items[i], tests[i], cost[i], truth);
  };
  const std::vector<char> visible = scene::find_visible(s, v, in_frustum, is_occluder, hierarchical(mode_), tester);

  // 3. The objects found visible, with the geometry the trace recorded for them.
  ++frames_;
  frames_with_truth_ += has_truth ? 1 : 0;
  in_frustum_ += in_frustum.size();
  for (auto o : in_frustum) {
    if (is_occluder[o]) {
      ++occluders_;
      continue;
    }
    ++candidates_;
    const bool truly_visible = has_truth && truth->visible_pixels[o] > 0;
    if (has_truth && !truly_visible) ++candidates_not_visible_;
    if (!visible[o]) {
      ++culled_;
      if (truly_visible) ++false_culls_;
      continue;
    }
    ++found_visible_;
    if (geometry[o] < 0) {
      ++undrawable_;
      continue;
    }
    auto w = std::make_shared<cp::Work>();
    w->frame = f;
    w->draw = static_cast<std::uint32_t>(geometry[o]);
    issue(cp, std::move(w), false);
  }
}

}  // namespace nbsim::cull

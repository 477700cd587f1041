// ParticlesUnit: the particles technique's frame program and counters; see unit.h.
#include "model/particles/unit.h"

#include <fmt/format.h>

#include <algorithm>

#include "model/common/error.h"
#include "model/particles/roles.h"

namespace nbsim::particles {

void ParticlesUnitConfig::describe(config::Schema& s, ParticlesUnitConfig& c) {
  s.add("particles.tests_per_cycle", c.tests_per_cycle, "particles/cycle",
        "particles through the vertex-stage test a cycle (window position, sprite rectangle, decision)", 0.01, 1024.0);
  s.add("particles.latency_cycles", c.latency_cycles, "cycles", "latency of a frame's batch of vertex-stage tests", 0, 100000);
  s.add("particles.center_lookups_per_cycle", c.center_lookups_per_cycle, "texels/cycle",
        "mode center: depth-buffer texels the vertex stage reads a cycle", 0.01, 1024.0);
  s.add("particles.mode", c.mode,
        "the vertex-stage test: trace (the capture's particle_mode) or none, center, nb, hiz (a capture replayed as that "
        "mode would have run; exact on a none capture, which draws every sprite)",
        {"trace", "none", "center", "nb", "hiz"});
}

ParticlesUnit::ParticlesUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const ParticlesUnitConfig& config,
                             const ParticlesSetup& setup, const DepthImage& depth_buffer, query::Structure* structure,
                             const HiZUnitConfig* hiz)
    : sim::Unit(name, registry),
      config_(config),
      setup_(setup),
      depth_buffer_(depth_buffer),
      structure_(structure),
      frames_(stats().counter("frames", "frames", "frames replayed")),
      particles_(stats().counter("particles", "particles", "particles in the PRTC records")),
      tested_(stats().counter("tested", "particles", "particles the vertex stage queried (lookups > 0)")),
      culled_(stats().counter("culled", "particles", "particles the model's vertex-stage test culled")),
      kept_too_large_(stats().counter("kept_too_large", "particles",
                                      "on screen but larger than the levels built: kept untested (nb, hiz)")),
      offscreen_(stats().counter("offscreen", "particles", "off screen or outside the depth range: not tested")),
      lookups_(stats().counter("lookups", "texels", "distinct texels the vertex-stage queries read (query depth tests)")),
      build_texels_(stats().counter("build_texels", "texels",
                                    "N-buffer texels recomputed for the levels built, or Hi-Z texels written (partial build)")),
      particle_draws_(stats().counter("particle_draws", "draws", "particle draws issued (GL's, as recorded)")),
      particle_fragments_(stats().counter("particle_fragments", "fragments",
                                          "rasterized fragments of the particle draws (their depth tests)")),
      particle_passed_(stats().counter("particle_passed", "samples", "samples of the particle draws that passed")),
      scene_depth_tests_(stats().counter("scene_depth_tests", "tests", "depth tests of the scene draws")),
      decision_mismatches_(stats().counter("decision_mismatches", "particles",
                                           "particles the model culled and GL drew, or the other way round (expected 0)")),
      lookup_mismatches_(stats().counter("lookup_mismatches", "particles",
                                         "particles whose lookups differ from the ones GL's vertex shader counted")),
      gl_culled_(stats().counter("gl_culled", "particles", "particles GL's vertex shader culled (recorded)")),
      gl_lookups_(stats().counter("gl_lookups", "texels", "texels GL's vertex shader read (recorded)")),
      popping_(stats().counter("popping", "particles",
                               "culled by the model while GL's reference pass shows a passing sample (must be 0 but for center)")),
      false_culls_(stats().counter("false_culls", "particles",
                                   "culled by the model while some pixel of the sprite passes the depth test (exact sprite test)")),
      exactly_hidden_(stats().counter("exactly_hidden", "particles",
                                      "on-screen particles whose every pixel fails the depth test (what an exact test culls)")),
      hidden_kept_(stats().counter("hidden_kept", "particles",
                                   "of exactly_hidden, kept by the model (culled less than the exact sprite test would)")),
      visible_reference_(stats().counter("visible_reference", "particles",
                                         "particles with a passing sample in GL's reference pass")),
      dropped_(stats().counter("dropped", "particles", "particles GL drew that the model culled: left out of its draws")),
      redrawn_(stats().counter("redrawn", "particles",
                               "particles GL culled that the model kept: drawn at the record's window position")),
      own_draws_(stats().counter("own_draws", "draws",
                                 "particle draws issued as the model's own because a decision differs from GL's")) {
  stats().formula("query_depth_tests", "tests", "depth tests of the vertex-stage queries (texels read)",
                  [this] { return static_cast<double>(lookups_.value()); });
  stats().formula("total_depth_tests", "tests",
                  "query depth tests + particle fragments + texels of the partial build (scene draws not included)", [this] {
                    return static_cast<double>(lookups_.value() + particle_fragments_.value() + build_texels_.value());
                  });
  if (setup_.mode == Mode::NBuffer) {
    if (!structure_ || structure_->structure_kind() != query::Kind::NBuffer)
      NBSIM_CHECK(false, "particles mode nb was not given its N-buffer");
  }
  if (setup_.mode == Mode::HiZ) {
    NBSIM_CHECK(hiz != nullptr, "particles mode hiz was not given its Hi-Z config");
    hiz_ = *hiz;
  }
  if ((setup_.mode == Mode::NBuffer || setup_.mode == Mode::HiZ) && setup_.top_level < 0)
    throw InputError(fmt::format("particles mode {}: the trace's levels_built says no level was built", to_string(setup_.mode)));
}

void ParticlesUnit::issue(cp::CommandProcessor& cp, std::shared_ptr<cp::Work> w) {
  ++issued_;
  cp.issue_draw(std::move(w));
}

void ParticlesUnit::wait_all() {
  sim::blocking([&] {
    while (completed_ < issued_ || clears_ < frames_begun_) wait(completed_event_);
  });
  sim::catch_up(heard_cycle_);
}

void ParticlesUnit::depth_cleared(float depth) {
  heard_cycle_ = std::max(heard_cycle_, sim::local_cycles());
  ++clears_;
  completed_event_.notify(sc_core::SC_ZERO_TIME);
  if (structure_) structure_->cleared(depth);  // a fast clear: not counted as build work
}

void ParticlesUnit::depth_written(const cp::Work& w, const DepthImage& depth, const Rect& dirty) {
  if (!w.feeds_cull || !structure_) return;
  pending_build_ += structure_->changed(depth, dirty);
}

void ParticlesUnit::draw_finished(const cp::Work& w, const depth::DrawResult& r) {
  ++completed_;
  const scene::DrawRecord& d = w.record();
  if (d.role == kParticlesRole) {
    particle_fragments_ += r.depth.depth_tests;
    particle_passed_ += r.depth.passed;
  } else if (d.role == scene::DrawRole::Scene) {
    scene_depth_tests_ += r.depth.depth_tests;
  }
  heard_cycle_ = std::max(heard_cycle_, r.done_cycle);
  completed_event_.notify(sc_core::SC_ZERO_TIME);
}

void ParticlesUnit::decide(const FrameParticles& fp) {
  const std::size_t n = fp.particles.size();
  decisions_.assign(n, Decision{});
  std::vector<Decision>& decisions = decisions_;
  std::vector<SpriteRect> rects(n);
  for (std::size_t i = 0; i < n; ++i) rects[i] = sprite_rect(fp.particles[i], setup_.width_px, setup_.height_px);

  // The vertex stage's own work: every particle's rectangle and decision.
  label_with([&] { return fmt::format("{} particle tests", n); });
  work(sim::batch_cycles(n, config_.tests_per_cycle, config_.latency_cycles));

  std::uint64_t lookups = 0;
  switch (setup_.mode) {
    case Mode::None: break;
    case Mode::Center:
      for (std::size_t i = 0; i < n; ++i) {
        decisions[i] = center_test(fp.particles[i], rects[i], depth_buffer_, setup_.margin, setup_.op);
        lookups += decisions[i].lookups;
      }
      work(sim::batch_cycles(lookups, config_.center_lookups_per_cycle, 0));
      break;
    case Mode::NBuffer: {
      rects_.clear(), nearest_.clear(), index_.clear();
      for (std::size_t i = 0; i < n; ++i) {
        if (!rects[i].on_screen) continue;
        if (!nb_testable(rects[i], setup_.top_level)) {
          decisions[i].too_large = true;
          continue;
        }
        index_.push_back(i);
        rects_.push_back(rects[i].clipped);
        nearest_.push_back(query_nearest(fp.particles[i].depth, setup_.margin, setup_.op));
      }
      structure_->query_batch(rects_, nearest_, answers_);  // the N-buffer unit's query port, timed there
      NBSIM_CHECK(answers_.size() == index_.size(), "the N-buffer answered another number of queries");
      for (std::size_t k = 0; k < index_.size(); ++k) {
        Decision& d = decisions[index_[k]];
        d.tested = true;
        d.culled = answers_[k].hidden;
        d.lookups = static_cast<std::uint32_t>(answers_[k].lookups);
        lookups += d.lookups;
        build_texels_ += answers_[k].update_texels;  // lazy updates
      }
      break;
    }
    case Mode::HiZ: {
      // The partial pyramid (levels 0..top level written; the core builds the chain, the rest unused).
      const HiZPyramid pyramid(depth_buffer_, hiz_->pyramid(setup_.op));
      const std::uint64_t texels = hiz_build_texels(setup_.width_px, setup_.height_px, setup_.top_level);
      build_texels_ += texels;
      label("particles hiz build");
      work(sim::batch_cycles(texels, hiz_->build_texels_per_cycle, hiz_->build_latency_cycles));
      for (std::size_t i = 0; i < n; ++i) {
        decisions[i] = hiz_test(fp.particles[i], rects[i], pyramid, setup_.top_level, setup_.margin, setup_.op);
        lookups += decisions[i].lookups;
      }
      label("particles hiz queries");
      work(sim::batch_cycles(lookups, hiz_->lookups_per_cycle, hiz_->lookup_latency_cycles));
      break;
    }
  }

  // Counters, the comparison with GL's decisions, and the checks (off the clock).
  particles_ += n;
  lookups_ += lookups;
  for (std::size_t i = 0; i < n; ++i) {
    const Decision& d = decisions[i];
    const Particle& p = fp.particles[i];
    tested_ += d.tested ? 1 : 0;
    culled_ += d.culled ? 1 : 0;
    kept_too_large_ += d.too_large ? 1 : 0;
    offscreen_ += rects[i].on_screen ? 0 : 1;
    gl_culled_ += fp.culled[i];
    gl_lookups_ += fp.lookups[i];
    decision_mismatches_ += (d.culled ? 1u : 0u) != fp.culled[i] ? 1 : 0;
    lookup_mismatches_ += d.lookups != fp.lookups[i] ? 1 : 0;
    visible_reference_ += fp.reference_samples[i] > 0 ? 1 : 0;
    const Rect drawn = drawn_rect(p, setup_.width_px, setup_.height_px);
    const bool passes = sprite_passes(drawn, p.depth, depth_buffer_, setup_.op);
    exactly_hidden_ += !drawn.empty() && !passes ? 1 : 0;
    hidden_kept_ += !drawn.empty() && !passes && !d.culled ? 1 : 0;
    if (d.culled) {
      popping_ += fp.reference_samples[i] > 0 ? 1 : 0;
      false_culls_ += passes ? 1 : 0;
    }
  }
}

void ParticlesUnit::issue_particle_draw(const std::shared_ptr<const scene::Frame>& f, std::uint32_t draw,
                                        const FrameParticles& fp, std::size_t first, cp::CommandProcessor& cp) {
  const scene::DrawRecord& d = f->draws[draw];
  const std::size_t n = d.clip_positions.size();
  bool same = true;
  for (std::size_t k = 0; k < n && same; ++k) same = decisions_[first + k].culled == (fp.culled[first + k] != 0);
  auto w = std::make_shared<cp::Work>();
  w->frame = f;
  w->draw = draw;
  if (!same) {
    auto own = std::make_shared<scene::DrawRecord>();
    own->index = d.index;
    own->role = d.role;
    own->object = d.object;
    own->state = d.state;
    own->stencil = d.stencil;
    own->topology = d.topology;
    own->discards = d.discards;
    own->writes_depth = d.writes_depth;
    const float half_w = 0.5f * static_cast<float>(setup_.width_px), half_h = 0.5f * static_cast<float>(setup_.height_px);
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t p = first + k;
      const bool gl_culled = fp.culled[p] != 0;
      if (decisions_[p].culled) {
        dropped_ += gl_culled ? 0 : 1;
        continue;
      }
      if (!gl_culled) {
        own->clip_positions.push_back(d.clip_positions[k]);
        own->point_sizes.push_back(k < d.point_sizes.size() ? d.point_sizes[k] : fp.particles[p].size);
        continue;
      }
      // Kept by the model, culled by GL: back from the record's window position to clip space (w = 1).
      const Particle& q = fp.particles[p];
      const float z = d.state.clip == scene::ClipControl::ZeroToOne ? q.depth : 2.0f * q.depth - 1.0f;
      own->clip_positions.push_back({(q.x - half_w) / half_w, (q.y - half_h) / half_h, z, 1.0f});
      own->point_sizes.push_back(q.size);
      ++redrawn_;
    }
    ++own_draws_;
    if (own->clip_positions.empty()) return;  // every particle of the draw culled: nothing to draw
    w->own = std::move(own);
  }
  issue(cp, std::move(w));
}

void ParticlesUnit::run_frame(const std::shared_ptr<const scene::Frame>& f, cp::CommandProcessor& cp) {
  ++frames_begun_;
  const FrameParticles fp = read_particles(*f);  // refuses a damaged record before anything is issued

  // 1. The scene; its depth writes feed the N-buffer (mode nb).
  for (std::size_t i = 0; i < f->draws.size(); ++i) {
    const scene::DrawRecord& d = f->draws[i];
    if (d.role != scene::DrawRole::Scene || d.clip_positions.empty()) continue;
    auto w = std::make_shared<cp::Work>();
    w->frame = f;
    w->draw = static_cast<std::uint32_t>(i);
    w->feeds_cull = true;
    issue(cp, std::move(w));
  }
  wait_all();  // the scene's depth is in the depth unit; every earlier frame has left the pipeline

  // 2. The partial build (the GL build passes are not replayed: the structure is the model's own).
  if (structure_) pending_build_ += structure_->prepare(depth_buffer_);
  build_texels_ += pending_build_;
  pending_build_ = 0;

  // 3. Every particle's vertex-stage test.
  decide(fp);
  ++frames_;

  // 4. The particle draws as the model decided (GL's where the decisions agree), and any other
  // draw with geometry, in order.
  std::size_t first = 0;  // the draw's first particle
  for (std::size_t i = 0; i < f->draws.size(); ++i) {
    const scene::DrawRecord& d = f->draws[i];
    if (d.role == kParticlesRole) {
      ++particle_draws_;
      issue_particle_draw(f, static_cast<std::uint32_t>(i), fp, first, cp);
      first += d.clip_positions.size();
      continue;
    }
    if (d.role == scene::DrawRole::Scene || d.clip_positions.empty()) continue;
    auto w = std::make_shared<cp::Work>();
    w->frame = f;
    w->draw = static_cast<std::uint32_t>(i);
    issue(cp, std::move(w));
  }
  cp.issue_snapshot(f, scene::DepthWhich::Final);
}

}  // namespace nbsim::particles

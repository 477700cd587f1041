// ShadowsUnit: the shadow-volume technique's frame program and counters; see unit.h.
#include "model/shadows/unit.h"

#include <fmt/format.h>

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <limits>

#include "model/common/error.h"
#include "model/shadows/roles.h"

namespace nbsim::shadows {

void ShadowsUnitConfig::describe(config::Schema& s, ShadowsUnitConfig& c) {
  s.add("shadows.tests_per_cycle", c.tests_per_cycle, "casters/cycle",
        "casters through the rectangle and cull-decision stage a cycle (the queries are the N-buffer units')", 0.01, 1024.0);
  s.add("shadows.latency_cycles", c.latency_cycles, "cycles", "latency of a frame's batch of caster decisions", 0, 100000);
  s.add("shadows.volumes", c.volumes,
        "the shadow volumes drawn: trace (GL's, as captured) or the volumes of mode infinite, culled or clamped that the model builds "
        "from the trace's caster meshes with its own N-buffer answers (the paper's clamp rule), or model (the model's own in the "
        "trace's shadow_mode)",
        {"trace", "infinite", "culled", "clamped", "model"});
  s.add("shadows.litmaps", c.litmaps,
        "the litmaps the N-buffers are built over: trace (GL's images) or model (drawn by the model from the trace's object meshes: "
        "the litmap draws with their reprojection test and the receiver splat, bit-exact with GL's at the captured size)",
        {"trace", "model"});
  s.add("shadows.litmap_size", c.litmap_size, "lexels",
        "side of the model's litmaps and of both N-buffers (0: the trace's litmap_size); another size needs shadows.litmaps=model and "
        "shadows.volumes infinite, culled or clamped",
        0, 4096);
  s.add("shadows.own_reference", c.own_reference,
        "with the model's own culled or clamped volumes: draw its own infinite volumes at the same planes off the clock each frame "
        "and count the mask pixels unlike them (own_mask_diff, mask_errors); false skips the check (as the capture's timing leaves "
        "out GL's reference pass)");
  s.add("shadows.litmap_fragments_per_cycle", c.litmap_fragments_per_cycle, "fragments/cycle",
        "the model's litmap passes (shadows.litmaps=model): litmap fragments (each reprojected) and splat points a cycle", 0.01, 1024.0);
}

ShadowsUnit::ShadowsUnit(const sc_core::sc_module_name& name, stats::Registry& registry, const ShadowsUnitConfig& config,
                         const ShadowsSetup& setup, const DepthImage& depth, const raster::StencilImage& stencil,
                         query::NBufferStructure& min_nb, query::NBufferStructure& max_nb)
    : sim::Unit(name, registry),
      config_(config),
      setup_(setup),
      depth_(depth),
      stencil_(stencil),
      min_nb_(min_nb),
      max_nb_(max_nb),
      frames_(stats().counter("frames", "frames", "frames replayed")),
      casters_(stats().counter("casters", "casters", "casters in the SHDC records")),
      measured_(stats().counter("measured", "casters", "casters with a rectangle in the litmap, queried by the model")),
      culled_(stats().counter("culled", "casters", "casters the cull rule culls on the model's z_min/z_max")),
      gl_culled_(stats().counter("gl_culled", "casters", "casters GL culled (decision 1)")),
      outside_(stats().counter("outside", "casters", "casters outside the light's frustum (decision 2, as recorded)")),
      crossing_near_(stats().counter("crossing_near", "casters", "casters crossing the light's near plane (decision 3, as recorded)")),
      kept_by_slab_(stats().counter("kept_by_slab", "casters",
                                    "casters GL kept that the litmap rule culls on GL's values: the capture's slab, widened by a "
                                    "seen caster's own bounds or a near-plane crossing (scene data the trace does not hold)")),
      decision_mismatches_(stats().counter("decision_mismatches", "casters",
                                           "casters GL culled that the rule on GL's own values keeps (expected 0)")),
      zmin_mismatches_(stats().counter("zmin_mismatches", "casters", "casters whose model z_min differs from GL's")),
      zmax_mismatches_(stats().counter("zmax_mismatches", "casters", "casters whose model z_max differs from GL's")),
      not_conservative_(stats().counter("not_conservative", "casters",
                                        "casters whose model z_min is above the exact minimum of the rectangle's litmap_min lexels, or z_max below the "
                                        "exact maximum of its litmap_max lexels (must be 0)")),
      unsafe_culls_(stats().counter("unsafe_culls", "casters",
                                    "casters the model culls that the rule on the rectangle's exact depth range keeps (must be 0)")),
      culls_lost_(stats().counter("culls_lost", "casters", "casters GL culled that the model keeps (a looser design's cost)")),
      lookups_(stats().counter("lookups", "texels", "N-buffer texels the caster queries read, both units")),
      lookup_mismatches_(stats().counter("lookup_mismatches", "casters",
                                         "casters whose texels read differ from the capture's count")),
      build_texels_(stats().counter("build_texels", "texels", "N-buffer texels computed building both units from the litmaps")),
      litmap_draws_(stats().counter("litmap_draws", "draws", "litmap draws of the trace (not rasterized: no clip positions)")),
      litmap_reprojections_(stats().counter("litmap_reprojections", "fragments",
                                            "litmap fragments reprojected into the observer's view (GL's fragment counter of "
                                            "the litmap draws; each reads up to 3x3 observer depth texels)")),
      receiver_splats_(stats().counter("receiver_splats", "points",
                                       "observer receivers splatted into the litmaps as points (GL's fragment counter of the "
                                       "receiver_splat draws, both litmaps; each reads one observer depth texel)")),
      scene_depth_tests_(stats().counter("scene_depth_tests", "tests", "depth tests of the scene draws")),
      volume_draws_(stats().counter("volume_draws", "draws", "shadow-volume draws issued")),
      fill_(stats().counter("fill", "fragments", "rasterized fragments of the shadow-volume draws (the fill)")),
      gl_fill_(stats().counter("gl_fill", "fragments", "GL's rasterized fragments of the shadow-volume draws")),
      reference_fill_(stats().counter("reference_fill", "fragments",
                                      "GL's fill of every caster's infinite volume (SHDC reference_fill: the capture's reference "
                                      "pass, not recorded as draws; the infinite mode's own fill in an infinite capture)")),
      reference_frames_(stats().counter("reference_frames", "frames", "frames whose SHDC record holds reference_fill")),
      stencil_tests_(stats().counter("stencil_tests", "tests", "stencil tests of the shadow-volume draws")),
      mask_pixels_(stats().counter("mask_pixels", "pixels", "shadowed pixels of the model's mask")),
      gl_mask_pixels_(stats().counter("gl_mask_pixels", "pixels", "shadowed pixels of GL's shadow_mask")),
      mask_diff_(stats().counter("mask_diff", "pixels", "pixels where the model's mask differs from GL's shadow_mask (must be 0)")),
      mask_diff_infinite_(stats().counter("mask_diff_infinite", "pixels",
                                          "pixels where the model's mask differs from GL's shadow_mask_infinite (must be 0)")),
      gl_mask_diff_(stats().counter("gl_mask_diff", "pixels", "pixels where GL's shadow_mask differs from its shadow_mask_infinite")),
      model_volumes_(stats().counter("model_volumes", "draws", "shadow volumes the model built itself (config shadows.volumes)")),
      rect_mismatches_(stats().counter("rect_mismatches", "casters",
                                       "casters whose rectangle or outside/near decision, recomputed from the caster meshes, differs from SHDC's")),
      stencil_checksum_(stats().counter("stencil_checksum", "crc",
                                        "CRC-32 of the model's stencil buffer at each frame's end (a frame's value is its own; the run's is their sum)")),
      own_mask_diff_(stats().counter("own_mask_diff", "pixels",
                                     "with the model's own culled or clamped volumes: pixels where its mask differs from its own infinite "
                                     "volumes' mask, cut at the same planes (must be 0)")),
      litmap_texel_diff_(stats().counter("litmap_texel_diff", "texels",
                                         "with shadows.litmaps=model at the captured size: litmap texels (both litmaps) that differ from "
                                         "GL's, bit for bit (must be 0)")),
      litmap_fragment_diff_(stats().counter("litmap_fragment_diff", "draws",
                                            "with shadows.litmaps=model at the captured size: litmap and splat draws whose rasterized "
                                            "fragments differ from GL's counter (must be 0)")),
      litmap_discarded_(stats().counter("litmap_discarded", "fragments",
                                        "with shadows.litmaps=model: litmap fragments the reprojection test discarded (unseen by the observer)")),
      model_litmap_frames_(stats().counter("model_litmap_frames", "frames", "frames whose litmaps the model drew")),
      mask_errors_(stats().counter("mask_errors", "pixels",
                                   "shadow-mask pixels unlike the reference of the volumes drawn: GL's mode and infinite masks for "
                                   "GL's volumes (mask_diff + mask_diff_infinite), the model's own infinite volumes at the same planes "
                                   "for its own culled or clamped ones (own_mask_diff); 0 for the model's own infinite volumes, their "
                                   "own reference (must be 0)")) {
  if (config_.volumes != "trace") {
    own_mode_ = config_.volumes == "model" ? std::optional<Mode>(setup_.mode) : parse_mode(config_.volumes);
    if (!setup_.edge_rule)
      throw InputError(fmt::format("shadows.volumes={}: the model builds volumes with the paper's clamp rule (edge), and this trace was "
                                   "captured with clamp_rule caster, whose slabs need what the observer sees per object; capture it with "
                                   "--clamp-rule edge",
                                   config_.volumes));
  }
  own_litmaps_ = config_.litmaps == "model";
  if (other_size() && !own_litmaps_)
    throw InputError(fmt::format("shadows.litmap_size={}: the trace's litmaps are {}x{}; another size needs shadows.litmaps=model",
                                 setup_.litmap_size, setup_.trace_litmap_size, setup_.trace_litmap_size));
  if (other_size() && !own_mode_)
    throw InputError(fmt::format("shadows.litmap_size={}: GL's volumes belong to the captured {}x{} litmaps; another size needs the model's "
                                 "own volumes (shadows.volumes=infinite, culled or clamped)",
                                 setup_.litmap_size, setup_.trace_litmap_size, setup_.trace_litmap_size));
  NBSIM_CHECK(min_nb_.op() == FarOp::Min && max_nb_.op() == FarOp::Max, "the shadows program needs a min and a max N-buffer");
}

void ShadowsUnit::wait_all() {
  sim::blocking([&] {
    while (completed_ < issued_ || clears_ < frames_begun_) wait(completed_event_);
  });
  sim::catch_up(heard_cycle_);
}

void ShadowsUnit::depth_cleared(float) {
  heard_cycle_ = std::max(heard_cycle_, sim::local_cycles());
  ++clears_;
  completed_event_.notify(sc_core::SC_ZERO_TIME);
}

void ShadowsUnit::draw_finished(const cp::Work& w, const depth::DrawResult& r) {
  ++completed_;
  const scene::DrawRecord& d = w.record();
  if (d.role == kShadowVolumeRole) {
    FillShare* share = nullptr;
    if (w.own) {
      const auto it = own_share_.find(w.own.get());
      if (it != own_share_.end()) share = it->second;
    } else if (w.draw < volume_share_.size()) {
      share = volume_share_[w.draw];
    }
    if (share) ++share->volumes, share->fill += r.depth.fragments, share->gl_fill += d.gl.fragments;
    fill_ += r.depth.fragments;
    gl_fill_ += d.gl.fragments;
    stencil_tests_ += r.stencil.tests;
  } else if (d.role == scene::DrawRole::Scene) {
    scene_depth_tests_ += r.depth.depth_tests;
  }
  heard_cycle_ = std::max(heard_cycle_, r.done_cycle);
  completed_event_.notify(sc_core::SC_ZERO_TIME);
}

void ShadowsUnit::issue_role(const std::shared_ptr<const scene::Frame>& f, scene::DrawRole role, cp::CommandProcessor& cp) {
  for (std::size_t i = 0; i < f->draws.size(); ++i) {
    const scene::DrawRecord& d = f->draws[i];
    if (d.role != role || d.clip_positions.empty()) continue;
    auto w = std::make_shared<cp::Work>();
    w->frame = f;
    w->draw = static_cast<std::uint32_t>(i);
    ++issued_;
    if (role == kShadowVolumeRole) ++volume_draws_;
    cp.issue_draw(std::move(w));
  }
}

std::uint64_t ShadowsUnit::build(query::NBufferStructure& nb, const DepthImage& image) {
  // Every level of every texel from the new image (the litmaps are redrawn each frame).
  nbuffer::NBufferUnit& unit = nb.unit();
  std::uint64_t texels = unit.depth_changed(image, Rect{0, 0, image.width, image.height}).recomputed();
  texels += unit.end_of_pass().recomputed();
  return texels;
}

void ShadowsUnit::take_gl_litmaps(const scene::Frame& f) {
  for (const bool max : {false, true}) {
    const char* name = max ? "litmap_max" : "litmap_min";
    const scene::DepthSnapshot* s = f.depth(name);
    if (s->width != setup_.litmap_size || s->height != setup_.litmap_size)
      throw InputError(fmt::format("frame {}: the '{}' depth image is {}x{}, the trace's litmap_size {}", f.begin.frame, name, s->width,
                                   s->height, setup_.litmap_size));
    DepthImage& image = max ? gl_max_ : gl_min_;
    image.width = s->width, image.height = s->height;
    image.texels = s->texels;
  }
}

void ShadowsUnit::draw_own_litmaps(const scene::Frame& f, const FrameCasters& c) {
  const DepthImage sampled = sampled_depth_image(depth_, setup_.reference_path.depth_format);
  LitmapCounters k;
  own_ = draw_litmaps(f, *litmap_meshes_, light_of(c, f.begin.frame), setup_.litmap_size, setup_.reproject, sampled,
                      setup_.reference_path, !other_size(), k);
  label_with([&] { return fmt::format("litmap passes: {} fragments, {} splat points", k.fragments, k.splat_points); });
  work(sim::batch_cycles(k.fragments + k.splat_points, config_.litmap_fragments_per_cycle, 0));
  ++model_litmap_frames_;
  litmap_draws_ += k.draws;
  litmap_reprojections_ += k.fragments;
  litmap_discarded_ += k.discarded;
  receiver_splats_ += k.splat_fragments;
  litmap_fragment_diff_ += k.fragment_diff;
  if (other_size()) return;
  for (const bool max : {false, true}) {
    const scene::DepthSnapshot& gl = *f.depth(max ? "litmap_max" : "litmap_min");
    const DepthImage& mine = max ? own_.max : own_.min;
    if (gl.width != mine.width || gl.height != mine.height) {
      litmap_texel_diff_ += mine.texels.size();
      continue;
    }
    for (std::size_t i = 0; i < gl.texels.size(); ++i)
      litmap_texel_diff_ += std::bit_cast<std::uint32_t>(gl.texels[i]) != std::bit_cast<std::uint32_t>(mine.texels[i]) ? 1 : 0;
  }
}

void ShadowsUnit::query_casters(const scene::Frame& f, const FrameCasters& c, const LightDepth& light) {
  const std::size_t n = c.size();
  label_with([&] { return fmt::format("{} caster decisions", n); });
  work(sim::batch_cycles(n, config_.tests_per_cycle, config_.latency_cycles));
  rects_.clear(), nearest_.clear(), index_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const auto decision = static_cast<Decision>(c.decision[i]);
    outside_ += decision == Decision::OutsideLight ? 1 : 0;
    crossing_near_ += decision == Decision::CrossesNear ? 1 : 0;
    gl_culled_ += decision == Decision::Culled ? 1 : 0;
    if (other_size()) {  // the rectangle at the model's size, from the caster's bounds
      const CasterRect r = caster_rect(meshes_->bounds[i], light_of(c, f.begin.frame), setup_.litmap_size);
      if (r.decision != Decision::Volume) continue;
      index_.push_back(i);
      rects_.push_back(Rect{r.x, r.y, r.w, r.h});
      nearest_.push_back(0.0f);
      continue;
    }
    if (decision != Decision::Volume && decision != Decision::Culled) continue;
    index_.push_back(i);
    rects_.push_back(c.rect(i));
    nearest_.push_back(0.0f);  // the answer's value is what the program uses, not its hidden bit
  }
  // The two units' query ports work in parallel: the frame waits for the slower.
  min_nb_.unit().query_batch(rects_, nearest_, min_answers_);
  max_nb_.unit().query_batch(rects_, nearest_, max_answers_);
  NBSIM_CHECK(min_answers_.size() == index_.size() && max_answers_.size() == index_.size(),
              "an N-buffer answered another number of queries");
  casters_ += n;
  measured_ += index_.size();
  if (c.reference_fill) reference_fill_ += *c.reference_fill, ++reference_frames_;
  volume_share_.assign(f.draws.size(), nullptr);
  model_zmin_.assign(n, 1.0f), model_zmax_.assign(n, 0.0f);
  for (std::size_t i = 0; i < n && !own_mode_; ++i) {  // the model's own volumes count their casters by its own decisions
    FillShare& share = breakdown_[{c.class_names[c.cls[i]], std::string(kKeptNames[c.kept[i]])}];
    ++share.casters;
    share.fill_infinite += c.fill_infinite[i];
    if (c.draw[i] >= 0) volume_share_[static_cast<std::size_t>(c.draw[i])] = &share;
  }
  for (std::size_t k = 0; k < index_.size(); ++k) {
    const std::size_t i = index_[k];
    const nbuffer::QueryAnswer& lo = min_answers_[k];
    const nbuffer::QueryAnswer& hi = max_answers_[k];
    model_zmin_[i] = lo.value, model_zmax_[i] = hi.value;
    const auto texels = static_cast<std::uint32_t>(lo.lookups + hi.lookups);
    lookups_ += texels;
    build_texels_ += lo.update.recomputed() + hi.update.recomputed();  // lazy policy
    if (other_size()) {  // GL's per-caster record belongs to its own litmap size: the design against its own litmaps' lexels
      const DepthRange exact = exact_range(own_.min, own_.max, rects_[k]);  // off the clock
      not_conservative_ += lo.value > exact.z_min || hi.value < exact.z_max ? 1 : 0;
      unsafe_culls_ += litmap_rule_culls(lo.value, hi.value, c.caster_near[i], light, setup_.margin) &&
                               !litmap_rule_culls(exact.z_min, exact.z_max, c.caster_near[i], light, setup_.margin)
                           ? 1
                           : 0;
      continue;
    }
    lookup_mismatches_ += texels != c.lookups[i] ? 1 : 0;
    const DepthRange exact = exact_range(litmap(false), litmap(true), rects_[k]);  // off the clock
    const CasterCheck k2 = check_caster(c, i, lo.value, hi.value, exact, light, setup_.margin);
    culled_ += k2.model_culled ? 1 : 0;
    kept_by_slab_ += k2.kept_by_slab ? 1 : 0;
    decision_mismatches_ += k2.decision_mismatch ? 1 : 0;
    zmin_mismatches_ += k2.zmin_mismatch ? 1 : 0;
    zmax_mismatches_ += k2.zmax_mismatch ? 1 : 0;
    not_conservative_ += k2.not_conservative ? 1 : 0;
    unsafe_culls_ += k2.unsafe_cull ? 1 : 0;
    culls_lost_ += k2.cull_lost ? 1 : 0;
  }
}

void ShadowsUnit::compare_masks(const scene::Frame& f) {
  const auto image = [&](std::string_view name) -> const scene::StencilSnapshot& {
    const scene::StencilSnapshot* s = f.stencil(name);
    if (!s) throw InputError(fmt::format("frame {}: no '{}' stencil image: the shadow mask cannot be checked", f.begin.frame, name));
    if (s->width != setup_.width_px || s->height != setup_.height_px)
      throw InputError(fmt::format("frame {}: the '{}' stencil image is {}x{}, the viewport {}x{}", f.begin.frame, name, s->width,
                                   s->height, setup_.width_px, setup_.height_px));
    return *s;
  };
  const scene::StencilSnapshot& region = image("light_region");
  const scene::StencilSnapshot& mask = image("shadow_mask");
  const scene::StencilSnapshot& infinite = image("shadow_mask_infinite");
  std::uint64_t set = 0;
  stencil_checksum_ += crc32(0L, stencil_.texels.data(), static_cast<uInt>(stencil_.texels.size()));
  const std::uint64_t diff = mask_pixels_differing(stencil_.texels, region, mask, &set);
  const std::uint64_t diff_infinite = mask_pixels_differing(stencil_.texels, region, infinite);
  mask_diff_ += diff;
  mask_pixels_ += set;
  mask_diff_infinite_ += diff_infinite;
  if (!own_mode_) mask_errors_ += diff + diff_infinite;
  std::uint64_t gl_set = 0, gl_diff = 0;
  for (std::size_t i = 0; i < mask.texels.size(); ++i) {
    gl_set += mask.texels[i] != 0 ? 1 : 0;
    gl_diff += (mask.texels[i] != 0) != (infinite.texels[i] != 0) ? 1 : 0;
  }
  gl_mask_pixels_ += gl_set;
  gl_mask_diff_ += gl_diff;
  if (own_mode_ && *own_mode_ != Mode::Infinite && config_.own_reference) {
    // The model's own reference, off the clock: its infinite volumes into a cleared stencil over
    // this frame's depth (volumes write no depth), compared with its mode's mask.
    DepthImage depth = depth_;
    raster::StencilImage reference(stencil_.width, stencil_.height, 0);
    raster::RasterPath path(setup_.reference_path, depth, reference);
    const scene::DrawRecord d = volume_draw(0);
    raster::DrawState state = raster::draw_state(d.state);
    state.stencil = raster::stencil_state(d.stencil);
    path.draw(reference_clip_, state);
    std::uint64_t own = 0;
    for (std::size_t i = 0; i < reference.texels.size() && i < stencil_.texels.size(); ++i) {
      const bool lit = region.texels[i] != 0;
      own += (lit && reference.texels[i] != 0) != (lit && stencil_.texels[i] != 0) ? 1 : 0;
    }
    own_mask_diff_ += own;
    mask_errors_ += own;
  }
}

void ShadowsUnit::issue_model_volumes(const std::shared_ptr<const scene::Frame>& f, const FrameCasters& c, Mode mode,
                                      cp::CommandProcessor& cp) {
  const std::uint64_t frame = f->begin.frame;
  const LightFrustum light = light_of(c, frame);
  const glm::mat4 view_proj = observer_view_proj(f->begin);
  own_share_.clear();
  std::uint32_t own_index = static_cast<std::uint32_t>(f->draws.size());  // the model's volumes follow the trace's draws
  reference_clip_.clear();
  std::vector<glm::vec4> positions;
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (meshes_->meshes[i].object != c.object[i])
      throw InputError(fmt::format("frame {}: caster {} is object {} in ShadowCasters, {} in ShadowCasterMeshes", frame, i, c.object[i],
                                   meshes_->meshes[i].object));
    // The caster's rectangle from its bounds and the capture's light, against the record's.
    const CasterRect rect = caster_rect(meshes_->bounds[i], light, setup_.litmap_size);
    const auto recorded = static_cast<Decision>(c.decision[i]);
    const bool measured = recorded == Decision::Volume || recorded == Decision::Culled;
    if (!other_size())
      rect_mismatches_ += (measured ? rect.decision != Decision::Volume || rect.x != c.x[i] || rect.y != c.y[i] || rect.w != c.w[i] ||
                                          rect.h != c.h[i]
                                    : rect.decision != recorded)
                              ? 1
                              : 0;
    // Its decision and planes from the model's own answers.
    float clamp_near = 0.0f, clamp_far = std::numeric_limits<float>::infinity();
    bool dropped = rect.decision == Decision::OutsideLight;
    if (rect.decision == Decision::Volume) {
      const Planes p = slab_planes(rect.caster_near, rect.caster_far, light, model_zmin_[i], model_zmax_[i], setup_.margin, ClampRule::Edge);
      dropped = p.culled;
      if (other_size() && p.culled) ++culled_;  // (at the captured size, query_casters counts it)
      if (!p.culled) clamp_near = p.clamp_near, clamp_far = p.clamp_far;
    }
    // Its share of the fill: GL's reason, unless the model decided otherwise (it drops a caster GL
    // kept, or keeps one GL dropped: then for a receiver in its slab).
    const bool gl_dropped = c.kept[i] == static_cast<std::uint32_t>(KeptBy::Dropped);
    FillShare& share = breakdown_[{c.class_names[c.cls[i]],
                                   std::string(kKeptNames[dropped ? 0 : gl_dropped ? static_cast<std::size_t>(KeptBy::Receivers) : c.kept[i]])}];
    ++share.casters;
    share.fill_infinite += c.fill_infinite[i];
    if (mode != Mode::Infinite && config_.own_reference) {  // the reference: every caster's infinite volume at the same planes
      positions.clear();
      append_volume(meshes_->vertices, meshes_->meshes[i], light, volume_ends(clamp_near, clamp_far, false), positions);
      for (const glm::vec4& p : positions) reference_clip_.push_back(clip_position(view_proj, p));
    }
    if (mode != Mode::Infinite && dropped) continue;
    positions.clear();
    append_volume(meshes_->vertices, meshes_->meshes[i], light, volume_ends(clamp_near, clamp_far, mode == Mode::Clamped), positions);
    if (positions.empty()) continue;
    auto d = std::make_shared<scene::DrawRecord>(volume_draw(c.object[i]));
    // (Not the map's size: a finished draw's address may be reused for the next one, which then
    // replaces its entry, so the size would depend on the allocator.)
    d->index = own_index++;
    d->clip_positions.reserve(positions.size());
    for (const glm::vec4& p : positions) d->clip_positions.push_back(clip_position(view_proj, p));
    own_share_[d.get()] = &share;
    auto w = std::make_shared<cp::Work>();
    w->frame = f;
    w->draw = 0;
    w->own = std::move(d);
    ++issued_, ++volume_draws_, ++model_volumes_;
    cp.issue_draw(std::move(w));
  }
}

void ShadowsUnit::run_frame(const std::shared_ptr<const scene::Frame>& f, cp::CommandProcessor& cp) {
  ++frames_begun_;
  // Everything the frame needs is checked before anything is issued (a damaged trace: exit 2).
  const FrameCasters c = read_casters(*f);
  if (std::optional<CasterMeshes> m = read_caster_meshes(*f)) {
    if (m->meshes.size() != c.size())
      throw InputError(fmt::format("frame {}: the ShadowCasterMeshes record has {} casters, the ShadowCasters record {}", f->begin.frame,
                                   m->meshes.size(), c.size()));
    meshes_ = std::move(m);
  }
  if (own_mode_ && !meshes_)
    throw InputError(fmt::format("frame {}: shadows.volumes={} needs the casters' meshes (a ShadowCasterMeshes record in the trace's first "
                                 "frame): capture the trace again with this nbsim",
                                 f->begin.frame, config_.volumes));
  if (std::optional<LitmapMeshes> m = read_litmap_meshes(*f)) litmap_meshes_ = std::move(m);
  if (own_litmaps_ && !litmap_meshes_)
    throw InputError(fmt::format("frame {}: shadows.litmaps=model needs every object's mesh (a ShadowLitmapMeshes record in the trace's "
                                 "first frame): capture the trace again with this nbsim",
                                 f->begin.frame));
  if (static_cast<int>(c.litmap_size) != setup_.trace_litmap_size)
    throw InputError(fmt::format("frame {}: the ShadowCasters record's litmap_size {} is not the header's {}", f->begin.frame,
                                 c.litmap_size, setup_.trace_litmap_size));
  if (!f->light) throw InputError(fmt::format("frame {}: no light camera (LGHT)", f->begin.frame));
  const std::optional<LightDepth> light = LightDepth::make(*f->light);
  if (!light)
    throw InputError(fmt::format("frame {}: the light camera's projection is not a perspective frustum with near < far",
                                 f->begin.frame));
  for (const char* name : {"litmap_min", "litmap_max"})
    if (!f->depth(name))
      throw InputError(fmt::format("frame {}: no '{}' depth image: the {} N-buffer has nothing to be built from", f->begin.frame,
                                   name, std::string_view(name) == "litmap_min" ? "min" : "max"));
  for (const char* name : {"light_region", "shadow_mask", "shadow_mask_infinite"})
    if (!f->stencil(name))
      throw InputError(fmt::format("frame {}: no '{}' stencil image: the shadow mask cannot be checked", f->begin.frame, name));

  // 1. The observer's depth.
  issue_role(f, scene::DrawRole::Scene, cp);
  // 2. The litmap pass: the model's, once the observer's depth is done; or GL's images, whose
  //    reprojections are GL's fragment counts, as are the receiver splat's points.
  if (own_litmaps_) {
    wait_all();
    draw_own_litmaps(*f, c);
  } else {
    take_gl_litmaps(*f);
    for (const scene::DrawRecord& d : f->draws)
      if (d.role == kLitmapRole) ++litmap_draws_, litmap_reprojections_ += d.gl.fragments;
      else if (d.role == kReceiverSplatRole) receiver_splats_ += d.gl.fragments;
  }
  // 3. Both N-buffers from the litmaps (each unit's engine builds while the scene is drawn).
  build_texels_ += build(min_nb_, litmap(false));
  build_texels_ += build(max_nb_, litmap(true));
  // 4. The casters' queries and decisions (the query ports wait for their engines; a frame with no
  // caster to query still waits for both builds).
  query_casters(*f, c, *light);
  min_nb_.unit().drain();
  max_nb_.unit().drain();
  ++frames_;
  // 5. The volumes, after the scene's depth (the draws keep their order in the pipeline): GL's, or
  //    the model's own.
  if (own_mode_) issue_model_volumes(f, c, *own_mode_, cp);
  else issue_role(f, kShadowVolumeRole, cp);
  wait_all();
  // 6. The shadow mask from the model's stencil buffer.
  compare_masks(*f);
  cp.issue_snapshot(f, scene::DepthWhich::Final);
}

}  // namespace nbsim::shadows

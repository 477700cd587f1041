// The relief program's plain core; see replay.h.
#include "model/relief/replay.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <optional>
#include <span>

#include <zlib.h>

#include "model/common/error.h"
#include "model/relief/roles.h"

namespace nbsim::relief {

namespace {

raster::RasterPathConfig path_config(int width, int height, bool fused) {
  if (width < 1 || width > 16384 || height < 1 || height > 16384)
    throw InputError(fmt::format("the relief viewport is {}x{} pixels; each side must be 1 to 16384", width, height));
  raster::RasterPathConfig c;
  c.width_px = width;
  c.height_px = height;
  c.fused_interpolation = fused;
  return c;
}

// The second pass of a box draw that writes depth: the walk's misses discarded, the hits tested
// and written at the box's interpolated depth, or at their own (exact).
class KeepHits final : public raster::FragmentShader {
 public:
  KeepHits(const std::vector<std::uint8_t>& hit, const std::vector<float>* depth, int width) : hit_(hit), depth_(depth), width_(width) {}
  bool discards(int x, int y, float) const override { return hit_[at(x, y)] == 0; }
  std::optional<float> frag_depth(int x, int y) const override {
    if (!depth_) return std::nullopt;
    return (*depth_)[at(x, y)];
  }
  // Without depths of its own (the box's depth), a block's kept pixels at once: its hit bytes.
  std::optional<std::uint16_t> keep_block(int x, int y, std::uint16_t mask) const override {
    if (depth_) return std::nullopt;
    unsigned keep = 0;
    for (unsigned m = mask; m != 0; m &= m - 1) {
      const int i = std::countr_zero(m);
      keep |= (hit_[at(x + (i & 3), y + (i >> 2))] != 0 ? 1u : 0u) << i;
    }
    return static_cast<std::uint16_t>(keep);
  }

 private:
  std::size_t at(int x, int y) const noexcept { return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x); }
  const std::vector<std::uint8_t>& hit_;
  const std::vector<float>* depth_;
  int width_;
};

}  // namespace

TexelCache::TexelCache(const memory::CacheConfig& c) : cache_(c) {
  while ((1 << line_shift_) < c.line_bytes) ++line_shift_;
  // A lookup of its set's most recently used line is a hit that changes nothing in the LRU order,
  // so the walks count it without the cache (the same hits and misses). With no cache at all (0
  // bytes) every lookup misses; with fewer bytes than a set, a lookup of the line just before hits
  // and every other misses.
  merge_ = c.size_bytes > 0;
}

LineGeometry TexelCache::geometry() const {
  const memory::CacheConfig& c = cache_.config();
  return {line_shift_, static_cast<std::uint64_t>(c.size_bytes) / static_cast<std::uint64_t>(c.line_bytes * c.ways), merge_};
}

void TexelCache::invalidate() {
  cache_.invalidate();
  last_line_ = ~std::uint64_t{0};
}

// A run's lookups: virtual border texels were left out (a constant, no memory), and the lookups known
// to hit merged; the run's first line may repeat the last line of the run before.
void TexelCache::take(const LookupLines& run) {
  draw_hits += run.repeats();
  std::span<const std::uint64_t> lines = run.lines();
  if (lines.empty()) return;
  const std::uint64_t last = lines.back();
  if (merge_ && lines.front() == last_line_) ++draw_hits, lines = lines.subspan(1);
  const std::uint64_t hits = cache_.read_all(lines);
  draw_hits += hits;
  draw_misses += lines.size() - hits;
  last_line_ = last;
}

ReliefReplay::ReliefReplay(int width, int height, bool fused_interpolation, CoveringSpec covering, BoxDepth box_depth, int threads)
    : width_(width),
      height_(height),
      covering_(covering),
      box_depth_(box_depth),
      depth_(path_config(width, height, fused_interpolation).width_px, height, 1.0f),
      without_box_(width, height, 1.0f),
      passed_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0),
      path_(path_config(width, height, fused_interpolation), depth_),
      without_box_path_(path_config(width, height, fused_interpolation), without_box_),
      pool_(threads),
      level_marks_(static_cast<std::size_t>(pool_.threads())),
      scratch_(static_cast<std::size_t>(pool_.threads())) {
  path_.set_reuse_rasterization(true);  // every method draws the same box
  if (box_depth_ != BoxDepth::None) {
    for (std::vector<std::uint8_t>& h : hit_) h.assign(passed_.size(), 0);
    if (box_depth_ == BoxDepth::Exact)
      for (std::vector<float>& h : hit_depth_) h.assign(passed_.size(), 0.0f);
  }
}

// The level texels the walks read, computed by the frame's on-demand N-buffer of the heights (made
// at its first nbuffer draw, where a full build's texels are charged) and compared with the full
// build's: begun before a draw's walks, fed each run's newly read texels in run order while later
// runs are walked, and summed after them. Which texels an on-demand build computes, and so every
// count here, does not depend on the order the texels are asked for.
void ReliefReplay::begin_levels(const GlReliefField& gl, BoxDrawCounts& c) {
  const int n = gl.field.size;
  if (!on_demand_fresh_) {  // the frame's first nbuffer draw
    if (!on_demand_ || on_demand_->width() != n) {
      on_demand_.emplace(n, n, NBufferConfig{FarOp::Max, StorageFormat::F32, -1});
      on_demand_->set_on_demand(true);
    }
    DepthImage heights;
    heights.width = heights.height = n;
    heights.texels = gl.field.heights;
    on_demand_->replace_on_demand(heights);
    on_demand_fresh_ = true;
    c.levels_eager_texels = static_cast<std::uint64_t>(gl.levels - 1) * static_cast<std::uint64_t>(n) * static_cast<std::uint64_t>(n);
  }
  demand_ = on_demand_->new_stats();
  for (std::vector<std::uint8_t>& marks : level_marks_) marks.assign(gl.nbuffer.size(), 0);
  levels_checked_.assign(gl.nbuffer.size(), 0);
}

void ReliefReplay::run_levels(const GlReliefField& gl, std::span<const std::uint32_t> texels, BoxDrawCounts& c) {
  const std::size_t n = static_cast<std::size_t>(gl.field.size), plane = n * n;
  for (const std::uint32_t index : texels) {
    if (levels_checked_[index]) continue;  // read by another thread's runs too
    levels_checked_[index] = 1;
    const int level = static_cast<int>(index / plane);
    const int x = static_cast<int>(index % plane % n), y = static_cast<int>(index % plane / n);
    on_demand_->ensure(level, x, y, demand_);
    c.levels_on_demand_mismatches += std::bit_cast<std::uint32_t>(on_demand_->texel(level, x, y)) != std::bit_cast<std::uint32_t>(gl.nbuffer[index]);
  }
}

void ReliefReplay::end_levels(BoxDrawCounts& c) const {
  for (std::size_t l = 1; l < demand_.texels_recomputed.size(); ++l) c.levels_on_demand_texels += static_cast<std::uint64_t>(demand_.texels_recomputed[l]);
}

ReliefFrameCounts ReliefReplay::run_frame(const scene::Frame& f, double tolerance, double box_height, LookupSink* lookups,
                                          void* context, void (*draw_done)(void* context, const BoxDrawCounts& draw)) {
  const std::uint64_t pixels = static_cast<std::uint64_t>(width_) * static_cast<std::uint64_t>(height_);
  const bool writes = box_depth_ != BoxDepth::None;
  on_demand_fresh_ = false;  // the frame's heights are its own
  early_.valid = false;      // and its depth before the boxes
  std::fill(depth_.texels.begin(), depth_.texels.end(), 1.0f);  // the frame's depth buffer: the scene's, then tested by the boxes
  // Every box draw starts from the depth before the frame's first (box_depth.h).
  const auto restore = [&](std::size_t box) {
    if (box == 0) before_boxes_ = depth_.texels;
    else std::copy(before_boxes_.begin(), before_boxes_.end(), depth_.texels.begin());
    if (writes) std::copy(before_boxes_.begin(), before_boxes_.end(), without_box_.texels.begin());
  };
  // A box draw's early test against the depth before the frame's boxes (restored): its fragments
  // (after the test for none and box, every rasterized one for exact: the test waits for the
  // shader's depth) in fragment_pixels_, its counts in early_. No write: a box draw writes after its
  // walks.
  const auto early_test = [&](const scene::DrawRecord& d) {
    std::fill(passed_.begin(), passed_.end(), std::uint8_t{0});
    raster::DrawState s = raster::draw_state(d.state);
    s.depth.passed_mask = &passed_;
    s.depth.write = false;
    if (box_depth_ == BoxDepth::Exact) s.depth.test = false;
    early_.counts = path_.draw(d.clip_positions, s);
    fragment_pixels_.clear();
    std::uint32_t at = 0;
    for (; at + 8 <= pixels; at += 8) {  // eight pixels at a time: most of the viewport has no fragment
      std::uint64_t word;
      std::memcpy(&word, passed_.data() + at, sizeof word);
      if (word == 0) continue;
      for (std::uint32_t b = at; b < at + 8; ++b)
        if (passed_[b] != 0) fragment_pixels_.push_back(b);
    }
    for (; at < pixels; ++at)
      if (passed_[at] != 0) fragment_pixels_.push_back(at);
    early_.valid = true;
    early_.state = d.state;
    early_.positions = d.clip_positions;
  };
  // The frame's records are read and checked on a helper while this thread tests the frame's first
  // draw early, when that is a box draw (the usual frame: no scene under the boxes; the depth is then
  // the cleared one, the depth before the boxes, which the loop saves); the loop below then finds
  // that draw's test done, as for the box draws after it.
  GlReliefField gl;
  std::vector<GlReliefFragments> records;
  std::optional<GlReliefDepth> gl_depth;
  const scene::DrawRecord* first_box = nullptr;
  if (!f.draws.empty()) {
    const scene::DrawRecord& d = f.draws.front();
    if (d.role == kReliefBoxRole && d.topology == scene::Topology::Triangles && d.clip_positions.size() % 3 == 0) first_box = &d;
  }
  pool_.run(
      1,
      [&](std::size_t) {
        gl = read_relief_field(f);
        records = read_relief_fragments(f, pixels);
        gl_depth = read_relief_depth(f, writes);
      },
      [](std::size_t) {},
      first_box ? std::function<void()>([&] { early_test(*first_box); }) : std::function<void()>());
  const FieldView view = gl.view();
  std::optional<ReferenceBlocks> blocks;
  if (scoring_) blocks.emplace(gl.field);
  WalkParams params = gl.params;  // the record's tunables with the capture's covering
  params.covering = covering_;
  reference_.resize(pixels);
  rays_.resize(pixels);
  pixel_state_.assign(pixels, kPixelUnknown);
  ReliefFrameCounts out;
  out.size = gl.field.size;
  for (const float r : gl.radius.radius) out.radius_sum += static_cast<std::uint64_t>(r), out.radius_zero += r == 0.0f ? 1 : 0;
  out.view_angle = gl.view_angle;

  std::size_t next_record = 0, box_draw = 0;
  // A box draw's counts are handed on once the scene draws after it are counted too.
  std::optional<BoxDrawCounts> open;
  const auto close = [&] {
    if (!open) return;
    if (draw_done) draw_done(context, *open);
    out.draws.push_back(*open);
    open.reset();
  };
  // A box draw's write (its hits into the depth buffer, checked against GL's), left pending after
  // its walks so that it can run beside the next box draw's walks when nothing between them needs
  // it (the next draw is a box draw whose early test is this one's); then the draw is open.
  struct PendingWrite {
    const scene::DrawRecord* draw;
    BoxDrawCounts counts;
    std::size_t box;  // the box draw's index in the frame
  };
  std::optional<PendingWrite> pending;
  const auto write_pending = [&] {
    if (!pending) return;
    BoxDrawCounts& c = pending->counts;
    if (writes) {  // the write: the hits at the box's depth (early test, late write) or at their own
      raster::DrawState keep = raster::draw_state(pending->draw->state);
      std::vector<std::uint8_t>& hit = hit_[pending->box % 2];
      const KeepHits shader(hit, box_depth_ == BoxDepth::Exact ? &hit_depth_[pending->box % 2] : nullptr, width_);
      keep.depth.shader = &shader;
      const raster::DrawCounters w = path_.draw(pending->draw->clip_positions, keep);
      c.samples = w.depth.passed;
      c.depth_written = w.depth.written;
      if (box_depth_ == BoxDepth::Exact) c.depth_tests = w.depth.depth_tests;
      for (const std::uint32_t px : fragment_pixels_) hit[px] = 0;  // only walked pixels were set (the next draw walks the same)
      const std::uint32_t crc = static_cast<std::uint32_t>(
          crc32(0L, reinterpret_cast<const Bytef*>(depth_.texels.data()), static_cast<uInt>(depth_.texels.size() * sizeof(float))));
      c.depth_mismatches = crc != gl_depth->depth_crc[pending->box] ? 1 : 0;
    }
    open = c;
    pending.reset();
  };
  for (const scene::DrawRecord& d : f.draws) {
    if (d.role == scene::DrawRole::Scene) {  // boxes in a scene: its depth, drawn before and after the boxes
      if (d.topology != scene::Topology::Triangles || d.clip_positions.size() % 3 != 0)
        throw InputError(fmt::format("frame {}: scene draw {} is not a list of triangles", f.begin.frame, d.index));
      write_pending();
      const raster::DrawState s = raster::draw_state(d.state);
      const raster::DrawCounters k = path_.draw(d.clip_positions, s);
      out.scene_depth_tests += k.depth.depth_tests;
      ++out.scene_draws;
      out.scene_mismatches += k.depth.passed != d.gl.samples_passed ? 1 : 0;
      if (open) {
        ++open->scene_after_draws;
        open->scene_after_samples += k.depth.passed;
        if (writes) open->scene_hidden += without_box_path_.draw(d.clip_positions, s).depth.passed - k.depth.passed;
      }
      continue;
    }
    if (d.role != kReliefBoxRole) continue;
    if (d.topology != scene::Topology::Triangles || d.clip_positions.size() % 3 != 0)
      throw InputError(fmt::format("frame {}: relief_box draw {} is not a list of triangles", f.begin.frame, d.index));
    if (next_record >= records.size() || records[next_record].draw != d.index)
      throw InputError(fmt::format("frame {}: relief_box draw {} has no ReliefFragments (RLFF) record in draw order", f.begin.frame, d.index));
    const GlReliefFragments& r = records[next_record++];
    const std::size_t box = box_draw++;

    // The walk's fragments (early_test). Every box draw tests against the same depth (the frame's
    // before its boxes), so a draw bit-identical to the frame's box draw before it (the methods draw
    // the same box) has its fragments and counts.
    const bool same_as_before = early_.valid && early_.state == d.state && early_.positions.size() == d.clip_positions.size() &&
                                std::memcmp(early_.positions.data(), d.clip_positions.data(),
                                            d.clip_positions.size() * sizeof(d.clip_positions[0])) == 0;
    // The box draw before's write and hand-on, then this draw's depth: now, or beside the walks.
    const bool beside = same_as_before && pending.has_value();
    const auto before_walks = [&] {
      write_pending();
      close();
      restore(box);
    };
    if (!beside) before_walks();
    if (!same_as_before) early_test(d);
    const raster::DrawCounters& k = early_.counts;

    BoxDrawCounts c;
    c.method = r.method;
    c.scored = scoring_;
    c.storage_bytes = storage_bytes(r.method, gl.field.size, gl.levels);
    c.triangles = k.geometry.prims_out;
    c.blocks = k.depth.blocks;
    c.depth_tests = k.depth.depth_tests;
    c.fragments = k.depth.passed;
    c.rasterized = k.depth.fragments;
    c.gl_fragments = d.gl.fragments;
    c.gl_samples = d.gl.samples_passed;
    // The fragments' walks, scores and comparison with GL's (every pixel's reference computed at most
    // once a frame), in parallel runs of consecutive fragments; each run's lookups go to `lookups` in
    // pixel order, and its counts are added to the draw's in order.
    const std::size_t run_count = (fragment_pixels_.size() + kRunFragments - 1) / kRunFragments;
    if (runs_.size() < run_count) runs_.resize(run_count), tallies_.resize(run_count);
    const LineGeometry geometry = lookups ? lookups->geometry() : LineGeometry{};
    // The N-buffer walk's level reads, marked by the walks, then computed on demand.
    const bool levels = r.method == Method::NBuffer && lookups;
    if (levels) begin_levels(gl, c);
    // This draw's hits (the draw before may still be writing its own, beside these walks).
    std::vector<std::uint8_t>& hit = hit_[box % 2];
    std::vector<float>& hit_depths = hit_depth_[box % 2];
    const auto walk_run = [&](std::size_t run) {
      LookupLines& lines = runs_[run];
      if (lookups) lines.reset(geometry);
      lines.mark_levels(levels ? level_marks_[static_cast<std::size_t>(WorkerPool::slot())].data() : nullptr);
      const std::size_t begin = run * kRunFragments, end = std::min(fragment_pixels_.size(), begin + kRunFragments);
      RunScratch& scratch = scratch_[static_cast<std::size_t>(WorkerPool::slot())];
      scratch.rays.clear();
      scratch.fragments.clear();
      for (std::size_t at = begin; at < end; ++at) {
        const std::uint32_t px = fragment_pixels_[at];
        std::uint8_t& state = pixel_state_[px];
        if (state == kPixelUnknown) {  // the pixel's first walk this frame: its ray (and, below, its reference)
          const float fx = static_cast<float>(px % static_cast<std::uint32_t>(width_)) + 0.5f;
          const float fy = static_cast<float>(px / static_cast<std::uint32_t>(width_)) + 0.5f;
          const std::optional<FragmentRay> ray = fragment_ray(gl.ray, gl.field.size, fx, fy);
          state = ray ? kPixelRay : kPixelNoRay;
          if (ray) rays_[px] = *ray;
        }
        if (state == kPixelNoRay) continue;
        scratch.rays.push_back(&rays_[px]);
        scratch.fragments.push_back(at);
      }
      scratch.results.resize(scratch.rays.size());
      walk_each(r.method, view, params, scratch.rays, scratch.results, lookups ? &lines : nullptr);
      // The run's fragments against GL's: the two sorted pixel lists merged over the run's share of
      // the viewport, from its first pixel (0 for the first run) to the next run's first (the end of
      // the viewport for the last), so that the runs' counts add up to one merge of the whole lists.
      Tally& tally = tallies_[run];
      tally.counts = BoxDrawCounts{};
      tally.distances.clear();
      BoxDrawCounts& t = tally.counts;
      const auto gl_at = [&](std::uint32_t px) {
        return static_cast<std::size_t>(std::lower_bound(r.pixel.begin(), r.pixel.end(), px) - r.pixel.begin());
      };
      std::size_t g = run == 0 ? 0 : gl_at(fragment_pixels_[begin]);
      const std::size_t g_end = end == fragment_pixels_.size() ? r.pixel.size() : gl_at(fragment_pixels_[end]);
      std::size_t q = 0;  // the next walked fragment in scratch
      for (std::size_t at = begin; at < end; ++at) {
        const std::uint32_t px = fragment_pixels_[at];
        while (g < g_end && r.pixel[g] < px) ++t.pixel_mismatches, ++g;  // GL's alone
        const bool in_gl = g < g_end && r.pixel[g] == px;
        const bool walked = q < scratch.fragments.size() && scratch.fragments[q] == at;
        const WalkResult w = walked ? scratch.results[q++] : WalkResult{};
        const std::uint32_t code = w.capped ? 2u : w.hit ? 1u : 0u;
        if (writes) hit[px] = code == 1u ? 1 : 0;
        t.lookups += w.lookups, t.steps += w.steps, t.bisections += w.bisections;
        t.longest_walk = std::max<std::uint64_t>(t.longest_walk, w.lookups);
        t.hits += code == 1u, t.capped += code == 2u, t.samples += code == 1u;
        if (walked) {
          const FragmentRay& ray = rays_[px];
          if (box_depth_ == BoxDepth::Exact && code == 1u) hit_depths[px] = hit_depth(gl_depth->texel_to_clip, ray, w.t);
          if (scoring_) {
            std::uint8_t& state = pixel_state_[px];
            if (state == kPixelRay) reference_[px] = reference_of(gl.field, ray, &*blocks), state = kPixelReference;
            const HitScore score = score_against(reference_[px], ray, gl.field.size, w.hit && !w.capped, w.t, box_height, tolerance);
            t.reference_hits += score.reference_hit;
            t.wrong_hit += score.error == HitError::WrongHit;
            t.wrong_miss += score.error == HitError::WrongMiss;
            t.far_hit += score.error == HitError::FarHit;
            if (code == 1u && score.reference_hit) tally.distances.push_back(score.distance);  // summed in order by the draw
          }
        }
        if (!in_gl) {  // the model's alone
          ++t.pixel_mismatches;
          continue;
        }
        t.gl_lookups += r.lookups[g];
        const bool same = code == r.hit[g] && std::memcmp(&w.t, &r.t[g], sizeof(float)) == 0 && w.lookups == r.lookups[g] &&
                          w.steps == r.steps[g] && w.bisections == r.bisections[g];
        t.walk_mismatches += same ? 0 : 1;
        ++g;
      }
      t.pixel_mismatches += g_end - g;  // GL's alone up to the next run's share
    };
    // The runs' lookups and counts handed on in order on this thread while the workers walk the runs
    // after them.
    const auto add_run = [&](std::size_t run) {
      if (lookups) lookups->take(runs_[run]);
      if (levels) run_levels(gl, runs_[run].level_texels(), c);
      const Tally& tally = tallies_[run];
      const BoxDrawCounts& t = tally.counts;
      c.pixel_mismatches += t.pixel_mismatches, c.walk_mismatches += t.walk_mismatches;
      c.lookups += t.lookups, c.steps += t.steps, c.bisections += t.bisections, c.gl_lookups += t.gl_lookups;
      c.longest_walk = std::max(c.longest_walk, t.longest_walk);
      c.hits += t.hits, c.capped += t.capped, c.samples += t.samples;
      c.reference_hits += t.reference_hits, c.wrong_hit += t.wrong_hit, c.wrong_miss += t.wrong_miss, c.far_hit += t.far_hit;
      for (const double distance : tally.distances) c.distance_sum += distance;
    };
    pool_.run(run_count, walk_run, add_run, beside ? std::function<void()>(before_walks) : std::function<void()>());
    if (run_count == 0) c.pixel_mismatches += r.pixel.size();  // GL's alone
    if (levels) end_levels(c);
    pending = PendingWrite{&d, c, box};
  }
  write_pending();
  close();
  if (next_record != records.size())
    throw InputError(fmt::format("frame {}: {} ReliefFragments (RLFF) records, but {} relief_box draws", f.begin.frame, records.size(),
                                 next_record));
  return out;
}

}  // namespace nbsim::relief

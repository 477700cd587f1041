// The apps program's plain core; see replay.h.
#include "model/apps/replay.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "model/apps/draw_flags.h"
#include "model/common/error.h"
#include "model/cull/primitive.h"
#include "model/scene/technique_record.h"

namespace nbsim::apps {

namespace {

using namespace flags;

// The record types (traces/format/apps/apps_chunk.h).
constexpr std::uint32_t kDrawsType = scene::record_type("APDS"), kClearsType = scene::record_type("APCL"),
                        kChangeType = scene::record_type("APDC"), kFrameType = scene::record_type("APFR");
constexpr const char* kDrawsLabel = "AppDraws (APDS)";
constexpr const char* kClearsLabel = "AppClears (APCL)";
constexpr const char* kChangeLabel = "AppDepthChange (APDC)";
constexpr const char* kFrameLabel = "AppFrame (APFR)";

constexpr std::uint32_t kGlPoints = 0x0000, kGlLines = 0x0001, kGlTriangles = 0x0004, kGlFill = 0x1B02;

constexpr std::array<std::string_view, kReasons> kReasonNames = {
    "replayed", "not_captured", "points",   "lines",    "discard",      "frag_depth", "polygon_offset", "polygon_mode",
    "multisample", "viewport",  "depth_range", "scissor", "depth_format", "non_finite", "no_target",
    "clip_distance"};

// The frame's AppDraws fields, each checked to have one value per draw.
struct DrawFields {
  const std::vector<std::uint32_t> *skipped, *primitive, *flags, *framebuffer, *width, *height, *bits, *is_float, *polygon_mode;
  const std::vector<std::int32_t> *vx, *vy, *vw, *vh, *sx, *sy, *sw, *sh;
  const std::vector<float> *near, *far, *factor, *units;
};

DrawFields draw_fields(const scene::TechniqueRecord& r, std::size_t draws, std::uint64_t frame) {
  DrawFields d{};
  const auto u = [&](const char* name) {
    const auto& v = scene::record_field<std::uint32_t>(r, name, kDrawsLabel, frame);
    if (v.size() != draws) throw InputError(fmt::format("frame {}: the {} record's '{}' has {} values for {} draws", frame, kDrawsLabel, name, v.size(), draws));
    return &v;
  };
  const auto i = [&](const char* name) {
    const auto& v = scene::record_field<std::int32_t>(r, name, kDrawsLabel, frame);
    if (v.size() != draws) throw InputError(fmt::format("frame {}: the {} record's '{}' has {} values for {} draws", frame, kDrawsLabel, name, v.size(), draws));
    return &v;
  };
  const auto f = [&](const char* name) {
    const auto& v = scene::record_field<float>(r, name, kDrawsLabel, frame);
    if (v.size() != draws) throw InputError(fmt::format("frame {}: the {} record's '{}' has {} values for {} draws", frame, kDrawsLabel, name, v.size(), draws));
    return &v;
  };
  d.skipped = u("skipped"), d.primitive = u("primitive"), d.flags = u("flags"), d.framebuffer = u("framebuffer");
  d.width = u("target_width"), d.height = u("target_height"), d.bits = u("depth_bits"), d.is_float = u("depth_float");
  d.polygon_mode = u("polygon_mode");
  d.vx = i("viewport_x"), d.vy = i("viewport_y"), d.vw = i("viewport_w"), d.vh = i("viewport_h");
  d.sx = i("scissor_x"), d.sy = i("scissor_y"), d.sw = i("scissor_w"), d.sh = i("scissor_h");
  d.near = f("depth_near"), d.far = f("depth_far"), d.factor = f("offset_factor"), d.units = f("offset_units");
  return d;
}

// The first reason the model cannot redo draw `k` exactly.
Reason reason_of(const DrawFields& d, std::size_t k, const scene::DrawRecord& draw, std::optional<raster::DepthFormat> format,
                 bool ignore_discard = false) {
  const std::uint32_t fl = (*d.flags)[k];
  const int w = static_cast<int>((*d.width)[k]), h = static_cast<int>((*d.height)[k]);
  if ((*d.skipped)[k] != 0 || (fl & kOverflow)) return Reason::NotCaptured;
  if ((*d.primitive)[k] == kGlPoints) return Reason::Points;
  if ((*d.primitive)[k] == kGlLines) return Reason::Lines;
  if ((*d.primitive)[k] != kGlTriangles) return Reason::NotCaptured;
  if (w <= 0 || h <= 0) return Reason::NoTarget;
  if (!ignore_discard && (fl & (kDiscards | kAlphaTest))) return Reason::Discard;
  if (fl & kWritesDepth) return Reason::FragDepth;
  if ((fl & kPolygonOffsetFill) && ((*d.factor)[k] != 0.0f || (*d.units)[k] != 0.0f)) return Reason::PolygonOffset;
  if ((fl & kPolygonModeNotFill) || (*d.polygon_mode)[k] != kGlFill) return Reason::PolygonMode;
  if (fl & kMultisample) return Reason::Multisample;
  if (fl & kClipDistance) return Reason::ClipDistance;
  if ((*d.vx)[k] != 0 || (*d.vy)[k] != 0 || (*d.vw)[k] != w || (*d.vh)[k] != h) return Reason::Viewport;
  if ((*d.near)[k] != 0.0f || (*d.far)[k] != 1.0f) return Reason::DepthRange;
  if ((fl & kScissor) && ((*d.sx)[k] > 0 || (*d.sy)[k] > 0 || (*d.sx)[k] + (*d.sw)[k] < w || (*d.sy)[k] + (*d.sh)[k] < h))
    return Reason::Scissor;
  if ((*d.bits)[k] != 0 && !format) return Reason::DepthFormat;
  for (const auto& p : draw.clip_positions)
    for (const float c : p)
      if (!std::isfinite(c)) return Reason::NonFinite;
  return Reason::Replayed;
}

// The format the model stores a target's depth in, or none (no depth buffer: Float32 then, unused).
std::optional<raster::DepthFormat> format_of(std::uint32_t bits, bool is_float) {
  if (bits == 0 || (bits == 32 && is_float)) return raster::DepthFormat::Float32;
  if (bits == 24) return raster::DepthFormat::Unorm24;
  return std::nullopt;
}

// The depth a clear of `z` leaves (llvmpipe packs a Z24 clear value by truncation, u_pack_color.h).
float cleared_depth(raster::DepthFormat format, float z) {
  if (format != raster::DepthFormat::Unorm24) return z;
  if (z >= 1.0f) return raster::from_unorm24(0xFFFFFFu);
  if (z <= 0.0f) return 0.0f;
  return raster::from_unorm24(static_cast<std::uint32_t>(static_cast<double>(z) * 16777215.0));
}

constexpr std::array<std::string_view, kUntested> kUntestedNames = {"tested", "flagged", "other_target", "stale", "depth_func",
                                                                   "stencil_writes", "no_triangles"};

// Whether a draw's depth func fails wherever the buffer holds a nearer-or-equal depth under `op`,
// so that a rectangle found hidden holds no fragment that passes.
bool fails_behind(scene::DepthFunc f, FarOp op) {
  if (op == FarOp::Max) return f == scene::DepthFunc::Less || f == scene::DepthFunc::Lequal;
  return f == scene::DepthFunc::Greater || f == scene::DepthFunc::Gequal;
}

}  // namespace

std::string_view to_string(Untested u) noexcept {
  const auto i = static_cast<std::size_t>(u);
  return i < kUntestedNames.size() ? kUntestedNames[i] : "?";
}

query::Answer full_depth_query(const DepthImage& depth, const Rect& r, float nearest, FarOp op) noexcept {
  query::Answer a;
  a.lookups = static_cast<std::uint64_t>(r.area());
  a.hidden = true;
  for (int y = r.y; y < r.y1() && a.hidden; ++y) {
    const float* row = depth.texels.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(depth.width);
    for (int x = r.x; x < r.x1(); ++x)
      if (op == FarOp::Max ? !(nearest > row[x]) : !(nearest < row[x])) {
        a.hidden = false;
        break;
      }
  }
  return a;
}

void AppsReplay::touched(Target& t, const Rect& r) {
  if (!cull_.tester || mirrored_ != &t || r.empty()) return;
  cull_.tester->changed(t.depth, r);
  t.tester_dirty = true;
}

bool AppsReplay::cull_test(Target& t, const scene::DrawRecord& draw, AppDrawCounts& c, std::vector<char>& skip) {
  DrawTester& tester = *cull_.tester;
  if (mirrored_ != &t) {
    tester.rebuild(t.depth);
    mirrored_ = &t;
    t.tester_dirty = true;
  }
  // The draw's bounds and its triangles' (per-primitive), from setup, as the path will draw them.
  const raster::DrawState s = draw_state_of(t, draw, true);
  rects_.clear(), nearest_.clear();
  Rect box{};
  float nearest = cull_.op == FarOp::Max ? 1.0f : 0.0f;
  bool bounded = true;
  int x0 = t.width, y0 = t.height, x1 = 0, y1 = 0;
  t.path->setup_only(draw.clip_positions, s, [&](const geometry::WindowTriangle& w, const raster::SetupTriangle& st) {
    const cull::PrimitiveQuery q = cull::primitive_query(w, st, cull_.op, cull_.fused_interpolation);
    if (!q.testable) {  // no depth bound: the draw cannot be culled, nor this triangle
      if (!q.rect.empty()) x0 = 0, y0 = 0, x1 = t.width, y1 = t.height;
      bounded = false;
      rects_.push_back(Rect{}), nearest_.push_back(0.0f);
      return;
    }
    const float z = raster::stored_depth(t.format, q.nearest);  // monotone: still no fragment nearer
    x0 = std::min(x0, q.rect.x), y0 = std::min(y0, q.rect.y), x1 = std::max(x1, q.rect.x1()), y1 = std::max(y1, q.rect.y1());
    nearest = cull_.op == FarOp::Max ? std::min(nearest, z) : std::max(nearest, z);
    rects_.push_back(q.rect), nearest_.push_back(z);
  });
  if (rects_.empty()) {
    c.untested = Untested::NoTriangles;
    return false;
  }
  c.untested = Untested::Tested;
  if (x1 > x0 && y1 > y0) box = Rect{x0, y0, x1 - x0, y1 - y0};
  if (t.tester_dirty) {
    tester.prepare(t.depth);
    t.tester_dirty = false;
  }
  if (bounded && !box.empty()) {
    tester.query(t.depth, std::span<const Rect>(&box, 1), std::span<const float>(&nearest, 1), answers_);
    c.query_lookups = answers_.front().lookups;
    if (answers_.front().hidden) {
      c.culled = true;
      return true;
    }
  }
  if (!cull_.primitives) return false;
  // Each triangle with a bound, as one batch: rects_ and nearest_ compacted to those, index_ the
  // triangle each came from.
  skip.assign(rects_.size(), 0);
  index_.clear();
  for (std::size_t i = 0; i < rects_.size(); ++i)
    if (!rects_[i].empty()) rects_[index_.size()] = rects_[i], nearest_[index_.size()] = nearest_[i], index_.push_back(i);
  if (index_.empty()) return false;
  rects_.resize(index_.size()), nearest_.resize(index_.size());
  tester.query(t.depth, rects_, nearest_, answers_);
  c.primitive_tests = index_.size();
  for (std::size_t j = 0; j < answers_.size(); ++j) {
    c.primitive_lookups += answers_[j].lookups;
    if (answers_[j].hidden) skip[index_[j]] = 1, ++c.primitives_culled;
  }
  return false;
}

std::string_view to_string(Reason r) noexcept {
  const auto i = static_cast<std::size_t>(r);
  return i < kReasonNames.size() ? kReasonNames[i] : "?";
}

AppsReplay::Target& AppsReplay::target(std::uint32_t fb, int width, int height, raster::DepthFormat format, bool has_depth) {
  Target& t = targets_[fb];
  if (t.path && t.width == width && t.height == height && t.format == format) return t;
  if (mirrored_ == &t) mirrored_ = nullptr;  // remade: the tester rebuilds from it before its next query
  t.width = width, t.height = height, t.format = format;
  t.depth = DepthImage(width, height, 1.0f);
  t.stencil = raster::StencilImage(width, height, 0);
  raster::RasterPathConfig c;
  c.width_px = width;
  c.height_px = height;
  c.depth_format = format;
  c.window_framebuffer = fb == 0;  // drawn upside down with the bottom-edge rule (replay.h)
  t.path = std::make_unique<raster::RasterPath>(c, t.depth, t.stencil);
  t.flipped = fb == 0;
  // Its content before the first clear is GL's, unknown to the model; a target without a depth
  // buffer has none to know.
  t.stale = has_depth;  // its content before the first clear is GL's, not known to the model
  return t;
}

raster::DrawCounters AppsReplay::replay(Target& t, const scene::DrawRecord& draw, bool has_depth, std::span<const char> skip) {
  const raster::DrawCounters k = replay_untold(t, draw, has_depth, skip);
  touched(t, t.path->written_box());
  return k;
}

raster::DrawState AppsReplay::draw_state_of(const Target& t, const scene::DrawRecord& draw, bool has_depth) {
  raster::DrawState s = raster::draw_state(draw.state);
  if (!draw.state.test) s.depth.write = false;  // GL writes depth only with the test on
  if (!has_depth) s.depth.test = false, s.depth.write = false;  // no depth buffer: every fragment passes
  s.stencil = raster::stencil_state(draw.stencil);
  if (t.flipped) s.geometry.face.front_ccw = !s.geometry.face.front_ccw;  // the winding mirrors with the rows
  return s;
}

raster::DrawCounters AppsReplay::replay_untold(Target& t, const scene::DrawRecord& draw, bool has_depth, std::span<const char> skip) {
  return t.path->draw(draw.clip_positions, draw_state_of(t, draw, has_depth), skip);
}

bool AppsReplay::same_change(const Target& t, const std::vector<float>& before, const scene::TechniqueRecord& change, std::uint64_t frame,
                             std::size_t k) const {
  const auto& pixel = scene::record_field<std::uint32_t>(change, "pixel", kChangeLabel, frame);
  const auto& depth = scene::record_field<float>(change, "depth", kChangeLabel, frame);
  if (pixel.size() != depth.size()) throw InputError(fmt::format("frame {}: the {} record of draw {} has {} pixels and {} depths", frame, kChangeLabel, k, pixel.size(), depth.size()));
  std::size_t changed = 0;
  for (std::size_t i = 0; i < t.depth.texels.size(); ++i) {
    const std::size_t at = t.stored(i);  // i: GL's read-back index
    if (std::memcmp(&t.depth.texels[at], &before[at], sizeof(float)) == 0) continue;
    if (changed >= pixel.size() || pixel[changed] != i || std::memcmp(&depth[changed], &t.depth.texels[at], sizeof(float)) != 0) return false;
    ++changed;
  }
  return changed == pixel.size();
}

AppFrameCounts AppsReplay::run_frame(const scene::Frame& f) {
  const std::uint64_t frame = f.begin.frame;
  AppFrameCounts out;
  const std::size_t n = f.draws.size();
  const scene::TechniqueRecord& draws_rec = scene::single_record(f, kDrawsType, kDrawsLabel, "an apps frame has one (nbsim capture apitrace writes it)");
  const scene::TechniqueRecord& clears_rec = scene::single_record(f, kClearsType, kClearsLabel, "an apps frame has one");
  const scene::TechniqueRecord& frame_rec = scene::single_record(f, kFrameType, kFrameLabel, "an apps frame has one");
  if (scene::record_scalar<std::uint64_t>(draws_rec, "count", kDrawsLabel, frame) != n)
    throw InputError(fmt::format("frame {}: the {} record counts {} draws, the frame has {}", frame, kDrawsLabel,
                                 scene::record_scalar<std::uint64_t>(draws_rec, "count", kDrawsLabel, frame), n));
  const DrawFields d = draw_fields(draws_rec, n, frame);
  // The clears, in order.
  const auto& before = scene::record_field<std::uint32_t>(clears_rec, "before_draw", kClearsLabel, frame);
  const auto& clear_fb = scene::record_field<std::uint32_t>(clears_rec, "framebuffer", kClearsLabel, frame);
  const auto& buffers = scene::record_field<std::uint32_t>(clears_rec, "buffers", kClearsLabel, frame);
  const auto& clear_flags = scene::record_field<std::uint32_t>(clears_rec, "flags", kClearsLabel, frame);
  const auto& stencil_mask = scene::record_field<std::uint32_t>(clears_rec, "stencil_write_mask", kClearsLabel, frame);
  const auto& csx = scene::record_field<std::int32_t>(clears_rec, "scissor_x", kClearsLabel, frame);
  const auto& csy = scene::record_field<std::int32_t>(clears_rec, "scissor_y", kClearsLabel, frame);
  const auto& csw = scene::record_field<std::int32_t>(clears_rec, "scissor_w", kClearsLabel, frame);
  const auto& csh = scene::record_field<std::int32_t>(clears_rec, "scissor_h", kClearsLabel, frame);
  const auto& stencil_value = scene::record_field<std::int32_t>(clears_rec, "stencil", kClearsLabel, frame);
  const auto& depth_value = scene::record_field<float>(clears_rec, "depth", kClearsLabel, frame);
  const std::size_t clears = before.size();
  for (const std::size_t size : {clear_fb.size(), buffers.size(), clear_flags.size(), stencil_mask.size(), csx.size(), csy.size(), csw.size(),
                                 csh.size(), stencil_value.size(), depth_value.size()})
    if (size != clears) throw InputError(fmt::format("frame {}: the {} record's fields have different lengths", frame, kClearsLabel));
  // Depth changes by draw.
  std::vector<const scene::TechniqueRecord*> change(n, nullptr);
  for (const scene::TechniqueRecord& r : f.technique_records) {
    if (r.type != kChangeType) continue;
    const std::uint64_t k = scene::record_scalar<std::uint64_t>(r, "draw", kChangeLabel, frame);
    if (k >= n || change[k]) throw InputError(fmt::format("frame {}: an {} record of draw {} (the frame has {} draws)", frame, kChangeLabel, k, n));
    change[k] = &r;
  }
  // The size and format each framebuffer's draws report (clears take them from there).
  struct Known {
    int width, height;
    raster::DepthFormat format;
    bool has_depth;
  };
  std::map<std::uint32_t, Known> known;
  for (std::size_t k = 0; k < n; ++k)
    if (const auto fmt = format_of((*d.bits)[k], (*d.is_float)[k] != 0); fmt && (*d.width)[k] > 0 && (*d.height)[k] > 0)
      known.emplace((*d.framebuffer)[k], Known{static_cast<int>((*d.width)[k]), static_cast<int>((*d.height)[k]), *fmt, (*d.bits)[k] != 0});

  const auto main_fb = static_cast<std::uint32_t>(scene::record_scalar<std::uint64_t>(frame_rec, "framebuffer", kFrameLabel, frame));
  // Whether draw k into `t` is tested for culling, and why not (c.untested; Tested then set by cull_test).
  const auto untested = [&](std::size_t k, const scene::DrawRecord& draw, const Target& t, bool may_write_stencil) {
    const std::uint32_t fl = (*d.flags)[k];
    if ((*d.framebuffer)[k] != main_fb || t.width != cull_.width || t.height != cull_.height) return Untested::OtherTarget;
    if (t.stale) return Untested::Stale;
    if (!(fl & kDepthTest) || (*d.bits)[k] == 0 || !fails_behind(draw.state.func, cull_.op)) return Untested::DepthFunc;
    if (fl & kRasterizerDiscard) return Untested::NoTriangles;
    if (may_write_stencil) return Untested::StencilWrites;
    return Untested::Tested;
  };

  std::size_t next_clear = 0;
  const auto apply_clears = [&](std::size_t upto) {
    for (; next_clear < clears && before[next_clear] <= upto; ++next_clear) {
      const std::size_t c = next_clear;
      ++out.clears;
      Target* t = nullptr;
      if (const auto it = known.find(clear_fb[c]); it != known.end())
        t = &target(clear_fb[c], it->second.width, it->second.height, it->second.format, it->second.has_depth);
      else if (const auto jt = targets_.find(clear_fb[c]); jt != targets_.end())
        t = &jt->second;
      if (!t) continue;  // a target no draw of the frame uses: nothing to keep
      int x0 = 0, y0 = 0, x1 = t->width, y1 = t->height;
      if (clear_flags[c] & kScissor) {
        const int sy = t->flipped ? t->height - (csy[c] + csh[c]) : csy[c];  // the box as the rows are stored
        x0 = std::max(x0, csx[c]), y0 = std::max(y0, sy), x1 = std::min(x1, csx[c] + csw[c]), y1 = std::min(y1, sy + csh[c]);
      }
      const bool whole = x0 == 0 && y0 == 0 && x1 == t->width && y1 == t->height;
      const bool depth = (buffers[c] & kClearDepth) && (clear_flags[c] & kDepthMask);
      const bool stencil = (buffers[c] & kClearStencil) && (stencil_mask[c] & 0xFFu) != 0;
      const float z = cleared_depth(t->format, depth_value[c]);
      const auto sm = static_cast<std::uint8_t>(stencil_mask[c] & 0xFFu), sv = static_cast<std::uint8_t>(stencil_value[c] & 0xFF);
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          const std::size_t at = static_cast<std::size_t>(y) * static_cast<std::size_t>(t->width) + static_cast<std::size_t>(x);
          if (depth) t->depth.texels[at] = z;
          if (stencil) t->stencil.texels[at] = static_cast<std::uint8_t>((t->stencil.texels[at] & ~sm) | (sv & sm));
        }
      if (depth && whole && cull_.tester && mirrored_ == t) {
        cull_.tester->cleared(t->depth, z);
        t->tester_dirty = true;
      } else if (depth) {
        touched(*t, Rect{x0, y0, x1 - x0, y1 - y0});
      }
      // A whole clear of both buffers makes the target known again (a target with no stencil writes
      // counts as cleared by its depth clear: the model keeps stencil 0 there as GL does).
      if (whole && depth && (stencil || !(buffers[c] & kClearStencil))) t->stale = false;
    }
  };

  for (std::size_t k = 0; k < n; ++k) {
    apply_clears(k);
    const scene::DrawRecord& draw = f.draws[k];
    AppDrawCounts c;
    c.frame = static_cast<std::uint32_t>(frame);
    c.draw = static_cast<std::uint32_t>(k);
    c.framebuffer = (*d.framebuffer)[k];
    c.gl_samples = draw.gl.samples_passed;
    const std::optional<raster::DepthFormat> format = format_of((*d.bits)[k], (*d.is_float)[k] != 0);
    c.reason = reason_of(d, k, draw, format);
    const std::uint32_t fl = (*d.flags)[k];
    const bool may_write_depth = (fl & kDepthTest) && (fl & kDepthMask) && !(fl & kRasterizerDiscard) && (*d.bits)[k] != 0;
    const bool may_write_stencil = (fl & kStencilTest) && !(fl & kRasterizerDiscard) &&
                                   ((draw.stencil.front.write_mask & 0xFFu) != 0 || (draw.stencil.back.write_mask & 0xFFu) != 0);
    const int w = static_cast<int>((*d.width)[k]), h = static_cast<int>((*d.height)[k]);
    // A draw whose fragment shader may discard, and that nothing else keeps the model from, is
    // replayed as if it discarded nothing and checked against GL: its samples passed, and the depth
    // it changed against the change GL recorded (the interposer records one for every such draw
    // that may write depth). Equal: compared and matched like any replayed draw; else GL's change
    // stands and it is flagged (replay.h).
    if (c.reason == Reason::Discard) {  // flagged for the next reason when it has one: discard may not even happen
      const Reason other = reason_of(d, k, draw, format, true);
      if (other != Reason::Replayed) c.reason = other;
    }
    const bool try_discard = c.reason == Reason::Discard && !may_write_stencil && (!may_write_depth || change[k] != nullptr);
    // The cull test, for a draw the model replays (a may-discard one too: discard only removes fragments).
    skip_.clear();
    if (cull_.tester && (c.reason == Reason::Replayed || try_discard)) {
      Target& t = target(c.framebuffer, w, h, *format, (*d.bits)[k] != 0);
      c.untested = untested(k, draw, t, may_write_stencil);
      if (c.untested == Untested::Tested && cull_test(t, draw, c, skip_)) {
        c.reason = Reason::Replayed;  // not drawn: culled (its GL samples say whether wrongly)
        c.triangles = draw.clip_positions.size() / 3;
        out.draws.push_back(c);
        continue;
      }
    }
    if (try_discard) {
      Target& t = target(c.framebuffer, w, h, *format, (*d.bits)[k] != 0);
      if (!t.stale) {
        std::vector<float>& prior = scratch_;
        prior = t.depth.texels;
        const raster::DrawCounters r = replay_untold(t, draw, (*d.bits)[k] != 0, skip_);
        bool equal = r.depth.passed == c.gl_samples;
        if (equal && may_write_depth) equal = same_change(t, prior, *change[k], frame, k);
        c.may_discard = true;
        if (equal) {
          touched(t, t.path->written_box());
          c.reason = Reason::Replayed;
          c.triangles = draw.clip_positions.size() / 3;
          c.fragments = r.depth.fragments, c.depth_tests = r.depth.depth_tests, c.samples = r.depth.passed, c.written = r.depth.written;
        } else {
          t.depth.texels.swap(prior);  // the depth as before the draw: GL's change is applied below
        }
      }
    }
    if (c.reason == Reason::Replayed && !c.may_discard) {
      Target& t = target(c.framebuffer, w, h, *format, (*d.bits)[k] != 0);
      c.stale = t.stale;
      const raster::DrawCounters r = replay(t, draw, (*d.bits)[k] != 0, skip_);
      c.triangles = draw.clip_positions.size() / 3;
      c.fragments = r.depth.fragments;
      c.depth_tests = r.depth.depth_tests;
      c.samples = r.depth.passed;
      c.written = r.depth.written;
    } else if (c.reason != Reason::Replayed && w > 0 && h > 0 && (may_write_depth || may_write_stencil)) {
      Target& t = target(c.framebuffer, w, h, format.value_or(raster::DepthFormat::Float32), (*d.bits)[k] != 0);
      if (change[k] && !may_write_stencil) {
        const scene::TechniqueRecord& r = *change[k];
        const auto& pixel = scene::record_field<std::uint32_t>(r, "pixel", kChangeLabel, frame);
        const auto& depth = scene::record_field<float>(r, "depth", kChangeLabel, frame);
        if (pixel.size() != depth.size() || scene::record_scalar<std::uint64_t>(r, "width", kChangeLabel, frame) != static_cast<std::uint64_t>(w) ||
            scene::record_scalar<std::uint64_t>(r, "height", kChangeLabel, frame) != static_cast<std::uint64_t>(h))
          throw InputError(fmt::format("frame {}: the {} record of draw {} does not fit its {}x{} target", frame, kChangeLabel, k, w, h));
        int x0 = t.width, y0 = t.height, x1 = 0, y1 = 0;
        for (std::size_t i = 0; i < pixel.size(); ++i) {
          if (pixel[i] >= t.depth.texels.size()) throw InputError(fmt::format("frame {}: the {} record of draw {} names pixel {}", frame, kChangeLabel, k, pixel[i]));
          const std::size_t at = t.stored(pixel[i]);
          t.depth.texels[at] = depth[i];
          const int x = static_cast<int>(at % static_cast<std::size_t>(t.width)), y = static_cast<int>(at / static_cast<std::size_t>(t.width));
          x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x + 1), y1 = std::max(y1, y + 1);
        }
        if (x1 > x0) touched(t, Rect{x0, y0, x1 - x0, y1 - y0});
        c.depth_change = true;
      } else {
        t.stale = true;
      }
    }
    out.draws.push_back(c);
  }
  apply_clears(n);

  // The final depth of the main target against GL's.
  out.unhandled = scene::record_scalar<std::string>(frame_rec, "unhandled", kFrameLabel, frame);
  const scene::DepthSnapshot* gl = f.depth("final");
  if (const auto it = targets_.find(main_fb); gl && it != targets_.end() && !it->second.stale && gl->width == it->second.width &&
                                               gl->height == it->second.height) {
    out.depth_compared = true;
    out.depth_pixels = gl->texels.size();
    for (std::size_t i = 0; i < gl->texels.size(); ++i) {
      const std::size_t m = it->second.stored(i);
      if (std::memcmp(&gl->texels[i], &it->second.depth.texels[m], sizeof(float)) != 0) ++out.depth_mismatches;
    }
  }
  return out;
}

}  // namespace nbsim::apps

// Particles' plain core; see sprite.h.
#include "model/particles/sprite.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <variant>

#include "model/common/error.h"
#include "model/common/names.h"
#include "model/raster/point_setup.h"
#include "model/scene/technique_record.h"
#include "model/particles/roles.h"

namespace nbsim::particles {

std::optional<Mode> parse_mode(std::string_view s) { return parse_enum_name<Mode>(kModeNames, s); }
std::string_view to_string(Mode m) noexcept { return enum_name(kModeNames, m); }

int floor_log2(int v) noexcept { return v <= 1 ? 0 : std::bit_width(static_cast<unsigned>(v)) - 1; }

int top_level_needed(Mode m, int largest_side_px, int level_cap) noexcept {
  const int side = std::max(largest_side_px, 1);
  switch (m) {
    case Mode::NBuffer: return std::min(floor_log2(side + 1), level_cap);
    case Mode::HiZ: return std::min(side <= 1 ? 0 : static_cast<int>(std::bit_width(static_cast<unsigned>(side - 1))), level_cap);
    case Mode::None:
    case Mode::Center: break;
  }
  return -1;
}

SpriteRect sprite_rect(const Particle& p, int width_px, int height_px) {
  SpriteRect r;
  // const vec2 a = win - 0.5 - 0.5 * size; (0.5 * size is exact: sizes are whole pixels)
  const auto corner = [&](float win, int& lo, int& hi) {
    const float a = win - 0.5f - 0.5f * p.size;
    const float nearest = std::nearbyint(a);
    const bool tie = std::fabs(a - nearest) < kTiePx;
    lo = static_cast<int>(tie ? nearest : std::ceil(a));
    hi = lo + static_cast<int>(p.size) + (tie ? 1 : 0);
  };
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.size) || std::fabs(p.x) > 1e9f || std::fabs(p.y) > 1e9f)
    return r;  // never on screen (and no overflow in the conversions)
  corner(p.x, r.lo_x, r.hi_x);
  corner(p.y, r.lo_y, r.hi_y);
  const int x0 = std::max(r.lo_x, 0), y0 = std::max(r.lo_y, 0);
  const int x1 = std::min(r.hi_x, width_px), y1 = std::min(r.hi_y, height_px);
  // The shader's inside_z (clip.w > 0 and z inside the clip volume) is the window depth in [0, 1]:
  // a point behind the eye lands outside it in both conventions.
  const bool inside_z = p.depth >= 0.0f && p.depth <= 1.0f;
  r.on_screen = inside_z && x0 < x1 && y0 < y1;
  if (r.on_screen) r.clipped = Rect{x0, y0, x1 - x0, y1 - y0};
  return r;
}

Decision center_test(const Particle& p, const SpriteRect& r, const DepthImage& depth, float margin, FarOp op) {
  Decision d;
  if (!r.on_screen) return d;
  const int cx = static_cast<int>(std::floor(p.x)), cy = static_cast<int>(std::floor(p.y));
  if (cx < 0 || cy < 0 || cx >= depth.width || cy >= depth.height) return d;
  d.tested = true;
  d.lookups = 1;
  d.culled = hidden_behind(p.depth, depth.at(cx, cy), margin, op);
  return d;
}

bool nb_testable(const SpriteRect& r, int top_level) noexcept { return r.on_screen && floor_log2(r.side()) <= top_level; }

Decision hiz_test(const Particle& p, const SpriteRect& r, const HiZPyramid& pyramid, int top_level, float margin, FarOp op) {
  Decision d;
  if (!r.on_screen) return d;
  const int c0x = r.clipped.x, c0y = r.clipped.y, c1x = r.clipped.x1(), c1y = r.clipped.y + r.clipped.h;
  int k = 0;
  while (k <= top_level && (((c1x - 1) >> k) - (c0x >> k) > 1 || ((c1y - 1) >> k) - (c0y >> k) > 1)) ++k;
  if (k > top_level || k >= pyramid.level_count()) {
    d.too_large = true;
    return d;
  }
  const int t0x = c0x >> k, t0y = c0y >> k, t1x = (c1x - 1) >> k, t1y = (c1y - 1) >> k;
  const auto far = [op](float a, float b) { return op == FarOp::Max ? std::max(a, b) : std::min(a, b); };
  float f = pyramid.texel(k, t0x, t0y);
  d.lookups = 1;
  if (t1x != t0x) f = far(f, pyramid.texel(k, t1x, t0y)), ++d.lookups;
  if (t1y != t0y) f = far(f, pyramid.texel(k, t0x, t1y)), ++d.lookups;
  if (t1x != t0x && t1y != t0y) f = far(f, pyramid.texel(k, t1x, t1y)), ++d.lookups;
  d.tested = true;
  d.culled = hidden_behind(p.depth, f, margin, op);
  return d;
}

std::uint64_t hiz_build_texels(int width_px, int height_px, int top_level) noexcept {
  std::uint64_t n = 0;
  for (int k = 0; k <= top_level && k < 31; ++k) {
    const std::uint64_t w = (static_cast<std::uint64_t>(width_px) + (1ull << k) - 1) >> k;
    const std::uint64_t h = (static_cast<std::uint64_t>(height_px) + (1ull << k) - 1) >> k;
    n += w * h;
  }
  return n;
}

Rect drawn_rect(const Particle& p, int width_px, int height_px) noexcept {
  const auto inside = [](float v, int side) { return v >= 0.0f && v <= static_cast<float>(side); };
  if (!inside(p.x, width_px) || !inside(p.y, height_px) || !(p.depth >= 0.0f && p.depth <= 1.0f)) return {};
  const std::int32_t w = raster::point_width_fixed(p.size);
  // Pixel i is covered when x0 <= 256 i < x1: i from ceil(x0 / 256) to ceil(x1 / 256) - 1.
  const auto first = [](std::int32_t f) { return static_cast<int>((static_cast<std::int64_t>(f) + 255) >> 8); };
  const std::int32_t x0 = raster::snap_point_coordinate(p.x - 0.5f) - w / 2, y0 = raster::snap_point_coordinate(p.y - 0.5f) - w / 2;
  const int px0 = std::max(first(x0), 0), py0 = std::max(first(y0), 0);
  const int px1 = std::min(first(x0 + w), width_px), py1 = std::min(first(y0 + w), height_px);
  if (px0 >= px1 || py0 >= py1) return {};
  return Rect{px0, py0, px1 - px0, py1 - py0};
}

bool sprite_passes(const Rect& r, float d, const DepthImage& depth, FarOp op) noexcept {
  for (int y = r.y; y < r.y + r.h; ++y)
    for (int x = r.x; x < r.x1(); ++x) {
      const float z = depth.at(x, y);
      if (op == FarOp::Max ? d < z : d > z) return true;
    }
  return false;
}

namespace {

template <class T>
const std::vector<T>& field(const scene::TechniqueRecord& rec, std::string_view name, std::uint64_t frame) {
  return scene::record_field<T>(rec, name, "ParticleCulling", frame);
}

}  // namespace

FrameParticles read_particles(const scene::Frame& f) {
  const std::uint64_t frame = f.begin.frame;
  const scene::TechniqueRecord* rec =
      &scene::single_record(f, kParticlesRecordType, "ParticleCulling (PRTC)", "nothing to decide for its particle draws");
  std::uint64_t count = 0;
  bool has_count = false;
  for (const scene::TechniqueField& fl : rec->fields)
    if (fl.name == "count")
      if (const auto* v = std::get_if<std::uint64_t>(&fl.value)) count = *v, has_count = true;
  if (!has_count) throw InputError(fmt::format("frame {}: the ParticleCulling record has no count", frame));
  FrameParticles out;
  out.draw = field<std::uint32_t>(*rec, "draw", frame);
  out.culled = field<std::uint32_t>(*rec, "culled", frame);
  out.lookups = field<std::uint32_t>(*rec, "lookups", frame);
  out.reference_samples = field<std::uint32_t>(*rec, "reference_samples", frame);
  const auto& x = field<float>(*rec, "x", frame);
  const auto& y = field<float>(*rec, "y", frame);
  const auto& depth = field<float>(*rec, "depth", frame);
  const auto& size = field<float>(*rec, "size", frame);
  for (std::size_t n : {out.draw.size(), out.culled.size(), out.lookups.size(), out.reference_samples.size(), x.size(),
                        y.size(), depth.size(), size.size()})
    if (n != count)
      throw InputError(fmt::format("frame {}: the ParticleCulling record's count is {} but a field has {} elements", frame,
                                   count, n));
  // The particle draws' points, in draw order, must be the record's particles.
  std::uint64_t points = 0;
  std::size_t p = 0;
  for (std::size_t i = 0; i < f.draws.size(); ++i) {
    const scene::DrawRecord& d = f.draws[i];
    if (d.role != kParticlesRole) continue;
    const std::size_t n = d.clip_positions.size();
    points += n;
    for (std::size_t k = 0; k < n; ++k, ++p)
      if (p < count && out.draw[p] != i)
        throw InputError(fmt::format("frame {}: particle {} is recorded as drawn by draw {}, but draw {} drew it", frame, p,
                                     out.draw[p], i));
  }
  if (points != count)
    throw InputError(fmt::format(
        "frame {}: the ParticleCulling record's count is {}, but the frame's particle draws hold {} points", frame, count,
        points));
  out.particles.resize(count);
  for (std::size_t i = 0; i < count; ++i) out.particles[i] = {x[i], y[i], depth[i], size[i]};
  return out;
}

}  // namespace nbsim::particles

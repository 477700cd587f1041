// Shadow volumes with litmaps: the SHDC record, the cull rule and the per-caster checks; see caster.h.
#include "model/shadows/caster.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>

#include "model/common/error.h"
#include "model/common/names.h"
#include "model/scene/technique_record.h"
#include "model/shadows/roles.h"

namespace nbsim::shadows {

std::optional<Mode> parse_mode(std::string_view s) noexcept {
  for (std::size_t i = 0; i < kModeNames.size(); ++i)
    if (kModeNames[i] == s) return static_cast<Mode>(i);
  return std::nullopt;
}

std::optional<ClampMargin> parse_clamp_margin(std::string_view s) noexcept {
  // "<rel> + <metres> m"
  const std::size_t plus = s.find(" + ");
  if (plus == std::string_view::npos || s.size() < plus + 3 + 2 || s.substr(s.size() - 2) != " m") return std::nullopt;
  const std::string rel(s.substr(0, plus)), metres(s.substr(plus + 3, s.size() - 2 - plus - 3));
  ClampMargin m;
  try {
    std::size_t used = 0;
    m.rel = std::stod(rel, &used);
    if (used != rel.size()) return std::nullopt;
    m.metres = std::stod(metres, &used);
    if (used != metres.size()) return std::nullopt;
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (!(m.rel >= 0.0 && m.rel <= 1.0 && m.metres >= 0.0 && m.metres <= 1000.0)) return std::nullopt;
  return m;
}

std::optional<LightDepth> LightDepth::make(const scene::Camera& light) noexcept {
  const double a = light.proj[10], b = light.proj[14];
  // A GL perspective frustum: w = -z_eye, a = -(f+n)/(f-n) < -1, b = -2fn/(f-n) < 0.
  if (light.proj[11] != -1.0f || !std::isfinite(a) || !std::isfinite(b) || !(a < -1.0) || !(b < 0.0)) return std::nullopt;
  return LightDepth{a, b};
}

bool litmap_rule_culls(float z_min, float z_max, float caster_near, const LightDepth& light, const ClampMargin& m) noexcept {
  const double far = light.depth_of_distance(light.distance_of_depth(z_max) * (1.0 + m.rel) + m.metres);
  return far < std::max(static_cast<double>(z_min), static_cast<double>(caster_near));
}

namespace {

template <class T>
const std::vector<T>& field(const scene::TechniqueRecord& rec, std::string_view name, std::uint64_t frame) {
  return scene::record_field<T>(rec, name, "ShadowCasters (SHDC)", frame);
}

std::optional<std::uint64_t> optional_scalar(const scene::TechniqueRecord& rec, std::string_view name) {
  for (const scene::TechniqueField& f : rec.fields)
    if (f.name == name)
      if (const auto* v = std::get_if<std::uint64_t>(&f.value)) return *v;
  return std::nullopt;
}

double real(const scene::TechniqueRecord& rec, std::string_view name, std::uint64_t frame) {
  for (const scene::TechniqueField& f : rec.fields)
    if (f.name == name)
      if (const auto* v = std::get_if<double>(&f.value)) return *v;
  throw InputError(fmt::format("frame {}: the ShadowCasters (SHDC) record has no '{}'", frame, name));
}

std::uint64_t scalar(const scene::TechniqueRecord& rec, std::string_view name, std::uint64_t frame) {
  if (const auto v = optional_scalar(rec, name)) return *v;
  throw InputError(fmt::format("frame {}: the ShadowCasters (SHDC) record has no '{}'", frame, name));
}

// "ground,tower,bird" -> its names.
std::vector<std::string> split_names(const std::string& text) {
  std::vector<std::string> out;
  for (std::size_t pos = 0; pos <= text.size() && !text.empty();) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    out.push_back(text.substr(pos, comma - pos));
    pos = comma + 1;
  }
  return out;
}

}  // namespace

FrameCasters read_casters(const scene::Frame& f) {
  const std::uint64_t frame = f.begin.frame;
  const scene::TechniqueRecord* rec =
      &scene::single_record(f, kShadowsRecordType, "ShadowCasters (SHDC)", "no caster to query or check");
  const std::uint64_t count = scalar(*rec, "count", frame);
  FrameCasters c;
  const std::uint64_t size = scalar(*rec, "litmap_size", frame);
  if (size < 1 || size > 16384)
    throw InputError(fmt::format("frame {}: the ShadowCasters record's litmap_size {} is outside 1 .. 16384", frame, size));
  c.litmap_size = static_cast<std::uint32_t>(size);
  c.object = field<std::uint32_t>(*rec, "object", frame);
  c.lookups = field<std::uint32_t>(*rec, "lookups", frame);
  c.decision = field<std::uint32_t>(*rec, "decision", frame);
  c.x = field<std::int32_t>(*rec, "x", frame);
  c.y = field<std::int32_t>(*rec, "y", frame);
  c.w = field<std::int32_t>(*rec, "w", frame);
  c.h = field<std::int32_t>(*rec, "h", frame);
  c.draw = field<std::int32_t>(*rec, "draw", frame);
  c.caster_near = field<float>(*rec, "caster_near", frame);
  c.caster_far = field<float>(*rec, "caster_far", frame);
  c.z_min = field<float>(*rec, "z_min", frame);
  c.z_max = field<float>(*rec, "z_max", frame);
  c.clamp_near = field<float>(*rec, "clamp_near", frame);
  c.clamp_far = field<float>(*rec, "clamp_far", frame);
  c.reference_fill = optional_scalar(*rec, "reference_fill");
  c.mask_diff_pixels = optional_scalar(*rec, "mask_diff_pixels");
  c.cls = field<std::uint32_t>(*rec, "class", frame);
  c.kept = field<std::uint32_t>(*rec, "kept", frame);
  c.fill_infinite = field<std::uint32_t>(*rec, "fill_infinite", frame);
  const char* light_fields[9] = {"light_eye_x",    "light_eye_y",   "light_eye_z",  "light_target_x", "light_target_y",
                                 "light_target_z", "light_fov_deg", "light_near_m", "light_far_m"};
  for (std::size_t k = 0; k < 9; ++k) c.light[k] = real(*rec, light_fields[k], frame);
  for (const scene::TechniqueField& value : rec->fields)
    if (const auto* names = value.name == "class_names" ? std::get_if<std::string>(&value.value) : nullptr) c.class_names = split_names(*names);
  for (std::size_t n : {c.lookups.size(), c.decision.size(), c.x.size(), c.y.size(), c.w.size(), c.h.size(), c.draw.size(),
                        c.caster_near.size(), c.caster_far.size(), c.z_min.size(), c.z_max.size(), c.clamp_near.size(),
                        c.clamp_far.size(), c.object.size(), c.cls.size(), c.kept.size(), c.fill_infinite.size()})
    if (n != count)
      throw InputError(fmt::format("frame {}: the ShadowCasters record's count is {} but a field has {} elements", frame, count, n));
  const auto side = static_cast<std::int64_t>(size);
  for (std::size_t i = 0; i < count; ++i) {
    if (c.decision[i] > 3)
      throw InputError(fmt::format("frame {}: caster {}'s decision {} is not 0 to 3", frame, i, c.decision[i]));
    const bool measured = c.decision[i] <= 1;
    if (measured && (c.w[i] < 1 || c.h[i] < 1 || c.x[i] < 0 || c.y[i] < 0 || std::int64_t{c.x[i]} + c.w[i] > side ||
                     std::int64_t{c.y[i]} + c.h[i] > side))
      throw InputError(fmt::format("frame {}: caster {}'s rectangle ({}, {}) {}x{} is not inside the {}x{} litmap", frame, i, c.x[i],
                                   c.y[i], c.w[i], c.h[i], size, size));
    if (c.draw[i] >= 0 && (static_cast<std::size_t>(c.draw[i]) >= f.draws.size() ||
                           f.draws[static_cast<std::size_t>(c.draw[i])].role != kShadowVolumeRole))
      throw InputError(fmt::format("frame {}: caster {} names draw {}, which is not a shadow_volume draw of the frame", frame, i,
                                   c.draw[i]));
    if (c.kept[i] >= kKeptNames.size())
      throw InputError(fmt::format("frame {}: caster {}'s kept {} is not 0 to {}", frame, i, c.kept[i], kKeptNames.size() - 1));
    if (c.cls[i] >= c.class_names.size())
      throw InputError(fmt::format("frame {}: caster {}'s class {} is not one of the record's {} class names", frame, i, c.cls[i],
                                   c.class_names.size()));
    if (c.draw[i] < -1) throw InputError(fmt::format("frame {}: caster {}'s draw {} is below -1", frame, i, c.draw[i]));
  }
  return c;
}

DepthRange exact_range(const DepthImage& litmap_min, const DepthImage& litmap_max, const Rect& r) noexcept {
  DepthRange e;
  for (int y = std::max(r.y, 0); y < std::min(r.y + r.h, litmap_min.height); ++y)
    for (int x = std::max(r.x, 0); x < std::min(r.x + r.w, litmap_min.width); ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(litmap_min.width) + static_cast<std::size_t>(x);
      e.z_min = std::min(e.z_min, litmap_min.texels[i]);
      if (i < litmap_max.texels.size()) e.z_max = std::max(e.z_max, litmap_max.texels[i]);
    }
  return e;
}

CasterCheck check_caster(const FrameCasters& c, std::size_t i, float model_z_min, float model_z_max, const DepthRange& exact,
                         const LightDepth& light, const ClampMargin& m) noexcept {
  CasterCheck k;
  const bool gl_culled = c.decision[i] == static_cast<std::uint32_t>(Decision::Culled);
  const bool rule_on_gl = litmap_rule_culls(c.z_min[i], c.z_max[i], c.caster_near[i], light, m);
  k.model_culled = litmap_rule_culls(model_z_min, model_z_max, c.caster_near[i], light, m);
  k.decision_mismatch = gl_culled && !rule_on_gl;
  k.kept_by_slab = !gl_culled && rule_on_gl;
  k.zmin_mismatch = model_z_min != c.z_min[i];
  k.zmax_mismatch = model_z_max != c.z_max[i];
  k.not_conservative = model_z_min > exact.z_min || model_z_max < exact.z_max;
  k.unsafe_cull = k.model_culled && !litmap_rule_culls(exact.z_min, exact.z_max, c.caster_near[i], light, m);
  k.cull_lost = gl_culled && !k.model_culled;
  return k;
}

std::uint64_t mask_pixels_differing(const std::vector<std::uint8_t>& stencil, const scene::StencilSnapshot& light_region,
                                    const scene::StencilSnapshot& mask, std::uint64_t* mask_pixels) noexcept {
  std::uint64_t diff = 0, set = 0;
  const std::size_t n = std::min({stencil.size(), light_region.texels.size(), mask.texels.size()});
  for (std::size_t i = 0; i < n; ++i) {
    const bool model = light_region.texels[i] != 0 && stencil[i] != 0;
    set += model ? 1 : 0;
    diff += model != (mask.texels[i] != 0) ? 1 : 0;
  }
  if (mask_pixels) *mask_pixels = set;
  return diff;
}

}  // namespace nbsim::shadows

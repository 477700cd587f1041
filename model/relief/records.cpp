// The relief technique's records, read and checked; see records.h.
#include "model/relief/records.h"

#include <fmt/format.h>

#include <bit>
#include <cmath>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "model/common/depth.h"
#include "model/common/error.h"
#include "model/nbuffer/nbuffer.h"
#include "model/scene/technique_record.h"
#include "model/relief/roles.h"

namespace nbsim::relief {

namespace {

constexpr const char* kFieldLabel = "ReliefField (RLFH)";
constexpr const char* kFragmentsLabel = "ReliefFragments (RLFF)";
constexpr const char* kDepthLabel = "ReliefDepth (RLFD)";
// Limits fixed by the design (traces/format/relief/relief_chunk.h, radius.h, walk.h WalkParams).
constexpr std::uint64_t kMaxRadiusLimit = 255, kMaxLinearSteps = 1024, kMaxBisections = 32;

// A scalar field (u32 fields decode as uint64_t, f64 as double, strings as std::string).
template <class T>
const T& scalar(const scene::TechniqueRecord& rec, std::string_view name, const char* label, std::uint64_t frame) {
  for (const scene::TechniqueField& f : rec.fields)
    if (f.name == name) {
      if (const T* v = std::get_if<T>(&f.value)) return *v;
      throw InputError(fmt::format("frame {}: the {} record's field '{}' has the wrong type", frame, label, name));
    }
  throw InputError(fmt::format("frame {}: the {} record has no field '{}'", frame, label, name));
}

// A u32 field in [lo, hi].
int bounded(const scene::TechniqueRecord& rec, const char* name, std::uint64_t lo, std::uint64_t hi, std::uint64_t frame) {
  const std::uint64_t v = scalar<std::uint64_t>(rec, name, kFieldLabel, frame);
  if (v < lo || v > hi) throw InputError(fmt::format("frame {}: the {} record's {} is {}, not {} to {}", frame, kFieldLabel, name, v, lo, hi));
  return static_cast<int>(v);
}

// A float vector field of `want` values (`why`: what makes it that many), none of them NaN.
const std::vector<float>& float_vector(const scene::TechniqueRecord& rec, const char* name, std::size_t want, std::string_view why,
                                       std::uint64_t frame) {
  const std::vector<float>& v = scene::record_field<float>(rec, name, kFieldLabel, frame);
  if (v.size() != want)
    throw InputError(fmt::format("frame {}: the {} record's field '{}' has {} values, but {} is {}", frame, kFieldLabel, name, v.size(),
                                 why, want));
  for (std::size_t k = 0; k < v.size(); ++k)
    if (std::isnan(v[k])) throw InputError(fmt::format("frame {}: the {} record's field '{}' has NaN at index {}", frame, kFieldLabel, name, k));
  return v;
}

std::array<float, 3> vec3(const scene::TechniqueRecord& rec, const char* name, std::uint64_t frame) {
  const std::vector<float>& v = float_vector(rec, name, 3, "a vector's length", frame);
  return {v[0], v[1], v[2]};
}

// The N-buffer GL built must be the max N-buffer of the heights, bit for bit (an F32 build copies
// the heights into level 0 exactly; the other levels are maxima of them).
void check_nbuffer(const GlReliefField& g, std::uint64_t frame) {
  const int n = g.field.size;
  DepthImage heights;
  heights.width = heights.height = n;
  heights.texels = g.field.heights;
  const NBuffer model(heights, NBufferConfig{FarOp::Max, StorageFormat::F32, -1});
  NBSIM_CHECK(model.level_count() == g.levels, "the model's N-buffer of the heightfield has another level count than RLFH's checked one");
  const std::size_t plane = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  for (int l = 0; l < g.levels; ++l) {
    const std::span<const float> want = model.level(l);
    const float* got = g.nbuffer.data() + static_cast<std::size_t>(l) * plane;
    for (std::size_t k = 0; k < plane; ++k)
      if (std::bit_cast<std::uint32_t>(got[k]) != std::bit_cast<std::uint32_t>(want[k]))
        throw InputError(fmt::format("frame {}: the {} record's nbuffer is not the max N-buffer of its heights: level {} texel ({}, {}) "
                                     "is {}, but the heights give {}",
                                     frame, kFieldLabel, l, k % static_cast<std::size_t>(n), k / static_cast<std::size_t>(n), got[k],
                                     want[k]));
  }
}

}  // namespace

FieldView GlReliefField::view() const {
  FieldView v;
  v.size = field.size;
  v.heights = field.heights;
  v.radius = radius.radius;
  v.nbuffer = nbuffer;
  v.levels = levels;
  return v;
}

GlReliefField read_relief_field(const scene::Frame& f) {
  const std::uint64_t frame = f.begin.frame;
  const scene::TechniqueRecord& rec =
      scene::single_record(f, kReliefFieldRecordType, kFieldLabel, "no heightfield to walk and nothing to compare with");
  GlReliefField g;
  const int n = bounded(rec, "size", kMinSize, kMaxSize, frame);
  g.field.size = n;
  g.radius.size = n;
  const int want_levels = nbuffer_level_count(n, n);
  const std::uint64_t levels = scalar<std::uint64_t>(rec, "levels", kFieldLabel, frame);
  if (levels != static_cast<std::uint64_t>(want_levels))
    throw InputError(fmt::format("frame {}: the {} record's levels is {}, but a {}x{} N-buffer has {}", frame, kFieldLabel, levels, n, n,
                                 want_levels));
  g.levels = want_levels;
  g.max_radius = bounded(rec, "max_radius", 1, kMaxRadiusLimit, frame);
  g.description = scalar<std::string>(rec, "field", kFieldLabel, frame);
  const std::size_t texels = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  const std::string side = fmt::format("size x size ({}x{})", n, n);

  g.field.heights = float_vector(rec, "heights", texels, side, frame);
  for (std::size_t k = 0; k < texels; ++k)
    if (!(g.field.heights[k] >= 0.0f && g.field.heights[k] <= 1.0f))
      throw InputError(fmt::format("frame {}: the {} record's height of texel ({}, {}) is {}, outside [0, 1]", frame, kFieldLabel,
                                   k % static_cast<std::size_t>(n), k / static_cast<std::size_t>(n), g.field.heights[k]));
  // Only the range: recomputing the safety radius (radius.h) to check its bound is too slow for a read.
  g.radius.radius = float_vector(rec, "radius", texels, side, frame);
  for (std::size_t k = 0; k < texels; ++k) {
    const float r = g.radius.radius[k];
    if (!(r >= 0.0f && r <= static_cast<float>(g.max_radius)) || r != std::floor(r))
      throw InputError(fmt::format("frame {}: the {} record's radius of texel ({}, {}) is {}, not a whole number in [0, {}] (max_radius)",
                                   frame, kFieldLabel, k % static_cast<std::size_t>(n), k / static_cast<std::size_t>(n), r,
                                   g.max_radius));
  }
  g.nbuffer = float_vector(rec, "nbuffer", static_cast<std::size_t>(g.levels) * texels,
                           fmt::format("levels x size x size ({}x{}x{})", g.levels, n, n), frame);
  check_nbuffer(g, frame);

  g.params.linear_steps = bounded(rec, "linear_steps", 1, kMaxLinearSteps, frame);
  g.params.binary_steps = bounded(rec, "binary_steps", 0, kMaxBisections, frame);
  g.params.root_steps = bounded(rec, "root_steps", 0, kMaxBisections, frame);
  g.ray.origin = vec3(rec, "origin", frame);
  g.ray.a = vec3(rec, "ray_a", frame);
  g.ray.b = vec3(rec, "ray_b", frame);
  g.ray.c = vec3(rec, "ray_c", frame);
  g.view_angle = scalar<double>(rec, "view_angle", kFieldLabel, frame);
  g.frustum_apex = scalar<double>(rec, "frustum_apex", kFieldLabel, frame);
  if (!(g.frustum_apex >= 0.0 && g.frustum_apex <= 1e6))
    throw InputError(fmt::format("frame {}: the {} record's frustum_apex is {}, not in [0, 1e6]", frame, kFieldLabel, g.frustum_apex));
  g.ray.frustum = g.frustum_apex > 0.0;
  const std::vector<float>& eye = float_vector(rec, "eye_h", g.ray.frustum ? 4 : 0, "a frustum's homogeneous eye (a box: none)", frame);
  const std::vector<float>& q = float_vector(rec, "ray_q", g.ray.frustum ? 12 : 0, "a frustum's three 4-vectors (a box: none)", frame);
  if (g.ray.frustum)
    for (std::size_t k = 0; k < 4; ++k) {
      g.ray.eye_h[k] = eye[k];
      g.ray.qa[k] = q[k], g.ray.qb[k] = q[4 + k], g.ray.qc[k] = q[8 + k];
    }
  return g;
}

std::vector<GlReliefFragments> read_relief_fragments(const scene::Frame& f, std::uint64_t viewport_pixels) {
  const std::uint64_t frame = f.begin.frame;
  std::vector<GlReliefFragments> out;
  std::vector<std::size_t> record_of_draw(f.draws.size(), f.technique_records.size());  // which RLFF holds each draw's fragments
  for (std::size_t r = 0; r < f.technique_records.size(); ++r) {
    const scene::TechniqueRecord& rec = f.technique_records[r];
    if (rec.type != kReliefFragmentsRecordType) continue;
    const std::size_t nth = out.size();
    if (!rec.decoded) throw InputError(fmt::format("frame {}: {} record {} was not decoded", frame, kFragmentsLabel, nth));
    const auto bad = [&](const std::string& what) {
      return InputError(fmt::format("frame {}: {} record {}: {}", frame, kFragmentsLabel, nth, what));
    };
    GlReliefFragments g;
    const std::uint64_t draw = scalar<std::uint64_t>(rec, "draw", kFragmentsLabel, frame);
    std::size_t d = 0;
    while (d < f.draws.size() && f.draws[d].index != draw) ++d;
    if (d == f.draws.size()) throw bad(fmt::format("draw {} is not a draw of the frame ({} draws)", draw, f.draws.size()));
    if (f.draws[d].role != kReliefBoxRole)
      throw bad(fmt::format("draw {} is a {} draw, not a relief_box draw", draw, scene::to_string(f.draws[d].role)));
    if (record_of_draw[d] != f.technique_records.size()) throw bad(fmt::format("draw {} already has its fragments in an earlier record", draw));
    record_of_draw[d] = r;
    g.draw = static_cast<std::uint32_t>(draw);
    const std::uint64_t method = scalar<std::uint64_t>(rec, "method", kFragmentsLabel, frame);
    if (method >= static_cast<std::uint64_t>(kMethods)) throw bad(fmt::format("method is {}, above {}", method, kMethods - 1));
    g.method = static_cast<Method>(method);
    const std::uint64_t count = scalar<std::uint64_t>(rec, "count", kFragmentsLabel, frame);
    const auto vec = [&](auto& dst, const char* name) {
      using V = std::remove_reference_t<decltype(dst)>;
      dst = scene::record_field<typename V::value_type>(rec, name, kFragmentsLabel, frame);
      if (dst.size() != count) throw bad(fmt::format("field '{}' has {} values, but count is {}", name, dst.size(), count));
    };
    vec(g.pixel, "pixel"), vec(g.hit, "hit"), vec(g.t, "t");
    vec(g.lookups, "lookups"), vec(g.steps, "steps"), vec(g.bisections, "bisections");
    for (std::size_t k = 0; k < count; ++k) {
      if (g.pixel[k] >= viewport_pixels) throw bad(fmt::format("fragment {} is at pixel {}, outside the viewport's {} pixels", k, g.pixel[k], viewport_pixels));
      if (k > 0 && g.pixel[k] <= g.pixel[k - 1])
        throw bad(fmt::format("pixels are not strictly increasing: fragment {} is at pixel {}, after {}", k, g.pixel[k], g.pixel[k - 1]));
      if (g.hit[k] > 2) throw bad(fmt::format("fragment {} has hit {}, above 2 (capped)", k, g.hit[k]));
      if (std::isnan(g.t[k])) throw bad(fmt::format("fragment {} has t NaN", k));
    }
    out.push_back(std::move(g));
  }
  for (std::size_t d = 0; d < f.draws.size(); ++d)
    if (f.draws[d].role == kReliefBoxRole && record_of_draw[d] == f.technique_records.size())
      throw InputError(fmt::format("frame {}: relief_box draw {} has no {} record", frame, f.draws[d].index, kFragmentsLabel));
  return out;
}

std::optional<GlReliefDepth> read_relief_depth(const scene::Frame& f, bool required) {
  const std::uint64_t frame = f.begin.frame;
  bool present = false;
  for (const scene::TechniqueRecord& r : f.technique_records) present = present || r.type == kReliefDepthRecordType;
  if (!present && !required) return std::nullopt;
  const scene::TechniqueRecord& rec = scene::single_record(
      f, kReliefDepthRecordType, kDepthLabel, "the trace's boxes write depth (relief_box_depth), and nothing says what GL's depth became");
  GlReliefDepth g;
  const std::vector<float>& m = scene::record_field<float>(rec, "texel_to_clip", kDepthLabel, frame);
  if (m.size() != 16) throw InputError(fmt::format("frame {}: the {} record's texel_to_clip has {} values, not 16", frame, kDepthLabel, m.size()));
  for (std::size_t k = 0; k < 16; ++k) {
    if (!std::isfinite(m[k])) throw InputError(fmt::format("frame {}: the {} record's texel_to_clip[{}] is {}", frame, kDepthLabel, k, m[k]));
    g.texel_to_clip[k] = m[k];
  }
  g.draws = scene::record_field<std::uint32_t>(rec, "draws", kDepthLabel, frame);
  g.depth_crc = scene::record_field<std::uint32_t>(rec, "depth_crc", kDepthLabel, frame);
  if (g.depth_crc.size() != g.draws.size())
    throw InputError(fmt::format("frame {}: the {} record has {} draws but {} CRCs", frame, kDepthLabel, g.draws.size(), g.depth_crc.size()));
  std::size_t next = 0;
  for (const scene::DrawRecord& d : f.draws) {
    if (d.role != kReliefBoxRole) continue;
    if (next >= g.draws.size() || g.draws[next] != d.index)
      throw InputError(fmt::format("frame {}: relief_box draw {} has no depth CRC in the {} record (in draw order)", frame, d.index, kDepthLabel));
    ++next;
  }
  if (next != g.draws.size())
    throw InputError(fmt::format("frame {}: the {} record lists {} draws, but the frame has {} relief_box draws", frame, kDepthLabel,
                                 g.draws.size(), next));
  return g;
}

}  // namespace nbsim::relief

// The relief technique's chunk descriptions; see relief_chunk.h.
#include "traces/format/relief/relief_chunk.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <string>
#include <variant>

#include "model/nbuffer/covering.h"
#include "model/relief/heightfield.h"
#include "model/relief/walk.h"

namespace nbsim::trace {

namespace {

// Limits fixed by the design, as relief_chunk.h and model/relief (radius.h, walk.h WalkParams)
// state them; the size limits are model/relief/heightfield.h's.
constexpr std::uint64_t kMaxRadiusLimit = 255, kMaxLinearSteps = 1024, kMaxBisections = 32;

std::uint64_t u(const TechniqueRecord& r, std::string_view name) {
  const TechniqueField* f = find_field(r, name);
  return f ? std::get<std::uint64_t>(f->value) : 0;
}
const std::vector<float>& floats(const TechniqueRecord& r, std::string_view name) {
  static const std::vector<float> none;
  const TechniqueField* f = find_field(r, name);
  return f ? std::get<std::vector<float>>(f->value) : none;
}

// Why `name` does not hold `want` values none of which is NaN, or empty.
std::string float_vector_problem(const TechniqueRecord& r, std::string_view name, std::uint64_t want, std::string_view why) {
  const std::vector<float>& v = floats(r, name);
  if (v.size() != want) return fmt::format("field '{}' has {} values, but {} is {}", name, v.size(), why, want);
  for (std::size_t k = 0; k < v.size(); ++k)
    if (std::isnan(v[k])) return fmt::format("field '{}' has NaN at index {}", name, k);
  return {};
}

std::string field_rule(const TechniqueRecord& r) {
  const std::uint64_t n = u(r, "size"), levels = u(r, "levels"), max_radius = u(r, "max_radius");
  if (n < static_cast<std::uint64_t>(relief::kMinSize) || n > static_cast<std::uint64_t>(relief::kMaxSize))
    return fmt::format("size is {}, not {} to {}", n, relief::kMinSize, relief::kMaxSize);
  const int side = static_cast<int>(n);
  const std::uint64_t want_levels = static_cast<std::uint64_t>(nbuffer_level_count(side, side));
  if (levels != want_levels) return fmt::format("levels is {}, but a {}x{} N-buffer has {}", levels, n, n, want_levels);
  if (max_radius < 1 || max_radius > kMaxRadiusLimit) return fmt::format("max_radius is {}, not 1 to {}", max_radius, kMaxRadiusLimit);
  const struct {
    const char* name;
    std::uint64_t lo, hi;
  } tunables[] = {{"linear_steps", 1, kMaxLinearSteps}, {"binary_steps", 0, kMaxBisections}, {"root_steps", 0, kMaxBisections}};
  for (const auto& t : tunables)
    if (u(r, t.name) < t.lo || u(r, t.name) > t.hi) return fmt::format("{} is {}, not {} to {}", t.name, u(r, t.name), t.lo, t.hi);
  const std::uint64_t texels = n * n;
  const std::string texels_why = fmt::format("size x size ({}x{})", n, n);
  for (const char* name : {"heights", "radius"})
    if (std::string p = float_vector_problem(r, name, texels, texels_why); !p.empty()) return p;
  if (std::string p = float_vector_problem(r, "nbuffer", levels * texels, fmt::format("levels x size x size ({}x{}x{})", levels, n, n));
      !p.empty())
    return p;
  for (const char* name : {"origin", "ray_a", "ray_b", "ray_c"})
    if (std::string p = float_vector_problem(r, name, 3, "a vector's length"); !p.empty()) return p;
  const TechniqueField* apex_field = find_field(r, "frustum_apex");
  const double apex = apex_field ? std::get<double>(apex_field->value) : 0.0;
  if (!(apex >= 0.0 && apex <= 1e6)) return fmt::format("frustum_apex is {}, not in [0, 1e6] (0: a box)", apex);
  const bool frustum = apex > 0.0;
  if (std::string p = float_vector_problem(r, "eye_h", frustum ? 4 : 0, frustum ? "a frustum's homogeneous eye" : "a box's"); !p.empty())
    return p;
  if (std::string p = float_vector_problem(r, "ray_q", frustum ? 12 : 0, frustum ? "a frustum's three 4-vectors" : "a box's"); !p.empty())
    return p;
  const std::vector<float>& heights = floats(r, "heights");
  for (std::size_t k = 0; k < heights.size(); ++k)
    if (!(heights[k] >= 0.0f && heights[k] <= 1.0f))
      return fmt::format("height of texel ({}, {}) is {}, outside [0, 1]", k % n, k / n, heights[k]);
  const std::vector<float>& radius = floats(r, "radius");
  for (std::size_t k = 0; k < radius.size(); ++k)
    if (!(radius[k] >= 0.0f && radius[k] <= static_cast<float>(max_radius)) || radius[k] != std::floor(radius[k]))
      return fmt::format("radius of texel ({}, {}) is {}, not a whole number in [0, {}]", k % n, k / n, radius[k], max_radius);
  return {};
}

std::string fragments_rule(const TechniqueRecord& r) {
  if (std::string p = vector_lengths_problem(r, u(r, "count"), {"draw", "method", "count"}, "fragment"); !p.empty()) return p;
  if (u(r, "method") >= static_cast<std::uint64_t>(relief::kMethods))
    return fmt::format("method is {}, above {}", u(r, "method"), relief::kMethods - 1);
  for (const TechniqueField& f : r.fields) {
    if (f.name == "hit") {
      const auto& v = std::get<std::vector<std::uint32_t>>(f.value);
      for (std::size_t k = 0; k < v.size(); ++k)
        if (v[k] > kReliefCapped) return fmt::format("field 'hit' of fragment {} is {}, above {}", k, v[k], kReliefCapped);
    } else if (f.name == "pixel") {
      const auto& v = std::get<std::vector<std::uint32_t>>(f.value);
      for (std::size_t k = 1; k < v.size(); ++k)
        if (v[k] <= v[k - 1])
          return fmt::format("field 'pixel' is not strictly increasing: fragment {} is pixel {}, after {}", k, v[k], v[k - 1]);
    } else if (f.name == "t") {
      const auto& v = std::get<std::vector<float>>(f.value);
      for (std::size_t k = 0; k < v.size(); ++k)
        if (std::isnan(v[k])) return fmt::format("field 't' of fragment {} is NaN", k);
    }
  }
  return {};
}

std::string depth_rule(const TechniqueRecord& r) {
  if (std::string p = float_vector_problem(r, "texel_to_clip", 16, "a 4x4 matrix"); !p.empty()) return p;
  const TechniqueField* draws = find_field(r, "draws");
  const TechniqueField* crcs = find_field(r, "depth_crc");
  const auto& d = std::get<std::vector<std::uint32_t>>(draws->value);
  const auto& c = std::get<std::vector<std::uint32_t>>(crcs->value);
  if (c.size() != d.size()) return fmt::format("field 'depth_crc' has {} values, but there are {} draws", c.size(), d.size());
  for (std::size_t k = 1; k < d.size(); ++k)
    if (d[k] <= d[k - 1]) return fmt::format("field 'draws' is not strictly increasing: {} after {}", d[k], d[k - 1]);
  return {};
}

}  // namespace

ChunkSpec relief_depth_chunk_spec() {
  ChunkSpec spec{kReliefDepthChunk,
                 "relief",
                 "ReliefDepth",
                 {{"texel_to_clip", FieldKind::VecF32,
                   "the box's vertex transform, texel space to clip, 16 values column-major (the exact depth's hit point goes through it)"},
                  {"draws", FieldKind::VecU32, "the frame's relief_box draws, by index, in order"},
                  {"depth_crc", FieldKind::VecU32,
                   "per draw: CRC-32 (zlib) of GL's depth buffer right after it, window depths as floats, y up, row-major"}}};
  spec.rule = depth_rule;
  return spec;
}

ChunkSpec relief_field_chunk_spec() {
  ChunkSpec spec{
      kReliefFieldChunk,
      "relief",
      "ReliefField",
      {{"size", FieldKind::U32, "N: the heightfield is N x N texels, 2 to 1024"},
       {"levels", FieldKind::U32, "levels of the max N-buffer: nbuffer_level_count(N, N) = ceil(log2 N), at least 1"},
       {"max_radius", FieldKind::U32, "the cap of the safety radius, texels, 1 to 255"},
       {"field", FieldKind::String, "what the heightfield is: a generator and its arguments (\"fbm:6 seed 7\") or a file name"},
       {"heights", FieldKind::VecF32, "the heightfield: N x N heights in [0, 1], y up, row-major (model/relief/heightfield.h)"},
       {"radius", FieldKind::VecF32, "the safety radius GL's walks read: N x N whole texels in [0, max_radius], y up, row-major"},
       {"nbuffer", FieldKind::VecF32,
        "the max N-buffer of the heights as GL built it: levels planes of N x N, level-major, y up, row-major; level 0 is the heights"},
       {"linear_steps", FieldKind::U32, "binary: equal steps from the box entry to its exit, 1 to 1024"},
       {"binary_steps", FieldKind::U32, "binary and robust: bisections after the bracket, 0 to 32"},
       {"root_steps", FieldKind::U32, "exact, nbuffer and robust's cell steps: bisections inside a cell, 0 to 32"},
       {"origin", FieldKind::VecF32, "the ray frame (model/relief/walk.h): the eye in texel space, x, y, z"},
       {"ray_a", FieldKind::VecF32,
        "the ray frame: a fragment's ray direction is (ray_a * px + ray_b * py) + ray_c, (px, py) its pixel centre in window "
        "coordinates; ray_a: x, y, z, texel space per pixel of px"},
       {"ray_b", FieldKind::VecF32, "x, y, z, texel space per pixel of py"},
       {"ray_c", FieldKind::VecF32, "x, y, z, texel space"},
       {"view_angle", FieldKind::F64, "degrees between the view direction and the box's up axis (for reports)"},
       {"frustum_apex", FieldKind::F64,
        "0: the box; above 0: a reverse-perspective frustum over the box's bottom face whose sides meet this many box heights "
        "below it (traces/capture/relief/view.h); its rays come from eye_h and ray_q"},
       {"eye_h", FieldKind::VecF32, "a frustum's ray frame (model/relief/walk.h): the eye in the frustum map's homogeneous coordinates, "
                                    "x, y, z, w (a box: empty)"},
       {"ray_q", FieldKind::VecF32,
        "a frustum's ray frame: qa, qb, qc (4 each), the fragment's near-plane point Q = (qa * px + qb * py) + qc (a box: empty)"}}};
  spec.rule = field_rule;
  return spec;
}

ChunkSpec relief_fragments_chunk_spec() {
  ChunkSpec spec{
      kReliefFragmentsChunk,
      "relief",
      "ReliefFragments",
      {{"draw", FieldKind::U32, "the index in the frame of the relief_box draw these fragments are of"},
       {"method", FieldKind::U32, "the walk that draw ran: 0 binary, 1 exact, 2 robust, 3 robust_clamp, 4 nbuffer"},
       {"count", FieldKind::U32, "fragments the shader ran, after the early depth test (every vector below has this many)"},
       {"pixel", FieldKind::VecU32, "the fragment's pixel, y * width + x of the viewport, strictly increasing"},
       {"hit", FieldKind::VecU32, "GL's answer: 0 miss (discarded), 1 hit, 2 capped (the walk reached its iteration cap: a miss)"},
       {"t", FieldKind::VecF32, "the hit's ray parameter, 0 on a miss"},
       {"lookups", FieldKind::VecU32, "texel reads the walk issued (model/relief/walk.h counts them)"},
       {"steps", FieldKind::VecU32, "steps the walk took"},
       {"bisections", FieldKind::VecU32, "bisections the walk took"}}};
  spec.rule = fragments_rule;
  return spec;
}

namespace {

// Comma-separated items, none empty, each valid by `item`.
template <class Item>
bool valid_list(std::string_view v, Item item) {
  if (v.empty()) return false;
  for (std::size_t at = 0;;) {
    const std::size_t comma = v.find(',', at);
    const std::string_view part = v.substr(at, comma == std::string_view::npos ? std::string_view::npos : comma - at);
    if (part.empty() || !item(part)) return false;
    if (comma == std::string_view::npos) return true;
    at = comma + 1;
  }
}

bool valid_methods(std::string_view v) {
  return valid_list(v, [](std::string_view m) {
    return m == "binary" || m == "exact" || m == "robust" || m == "robust_clamp" || m == "nbuffer";
  });
}

bool valid_angles(std::string_view v) {
  return valid_list(v, [](std::string_view a) {
    double deg = 0.0;
    const auto [end, ec] = std::from_chars(a.data(), a.data() + a.size(), deg);
    return ec == std::errc() && end == a.data() + a.size() && deg >= 0.0 && deg < 180.0;
  });
}

}  // namespace

std::vector<HeaderKeySpec> relief_header_keys() {
  const std::string t = "relief";
  return {text_key(t, "relief_field", "fbm:0 seed 3", "the heightfield: a procedural field and its parameter, a file or a mesh"),
          custom_key(t, "relief_methods", valid_methods, "comma-separated: binary, exact, robust, robust_clamp, nbuffer",
                     "binary,exact,robust,robust_clamp,nbuffer", "the walks drawn, one box draw each"),
          choice_key(t, "relief_placement", {"own", "city"}, "own", "the box seen from its own camera, or standing in the scene"),
          whole_key(t, "relief_field_size", 1, 1u << 20, "64", "side of the heightfield, texels"),
          real_key(t, "relief_box_height", 0.0, 1e6, true, "0.25", "height of the box over its width"),
          real_key(t, "relief_frustum_apex", 0.0, 1e6, false, "0", "0: the box; A > 0: a reverse-perspective frustum, apex A box heights below"),
          custom_key(t, "relief_angles", valid_angles, "comma-separated angles, degrees, 0 to below 180", "0,45,80,89",
                     "view angles from the box's up axis; frame k takes angle k mod count"),
          whole_key(t, "relief_max_radius", 1, 255, "16", "cap of the safety radius, texels"),
          choice_key(t, "relief_radius", {"strict", "paper"}, "strict",
                     "the safety radius: strict (every ray from the texel, blocked ones too) or paper (unblocked rays, an allowed error)"),
          choice_key(t, "relief_box_depth", {"none", "box", "exact"}, "none",
                     "what a box draw leaves in the depth buffer: nothing, the box face's depth where the ray hit, or the hit's depth"),
          real_key(t, "relief_radius_epsilon", 0.0, 1.0, false, "0",
                   "paper radius: how far (box heights) a ray may pass under the surface without counting as a second crossing"),
          choice_key(t, "relief_radius_combine", {"max", "min"}, "max",
                     "paper radius: how the directions' radii make a texel's: the paper's maximum, or the minimum"),
          whole_key(t, "relief_linear_steps", 1, 1024, "16", "binary: linear steps before the bisection"),
          whole_key(t, "relief_binary_steps", 0, 32, "8", "binary and robust: bisections after the bracket"),
          whole_key(t, "relief_root_steps", 0, 32, "16", "exact, nbuffer and robust's cell steps: bisections inside a cell"),
          whole_key(t, "relief_seed", 0, 0xFFFFFFFFFFFFFFFFu, "3", "seed of the heightfield and the view azimuths"),
          text_key(t, "relief_box_at", "auto", "where a box in the scene stands"),
          text_key(t, "relief_view", "the box [0,1]^2 x ...", "how the box is viewed")};
}

// This technique's part of the format (technique_chunks.h): the field and fragment chunks and the header keys.
TechniqueFormat relief_format() {
  return {{relief_field_chunk_spec(), relief_fragments_chunk_spec(), relief_depth_chunk_spec()}, relief_header_keys()};
}

}  // namespace nbsim::trace

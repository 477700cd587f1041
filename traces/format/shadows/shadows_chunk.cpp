// The shadows technique's chunk description; see shadows_chunk.h.
#include "traces/format/shadows/shadows_chunk.h"

#include <fmt/format.h>

#include <set>
#include <string>
#include <variant>

#include "model/shadows/caster.h"

namespace nbsim::trace {

namespace {

template <class T>
const std::vector<T>& vec(const TechniqueRecord& r, const char* name) {
  for (const TechniqueField& f : r.fields)
    if (f.name == name) return std::get<std::vector<T>>(f.value);
  static const std::vector<T> none;
  return none;
}

std::uint64_t scalar(const TechniqueRecord& r, const char* name) {
  for (const TechniqueField& f : r.fields)
    if (f.name == name) return std::get<std::uint64_t>(f.value);
  return 0;
}

// The rule of shadows_chunk_spec(): what a reader refuses beyond the field types.
std::string shadows_rule(const TechniqueRecord& r) {
  const std::uint64_t count = scalar(r, "count"), size = scalar(r, "litmap_size");
  if (std::string problem = vector_lengths_problem(r, count,
                                                   {"count", "litmap_size", "reference_fill", "mask_diff_pixels", "class_names", "light_eye_x",
                                                    "light_eye_y", "light_eye_z", "light_target_x", "light_target_y", "light_target_z",
                                                    "light_fov_deg", "light_near_m", "light_far_m"},
                                                   "caster");
      !problem.empty())
    return problem;
  const auto& kept = vec<std::uint32_t>(r, "kept");
  const auto& decision = vec<std::uint32_t>(r, "decision");
  const auto &x = vec<std::int32_t>(r, "x"), &y = vec<std::int32_t>(r, "y"), &w = vec<std::int32_t>(r, "w"), &h = vec<std::int32_t>(r, "h");
  const auto& draw = vec<std::int32_t>(r, "draw");
  for (std::size_t c = 0; c < count; ++c) {
    if (kept[c] > 4) return fmt::format("field 'kept' of caster {} is {}, above 4", c, kept[c]);
    if (decision[c] > 3) return fmt::format("field 'decision' of caster {} is {}, above 3", c, decision[c]);
    const auto s = static_cast<std::int64_t>(size);
    if (x[c] < 0 || y[c] < 0 || w[c] < 0 || h[c] < 0 || x[c] + static_cast<std::int64_t>(w[c]) > s ||
        y[c] + static_cast<std::int64_t>(h[c]) > s)
      return fmt::format("caster {}'s rectangle ({}, {}, {}x{}) is not inside the {}x{} litmap", c, x[c], y[c], w[c], h[c], size, size);
    if (draw[c] < -1) return fmt::format("field 'draw' of caster {} is {}, below -1", c, draw[c]);
  }
  return {};
}

}  // namespace

ChunkSpec shadows_chunk_spec() {
  ChunkSpec spec{
      kShadowsChunk,
      "shadows",
      "ShadowCasters",
      {{"count", FieldKind::U32, "casters in the scene (every vector below has this many elements)"},
       {"litmap_size", FieldKind::U32, "side of the square litmaps and N-buffers, lexels"},
       {"object", FieldKind::VecU32, "the caster's object id"},
       {"x", FieldKind::VecI32, "light-space rectangle: left lexel (grown by one lexel, clipped to the litmap)"},
       {"y", FieldKind::VecI32, "bottom lexel, y up"},
       {"w", FieldKind::VecI32, "width, lexels (0: outside the litmap)"},
       {"h", FieldKind::VecI32, "height, lexels"},
       {"caster_near", FieldKind::VecF32, "nearest light window depth of the caster's bounds, [0, 1] (LESS: 0 at the light)"},
       {"caster_far", FieldKind::VecF32, "farthest light window depth of the caster's bounds"},
       {"z_min", FieldKind::VecF32, "min N-buffer over the rectangle: the nearest visible receiver from the light (1: none)"},
       {"z_max", FieldKind::VecF32, "max N-buffer over the rectangle: the farthest visible receiver from the light (0: none)"},
       {"lookups", FieldKind::VecU32, "N-buffer texels read: 2 to 8 (1, 2 or 4 each), 0 when not tested"},
       {"decision", FieldKind::VecU32, "0 volume drawn, 1 culled (z_max, widened by the clamp margin, < max(z_min, caster_near)), 2 outside the light's "
        "frustum, 3 crosses the light's near plane (never culled, drawn infinite)"},
       {"clamp_near", FieldKind::VecF32,
        "near plane, light window depth (0: none): z_min narrowed by the clamp margin, set only when every receiver of the "
        "rectangle lies behind the whole caster; mode clamped starts the volume there, the other modes cut its sides there"},
       {"clamp_far", FieldKind::VecF32, "far plane: z_max widened by the clamp margin (+inf for a caster with decision 1, 2 or 3); mode clamped ends "
        "the volume there, the other modes cut its sides there (so the pieces between the planes are the same triangles in every mode)"},
       {"draw", FieldKind::VecI32, "the frame's draw (role shadow_volume) of its volume, -1 when none"},
       {"reference_fill", FieldKind::U64,
        "rasterized fragments of the reference pass: every caster's infinite volume (not recorded as draws)"},
       {"mask_diff_pixels", FieldKind::U64,
        "pixels where the STNC shadow_mask differs from shadow_mask_infinite (0 for a correct frame)"},
       {"class_names", FieldKind::String, "the scene's object classes, comma-separated (\"ground,tower,bird\")"},
       {"class", FieldKind::VecU32, "the caster's class: an index into class_names"},
       {"kept", FieldKind::VecU32, "why a culled or clamped capture keeps its volume, in every mode: 0 dropped (decision 1 or 2), 1 a visible "
        "receiver in its slab, 2 the observer sees the caster, 3 only the slab's widening keeps it, 4 it crosses the light's near plane"},
       {"fill_infinite", FieldKind::VecU32, "rasterized fragments of its infinite volume (its share of reference_fill)"},
       {"light_eye_x", FieldKind::F64, "the light camera as the capture built it in double precision (the volumes' points come from it): "
        "position x, metres"},
       {"light_eye_y", FieldKind::F64, "position y"},
       {"light_eye_z", FieldKind::F64, "position z"},
       {"light_target_x", FieldKind::F64, "the point it looks at, x"},
       {"light_target_y", FieldKind::F64, "y"},
       {"light_target_z", FieldKind::F64, "z"},
       {"light_fov_deg", FieldKind::F64, "field of view, degrees"},
       {"light_near_m", FieldKind::F64, "near plane, metres"},
       {"light_far_m", FieldKind::F64, "far plane, metres"}}};
  spec.rule = shadows_rule;
  return spec;
}

namespace {

// What SHDG and SHDM share: per mesh an object id and a range of `triangles`, whose indices name
// vertices of `vertices`. `what` names a mesh in messages ("caster"); "" when the rule holds.
std::string mesh_ranges_rule(const TechniqueRecord& r, std::string_view what) {
  const std::uint64_t count = scalar(r, "count");
  const auto& object = vec<std::uint32_t>(r, "object");
  const auto& first = vec<std::uint32_t>(r, "first_triangle");
  const auto& tris = vec<std::uint32_t>(r, "triangle_count");
  const auto& vertices = vec<float>(r, "vertices");
  const auto& indices = vec<std::uint32_t>(r, "triangles");
  if (object.size() != count || first.size() != count || tris.size() != count)
    return fmt::format("object, first_triangle and triangle_count have {}, {} and {} elements, but count is {}", object.size(), first.size(),
                       tris.size(), count);
  if (vertices.size() % 3 != 0) return fmt::format("vertices has {} floats, not three a vertex", vertices.size());
  if (indices.size() % 3 != 0) return fmt::format("triangles has {} indices, not three a triangle", indices.size());
  for (std::size_t c = 0; c < count; ++c)
    if (static_cast<std::uint64_t>(first[c]) + tris[c] > indices.size() / 3)
      return fmt::format("{} {} (object {}): triangles {} + {} run past the {} triangles", what, c, object[c], first[c], tris[c],
                         indices.size() / 3);
  for (std::size_t i = 0; i < indices.size(); ++i)
    if (indices[i] >= vertices.size() / 3)
      return fmt::format("triangle index {} is vertex {}, but there are {} vertices", i, indices[i], vertices.size() / 3);
  return {};
}

// The rule of caster_meshes_chunk_spec().
std::string caster_meshes_rule(const TechniqueRecord& r) {
  const std::uint64_t count = scalar(r, "count");
  const auto& bounds = vec<float>(r, "bounds");
  if (std::string e = mesh_ranges_rule(r, "caster"); !e.empty()) return e;
  if (bounds.size() != 6 * count) return fmt::format("bounds has {} floats, not six for each of {} casters", bounds.size(), count);
  return {};
}

// The rule of litmap_meshes_chunk_spec().
std::string litmap_meshes_rule(const TechniqueRecord& r) {
  if (std::string e = mesh_ranges_rule(r, "mesh"); !e.empty()) return e;
  std::set<std::uint32_t> seen;
  for (const std::uint32_t o : vec<std::uint32_t>(r, "object"))
    if (!seen.insert(o).second) return fmt::format("object {} is listed twice", o);
  return {};
}

bool valid_margin(std::string_view v) { return shadows::parse_clamp_margin(v).has_value(); }

}  // namespace

std::vector<HeaderKeySpec> shadows_header_keys() {
  const std::string t = "shadows";
  const std::string margin = "'<relative> + <metres> m', relative 0 .. 1, metres 0 .. 1000";
  return {choice_key(t, "shadow_mode", {"infinite", "culled", "clamped"}, "clamped", "which shadow volumes the capture drew"),
          whole_key(t, "litmap_size", 1, 16384, "512", "side of the square min and max litmaps, lexels"),
          text_key(t, "light", "auto", "auto (a spot light circling the scene's centre), or X,Y,Z,TX,TY,TZ in metres"),
          real_key(t, "light_fov_deg", 0.0, 180.0, true, "60", "the spot light's field of view, degrees"),
          whole_key(t, "casters", 0, 0xFFFFFFFFu, "2000", "the scene objects that cast shadows"),
          text_key(t, "stencil_volumes", "zfail_caps_two_sided_depth_clamp", "how the volumes are drawn into the stencil buffer"),
          custom_key(t, "reproject_tolerance", valid_margin, margin, "0.01 + 0.05 m",
                     "tolerance of the observer depth reprojected into the litmaps"),
          custom_key(t, "clamp_margin", valid_margin, margin, "0.01 + 0.1 m",
                     "how far a clamped volume's slab is pushed back before the cull test"),
          choice_key(t, "clamp_rule", {"edge", "caster"}, "caster",
                     "where a clamped volume starts: edge (the paper's: each edge and lit face on the min plane unless farther than it) "
                     "or caster (the min plane only when the whole caster is in front of it)")};
}

// This technique's part of the format (technique_chunks.h): its chunk type and header keys.
ChunkSpec caster_meshes_chunk_spec() {
  ChunkSpec spec{kCasterMeshesChunk,
                 "shadows",
                 "ShadowCasterMeshes",
                 {{"count", FieldKind::U32, "casters (the scene objects whose triangles form closed surfaces), in SHDC's order"},
                  {"object", FieldKind::VecU32, "each caster's object id"},
                  {"bounds", FieldKind::VecF32, "each caster's bounds: lo x, y, z, hi x, y, z (metres), six floats a caster"},
                  {"first_triangle", FieldKind::VecU32, "each caster's first triangle in `triangles`"},
                  {"triangle_count", FieldKind::VecU32, "its triangles"},
                  {"vertices", FieldKind::VecF32, "world positions, x, y, z a vertex (metres, y up)"},
                  {"triangles", FieldKind::VecU32, "three vertex indices a triangle, counter-clockwise seen from outside"}}};
  spec.rule = caster_meshes_rule;
  return spec;
}

ChunkSpec litmap_meshes_chunk_spec() {
  ChunkSpec spec{kLitmapMeshesChunk,
                 "shadows",
                 "ShadowLitmapMeshes",
                 {{"count", FieldKind::U32, "scene objects (every object a litmap draw may draw)"},
                  {"object", FieldKind::VecU32, "each object's id"},
                  {"first_triangle", FieldKind::VecU32, "each object's first triangle in `triangles`"},
                  {"triangle_count", FieldKind::VecU32, "its triangles, in the order GL draws them"},
                  {"vertices", FieldKind::VecF32, "world positions, x, y, z a vertex (metres, y up)"},
                  {"triangles", FieldKind::VecU32, "three vertex indices a triangle"}}};
  spec.rule = litmap_meshes_rule;
  return spec;
}

TechniqueFormat shadows_format() {
  return {{shadows_chunk_spec(), caster_meshes_chunk_spec(), litmap_meshes_chunk_spec()}, shadows_header_keys()};
}

}  // namespace nbsim::trace

// The LDI technique's chunk descriptions; see ldi_chunk.h.
#include "traces/format/ldi/ldi_chunk.h"

#include <fmt/format.h>

#include <charconv>
#include <string>
#include <variant>

#include "model/ldi/ldi.h"

namespace nbsim::trace {

namespace {

// Limits mirrored from model/ldi/ldi.h (kMaxSideTexels, kMaxLayers); the model checks the rest.
constexpr std::uint64_t kMaxSide = 16384, kMaxLayers = 2048;

std::uint64_t u(const TechniqueRecord& r, std::string_view name) {
  const TechniqueField* f = find_field(r, name);
  return f ? std::get<std::uint64_t>(f->value) : 0;
}
std::int64_t i(const TechniqueRecord& r, std::string_view name) {
  const TechniqueField* f = find_field(r, name);
  return f ? std::get<std::int64_t>(f->value) : 0;
}
template <class T>
std::size_t length(const TechniqueRecord& r, std::string_view name) {
  const TechniqueField* f = find_field(r, name);
  return f ? std::get<std::vector<T>>(f->value).size() : 0;
}

std::string image_rule(const TechniqueRecord& r) {
  const std::uint64_t w = u(r, "width"), h = u(r, "height"), layers = u(r, "layer_count");
  const std::uint64_t gh = u(r, "grid_h"), gv = u(r, "grid_v"), side = u(r, "comp_side");
  if (w < 1 || w > kMaxSide || h < 1 || h > kMaxSide)
    return fmt::format("the LDI is {}x{} texels; each side must be 1 to {}", w, h, kMaxSide);
  if (layers > kMaxLayers) return fmt::format("layer_count is {}, above {}", layers, kMaxLayers);
  if (gh < 1 || gv < 1 || gh > 1024 || gv > 1024) return fmt::format("the viewpoint grid is {}x{}; each side must be 1 to 1024", gh, gv);
  if (u(r, "direction") >= gh * gv) return fmt::format("direction is {}, but the grid has {} directions", u(r, "direction"), gh * gv);
  if (side > kMaxSide) return fmt::format("comp_side is {}, above {}", side, kMaxSide);
  const std::size_t want_layers = static_cast<std::size_t>(layers * w * h);
  if (length<float>(r, "layers") != want_layers)
    return fmt::format("field 'layers' has {} values, but layer_count x width x height is {}", length<float>(r, "layers"), want_layers);
  if (length<float>(r, "view") != 9) return fmt::format("field 'view' has {} values, not 9", length<float>(r, "view"));
  if (length<float>(r, "rotation") != 9) return fmt::format("field 'rotation' has {} values, not 9", length<float>(r, "rotation"));
  for (const char* name : {"candidate_d", "candidate_coverage"})
    if (length<std::uint32_t>(r, name) != gh * gv)
      return fmt::format("field '{}' has {} values, but the grid has {} directions", name, length<std::uint32_t>(r, name), gh * gv);
  if (length<std::uint32_t>(r, "compressed") != 2 * side * side)
    return fmt::format("field 'compressed' has {} values, but comp_side {} needs {}", length<std::uint32_t>(r, "compressed"), side,
                       2 * side * side);
  const std::int64_t cx = i(r, "crop_x"), cy = i(r, "crop_y"), cw = i(r, "crop_w"), ch = i(r, "crop_h");
  if (cx < 0 || cy < 0 || cw < 0 || ch < 0 || cx + cw > static_cast<std::int64_t>(w) || cy + ch > static_cast<std::int64_t>(h))
    return fmt::format("the crop ({}, {}, {}x{}) is not inside the {}x{} LDI", cx, cy, cw, ch, w, h);
  return {};
}

std::string tests_rule(const TechniqueRecord& r) {
  const std::uint64_t count = u(r, "count");
  if (std::string problem = vector_lengths_problem(r, count, {"count", "epsilon"}, "test point"); !problem.empty()) return problem;
  const TechniqueField* eps = find_field(r, "epsilon");
  if (eps && !(std::get<double>(eps->value) >= 0.0 && std::get<double>(eps->value) < 1.0))
    return fmt::format("epsilon is {}, not in [0, 1)", std::get<double>(eps->value));
  for (const TechniqueField& f : r.fields) {
    if (const auto* v = std::get_if<std::vector<std::uint32_t>>(&f.value)) {
      const bool answer = f.name == "gl_inside_layers" || f.name == "gl_inside_ranges";
      const std::uint32_t limit = f.name == "kind" ? kLdiPointKinds - 1 : answer ? 1u : 0xFFFFFFFFu;
      for (std::size_t p = 0; p < v->size(); ++p)
        if ((*v)[p] > limit) return fmt::format("field '{}' of test point {} is {}, above {}", f.name, p, (*v)[p], limit);
    } else if (const auto* s = std::get_if<std::vector<std::int32_t>>(&f.value); s && f.name == "reference") {
      for (std::size_t p = 0; p < s->size(); ++p)
        if ((*s)[p] < kLdiNearSurface) return fmt::format("field 'reference' of test point {} is {}, below {}", p, (*s)[p], kLdiNearSurface);
    }
  }
  return {};
}

}  // namespace

ChunkSpec ldi_image_chunk_spec() {
  ChunkSpec spec{
      kLdiImageChunk,
      "ldi",
      "LdiImage",
      {{"width", FieldKind::U32, "LDI width, texels (the peel's viewport)"},
       {"height", FieldKind::U32, "LDI height, texels"},
       {"layer_count", FieldKind::U32, "layers the peel found: the depth complexity d (the last, empty pass is not a layer)"},
       {"grid_h", FieldKind::U32, "viewpoint grid: directions around the vertical axis (s_H)"},
       {"grid_v", FieldKind::U32, "viewpoint grid: elevations (s_V)"},
       {"direction", FieldKind::U32, "the chosen direction, v * grid_h + h: smallest d, then largest coverage, then lowest index"},
       {"view", FieldKind::VecF32, "the chosen orthographic frame in the shape's unit cube: direction, right, up (3 each)"},
       {"rotation", FieldKind::VecF32, "the shape's rotation this frame, column-major 3x3, applied before it is fitted into the unit cube"},
       {"candidate_d", FieldKind::VecU32, "per direction: its depth complexity as GL measured it (most fragments on one texel)"},
       {"candidate_coverage", FieldKind::VecU32, "per direction: texels with at least one fragment"},
       {"layers", FieldKind::VecF32,
        "the LDI as GL peeled it: layer_count layers of width x height linear depths in [0, 1], layer-major, y up, row-major; "
        "+inf where the texel has no more layers"},
       {"crop_x", FieldKind::I32, "GL's crop: the bounding rectangle of the texels with a layer, left texel"},
       {"crop_y", FieldKind::I32, "bottom texel, y up"},
       {"crop_w", FieldKind::I32, "width, texels (0: no layer anywhere)"},
       {"crop_h", FieldKind::I32, "height, texels"},
       {"comp_side", FieldKind::U32, "side w_c of GL's compressed RG32UI texture (model/ldi/compression.h)"},
       {"comp_index", FieldKind::U32, "index-segment texels I = crop_w * crop_h"},
       {"comp_ranges", FieldKind::U32, "range-segment texels R"},
       {"compressed", FieldKind::VecU32, "GL's compressed texture read back: comp_side^2 texels, two channels each, row-major"}}};
  spec.rule = image_rule;
  return spec;
}

ChunkSpec ldi_tests_chunk_spec() {
  ChunkSpec spec{
      kLdiTestsChunk,
      "ldi",
      "LdiTests",
      {{"count", FieldKind::U32, "test points (every vector below has this many elements)"},
       {"epsilon", FieldKind::F64,
        "the reference's near-surface distance, unit-cube units along the ray: a point nearer a surface is counted apart"},
       {"kind", FieldKind::VecU32, "0 random, 1 crop boundary, 2 near a surface, 3 midway between layers"},
       {"x", FieldKind::VecI32, "texel column of the full LDI (may lie outside the crop, or the LDI)"},
       {"y", FieldKind::VecI32, "texel row, y up"},
       {"z", FieldKind::VecF32, "linear depth of the point, [0, 1]"},
       {"gl_inside_layers", FieldKind::VecU32, "GL's answer, uncompressed parity test on the cropped layers: 1 inside"},
       {"gl_fetches_layers", FieldKind::VecU32, "layer texels that shader read"},
       {"gl_inside_ranges", FieldKind::VecU32, "GL's answer, compressed parity test on the RG32UI texture: 1 inside"},
       {"gl_fetches_ranges", FieldKind::VecU32, "texels that shader read (1 index + the ranges up to the answer)"},
       {"reference", FieldKind::VecI32,
        "the exact reference: surface crossings along the texel-centre ray beyond the point (odd: inside), from the mesh in "
        "double precision; -1 within epsilon of a surface"}}};
  spec.rule = tests_rule;
  return spec;
}

namespace {

std::string all_layers_rule(const TechniqueRecord& r) {
  if (std::string problem = vector_lengths_problem(r, u(r, "count"), {"count"}, "test point"); !problem.empty()) return problem;
  const auto& inside = std::get<std::vector<std::uint32_t>>(find_field(r, "gl_inside_all")->value);
  for (std::size_t p = 0; p < inside.size(); ++p)
    if (inside[p] > 1) return fmt::format("field 'gl_inside_all' of test point {} is {}, above 1", p, inside[p]);
  return {};
}

}  // namespace

ChunkSpec ldi_all_layers_chunk_spec() {
  ChunkSpec spec{kLdiAllLayersChunk,
                 "ldi",
                 "LdiAllLayers",
                 {{"count", FieldKind::U32, "test points: LDIT's count (every vector below has this many elements)"},
                  {"gl_inside_all", FieldKind::VecU32, "GL's answer, the paper's reader (every layer of the texel read): 1 inside"},
                  {"gl_fetches_all", FieldKind::VecU32, "layer texels that shader read: d inside the crop, 0 outside"}}};
  spec.rule = all_layers_rule;
  return spec;
}

namespace {

std::string volume_rule(const TechniqueRecord& r) {
  const std::uint64_t w = u(r, "width"), h = u(r, "height"), layers = u(r, "layer_count"), side = u(r, "comp_side");
  if (w < 1 || w > kMaxSide || h < 1 || h > kMaxSide)
    return fmt::format("the LDI is {}x{} texels; each side must be 1 to {}", w, h, kMaxSide);
  if (layers > kMaxLayers) return fmt::format("layer_count is {}, above {}", layers, kMaxLayers);
  if (side > kMaxSide) return fmt::format("comp_side is {}, above {}", side, kMaxSide);
  if (length<float>(r, "layers") != static_cast<std::size_t>(layers * w * h))
    return fmt::format("field 'layers' has {} values, but layer_count x width x height is {}", length<float>(r, "layers"), layers * w * h);
  if (length<float>(r, "mesh_vertices") % 3 != 0 || length<std::uint32_t>(r, "mesh_triangles") % 3 != 0)
    return "the mesh's vertex and index counts must be multiples of 3";
  if (length<std::uint32_t>(r, "compressed") != 2 * side * side)
    return fmt::format("field 'compressed' has {} values, but comp_side {} needs {}", length<std::uint32_t>(r, "compressed"), side, 2 * side * side);
  const std::int64_t cx = i(r, "crop_x"), cy = i(r, "crop_y"), cw = i(r, "crop_w"), ch = i(r, "crop_h");
  if (cx < 0 || cy < 0 || cw < 0 || ch < 0 || cx + cw > static_cast<std::int64_t>(w) || cy + ch > static_cast<std::int64_t>(h))
    return fmt::format("the crop ({}, {}, {}x{}) is not inside the {}x{} LDI", cx, cy, cw, ch, w, h);
  return {};
}

std::string clip_rule(const TechniqueRecord& r) {
  const std::uint64_t volumes = u(r, "volume_count");
  if (volumes < 1 || volumes > 4) return fmt::format("volume_count is {}, not 1 to 4", volumes);
  if (u(r, "reader") > 2) return fmt::format("reader is {}, not 0 (layers), 1 (all) or 2 (ranges)", u(r, "reader"));
  if (length<float>(r, "view_proj") != 16) return fmt::format("field 'view_proj' has {} values, not 16", length<float>(r, "view_proj"));
  if (length<float>(r, "window_to_texel") != 16 * volumes)
    return fmt::format("field 'window_to_texel' has {} values, but {} volumes need {}", length<float>(r, "window_to_texel"), volumes, 16 * volumes);
  const std::size_t draws = length<std::uint32_t>(r, "draws");
  for (const char* name : {"keep_inside", "gl_discarded", "gl_fetches", "gl_hash_a", "gl_hash_b"})
    if (length<std::uint32_t>(r, name) != draws)
      return fmt::format("field '{}' has {} values, but there are {} draws", name, length<std::uint32_t>(r, name), draws);
  for (std::uint32_t k : std::get<std::vector<std::uint32_t>>(find_field(r, "keep_inside")->value))
    if (k > 1) return fmt::format("a keep_inside value is {}, not 0 or 1", k);
  return {};
}

}  // namespace

ChunkSpec ldi_volume_chunk_spec() {
  ChunkSpec spec{
      kLdiVolumeChunk,
      "ldi",
      "LdiVolume",
      {{"volume", FieldKind::U32, "the volume's number: the order of the volume tests"},
       {"shape", FieldKind::String, "its shape: a procedural shape's name (and parameter), or mesh:FILE"},
       {"center_x", FieldKind::F64, "the centre of its unit cube in the world, metres"},
       {"center_y", FieldKind::F64, "likewise, y (up)"},
       {"center_z", FieldKind::F64, "likewise, z"},
       {"size", FieldKind::F64, "the side of its unit cube in the world: world = centre + size (p - 0.5)"},
       {"mesh_vertices", FieldKind::VecF32, "the closed mesh in the unit cube, x y z a vertex (the exact reference's)"},
       {"mesh_triangles", FieldKind::VecU32, "its triangles, three vertex indices each, outward (counter-clockwise)"},
       {"view", FieldKind::VecF32, "the LDI's orthographic frame in the unit cube (viewpoint selection's choice): direction, right, up"},
       {"width", FieldKind::U32, "LDI width, texels"},
       {"height", FieldKind::U32, "LDI height, texels"},
       {"layer_count", FieldKind::U32, "the depth complexity d"},
       {"layers", FieldKind::VecF32, "the LDI as GL peeled it (as LdiImage's layers)"},
       {"crop_x", FieldKind::I32, "GL's crop: left texel"},
       {"crop_y", FieldKind::I32, "bottom texel"},
       {"crop_w", FieldKind::I32, "width, texels"},
       {"crop_h", FieldKind::I32, "height, texels"},
       {"comp_side", FieldKind::U32, "side of GL's compressed RG32UI texture"},
       {"compressed", FieldKind::VecU32, "GL's compressed texture, comp_side^2 texels of two values"}}};
  spec.rule = volume_rule;
  return spec;
}

ChunkSpec ldi_clip_chunk_spec() {
  ChunkSpec spec{
      kLdiClipChunk,
      "ldi",
      "LdiClip",
      {{"volume_count", FieldKind::U32, "volumes tested, in their LdiVolume order (1 to 4)"},
       {"reader", FieldKind::U32, "the shader's reader: 0 layers (early exit), 1 all layers (the paper's), 2 ranges (compressed)"},
       {"width", FieldKind::U32, "viewport width, pixels"},
       {"height", FieldKind::U32, "viewport height, pixels"},
       {"epsilon", FieldKind::F64, "the reference's near-surface distance, unit-cube units: nearer fragments are counted apart"},
       {"view_proj", FieldKind::VecF32, "the scene's view-projection uniform, column-major (clip control NEGATIVE_ONE_TO_ONE)"},
       {"window_to_texel", FieldKind::VecF32,
        "per volume, the uniform taking (gl_FragCoord.xyz, 1) to homogeneous (LDI texel x, y, linear depth), column-major"},
       {"draws", FieldKind::VecU32, "the draws that ran the volume test, in draw order (the others ran plain)"},
       {"keep_inside", FieldKind::VecU32, "per tested draw: 0 discards inside any volume (clipping), 1 outside every volume (a lens's focus)"},
       {"gl_discarded", FieldKind::VecU32, "per tested draw: GL's discarded fragments"},
       {"gl_fetches", FieldKind::VecU32, "per tested draw: texels GL's reader fetched"},
       {"gl_hash_a", FieldKind::VecU32, "per tested draw: the sum of a hash of each discarded fragment's pixel and depth bits (shaders/ldi/clip.frag)"},
       {"gl_hash_b", FieldKind::VecU32, "per tested draw: a second such sum"},
       {"depth_crc", FieldKind::U32, "CRC-32 of GL's depth buffer after the frame's draws (floats, y up)"}}};
  spec.rule = clip_rule;
  return spec;
}

namespace {

// "HxV": the viewpoint grid, each side 1 .. 1024.
bool valid_grid(std::string_view v) {
  const std::size_t x = v.find('x');
  if (x == std::string_view::npos) return false;
  const auto side = [](std::string_view s) {
    unsigned n = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), n);
    return ec == std::errc() && end == s.data() + s.size() && !s.starts_with('+') && n >= 1 && n <= 1024;
  };
  return side(v.substr(0, x)) && side(v.substr(x + 1));
}

}  // namespace

std::vector<HeaderKeySpec> ldi_header_keys() {
  const std::string t = "ldi";
  return {text_key(t, "shape", "nested", "the closed shape: a procedural shape's name, or mesh"),
          text_key(t, "shape_param", "3", "the procedural shape's parameter"),
          whole_key(t, "ldi_size", 1, static_cast<std::uint64_t>(ldi::kMaxSideTexels), "128", "side of the square LDI, texels"),
          custom_key(t, "grid", valid_grid, "HxV, each 1 .. 1024", "8x8", "the viewpoint-selection grid s_H x s_V"),
          whole_key(t, "max_layers", 1, static_cast<std::uint64_t>(ldi::kMaxLayers), "64", "most layers the peel stores"),
          whole_key(t, "points", 0, 0xFFFFFFFFu, "4096", "parity test points a frame"),
          real_key(t, "epsilon", 0.0, 1.0, false, "1e-05", "the parity test's depth tolerance"),
          whole_key(t, "ldi_seed", 0, 0xFFFFFFFFFFFFFFFFu, "1", "seed of the test points and the rotations"),
          whole_key(t, "mesh_vertices", 0, 0xFFFFFFFFu, "1086", "the shape's vertices"),
          whole_key(t, "mesh_triangles", 0, 0xFFFFFFFFu, "2160", "the shape's triangles"),
          text_key(t, "ldi_placement", "frame 0 unrotated, ...", "how each frame places the shape"),
          text_key(t, "ldi_depth", "peel: clip control ZERO_TO_ONE, ...", "the peel's depth convention"),
          choice_key(t, "ldi_application", {"clip", "lens"}, "clip", "the application in a scene (absent: one shape's LDI and test points)"),
          choice_key(t, "ldi_reader", {"all", "layers", "ranges"}, "all", "the reader of the applications' fragment shader"),
          text_key(t, "ldi_volumes", "auto", "the applications' volumes as given (auto, or SHAPE@X,Y,Z,SIZE;...)"),
          real_key(t, "ldi_lens_height", 0.0, 1.0, false, "0.25", "the lens's flattening of the objects inside its volumes")};
}

// This technique's part of the format (technique_chunks.h): the image and test-point chunks and the header keys.
TechniqueFormat ldi_format() {
  return {{ldi_image_chunk_spec(), ldi_tests_chunk_spec(), ldi_all_layers_chunk_spec(), ldi_volume_chunk_spec(), ldi_clip_chunk_spec()},
          ldi_header_keys()};
}

}  // namespace nbsim::trace

// Hand-made frames of the ldi technique for the tests (built in code, so these tests need no GL):
// a shape in the unit cube seen along -z (OrthoFrame's default: right +x, up +y), its triangles
// projected orthographically in double and rounded to float into clip positions (clip control
// zero-to-one, w = 1, so window depth is the linear depth d = 1 - z), one LdiPeel draw a pass, and
// the LDIL and LDIT records. What GL would record is taken from a stand-in LDI the test passes (the
// model's own peel unless a test changes it), with its crop, compressed texture and parity answers
// computed by model/ldi; the exact reference counts come from mesh::CrossingReference.
// Header-only: each test binary includes it once.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "model/ldi/compression.h"
#include "model/ldi/ldi.h"
#include "model/ldi/peel.h"
#include "model/ldi/vpt.h"
#include "model/mesh/crossings.h"
#include "model/mesh/mesh.h"
#include "model/scene/frame.h"
#include "model/ldi/roles.h"

namespace nbsim::ldi::testing {

// A vertex's clip position: x, y from the unit square to [-1, 1], z = 1 - p.z, w = 1.
inline std::vector<std::array<float, 4>> clip_positions(const mesh::TriMesh& m) {
  std::vector<std::array<float, 4>> out;
  out.reserve(m.triangles.size() * 3);
  for (const mesh::Tri& t : m.triangles)
    for (const std::uint32_t v : t) {
      const mesh::Vec3f& p = m.vertices[v];
      out.push_back({static_cast<float>(2.0 * static_cast<double>(p[0]) - 1.0), static_cast<float>(2.0 * static_cast<double>(p[1]) - 1.0),
                     static_cast<float>(1.0 - static_cast<double>(p[2])), 1.0f});
    }
  return out;
}

// The point of texel (x, y) of a w x h LDI at linear depth d, in the unit cube.
inline mesh::Vec3d texel_point(int x, int y, int w, int h, double d) {
  return {(x + 0.5) / w, (y + 0.5) / h, 1.0 - d};
}

// The peel draw's recorded state: LEQUAL, cull none, zero-to-one, the shader discards.
inline scene::DrawRecord peel_draw(const std::vector<std::array<float, 4>>& clip, std::uint32_t index) {
  scene::DrawRecord d;
  d.index = index;
  d.role = nbsim::ldi::kLdiPeelRole;
  d.state.func = scene::DepthFunc::Lequal;
  d.state.cull = scene::CullFace::None;
  d.state.clip = scene::ClipControl::ZeroToOne;
  d.clip_positions = clip;
  d.discards = true;
  return d;
}

inline scene::TechniqueField field(const char* name, auto value) { return scene::TechniqueField{name, value}; }

// LDIL for the stand-in LDI `gl`, fields in the registered order (traces/format/ldi/ldi_chunk.cpp).
inline scene::TechniqueRecord ldil_record(const Ldi& gl) {
  const CompressedLdi c = compress(gl);
  scene::TechniqueRecord r;
  r.type = kLdiImageRecordType;
  r.decoded = true;
  const std::uint64_t w = static_cast<std::uint64_t>(gl.width()), h = static_cast<std::uint64_t>(gl.height());
  r.fields = {field("width", w),
              field("height", h),
              field("layer_count", static_cast<std::uint64_t>(gl.layer_count())),
              field("grid_h", std::uint64_t{1}),
              field("grid_v", std::uint64_t{1}),
              field("direction", std::uint64_t{0}),
              field("view", std::vector<float>{0, 0, -1, 1, 0, 0, 0, 1, 0}),
              field("rotation", std::vector<float>{1, 0, 0, 0, 1, 0, 0, 0, 1}),
              field("candidate_d", std::vector<std::uint32_t>{static_cast<std::uint32_t>(gl.depth_complexity())}),
              field("candidate_coverage", std::vector<std::uint32_t>{static_cast<std::uint32_t>(c.crop.rect.area())}),
              field("layers", gl.depths()),
              field("crop_x", std::int64_t{c.crop.rect.x}),
              field("crop_y", std::int64_t{c.crop.rect.y}),
              field("crop_w", std::int64_t{c.crop.rect.w}),
              field("crop_h", std::int64_t{c.crop.rect.h}),
              field("comp_side", static_cast<std::uint64_t>(c.side)),
              field("comp_index", static_cast<std::uint64_t>(c.index_texels)),
              field("comp_ranges", static_cast<std::uint64_t>(c.range_texels)),
              field("compressed", c.texels)};
  return r;
}

// LDIT: for every `stride`-th texel (and a ring just outside the crop), a point midway between
// consecutive layers (and in front of the first and behind the last), one on each layer, and a
// pseudo-random one; GL's answers from the stand-in `gl`, the reference from `ref`.
inline scene::TechniqueRecord ldit_record(const Ldi& gl, const mesh::CrossingReference& ref, double epsilon, int stride = 3) {
  const CroppedLdi cropped = crop(gl);
  const CompressedLdi comp = compress(gl);
  std::vector<std::uint32_t> kind, inside_l, fetch_l, inside_r, fetch_r;
  std::vector<std::int32_t> xs, ys, reference;
  std::vector<float> zs;
  std::uint32_t seed = 12345;
  const auto add = [&](std::uint32_t k, int x, int y, float z) {
    kind.push_back(k), xs.push_back(x), ys.push_back(y), zs.push_back(z);
    const VptResult a = vpt_layers(cropped, x, y, z), b = vpt_ranges(comp, x, y, z);
    inside_l.push_back(a.inside ? 1 : 0), fetch_l.push_back(static_cast<std::uint32_t>(a.fetches));
    inside_r.push_back(b.inside ? 1 : 0), fetch_r.push_back(static_cast<std::uint32_t>(b.fetches));
    const mesh::CrossingCount n = ref.count(texel_point(x, y, gl.width(), gl.height(), z));
    reference.push_back(n.nearest_distance < epsilon || n.at_point > 0 ? -1 : static_cast<std::int32_t>(n.in_front));
  };
  for (int y = 0; y < gl.height(); y += stride)
    for (int x = 0; x < gl.width(); x += stride) {
      const int n = gl.count(x, y);
      for (int l = 0; l <= n; ++l) {
        const double lo = l == 0 ? 0.0 : gl.depth(x, y, l - 1), hi = l == n ? 1.0 : gl.depth(x, y, l);
        add(3, x, y, static_cast<float>(0.5 * (lo + hi)));
        if (l < n) add(2, x, y, gl.depth(x, y, l));
      }
      seed = seed * 1664525u + 1013904223u;
      add(0, x, y, static_cast<float>(seed >> 8) / 16777216.0f);
    }
  const Rect r = cropped.crop.rect;
  if (!r.empty())
    for (const auto& [x, y] : std::vector<std::array<int, 2>>{{r.x - 1, r.y}, {r.x, r.y}, {r.x1() - 1, r.y + r.h - 1}, {r.x1(), r.y + r.h / 2}})
      add(1, x, y, 0.5f);
  scene::TechniqueRecord t;
  t.type = kLdiTestsRecordType;
  t.decoded = true;
  t.fields = {field("count", static_cast<std::uint64_t>(kind.size())), field("epsilon", epsilon), field("kind", kind),
              field("x", xs), field("y", ys), field("z", zs), field("gl_inside_layers", inside_l),
              field("gl_fetches_layers", fetch_l), field("gl_inside_ranges", inside_r), field("gl_fetches_ranges", fetch_r),
              field("reference", reference)};
  return t;
}

// A frame of `m` peeled at w x h: the model's peel (a first run) is GL's stand-in for the layers and
// the counters, with one pass more than it has layers (the empty pass that ends the peel).
inline scene::Frame make_frame(const mesh::TriMesh& m, int w, int h, std::uint32_t frame_number = 0, double epsilon = 1e-6) {
  const auto clip = clip_positions(m);
  PeelReplay peel(w, h);
  scene::Frame f;
  f.begin.frame = frame_number;
  f.end.frame = frame_number;
  for (std::uint32_t pass = 0;; ++pass) {
    scene::DrawRecord d = peel_draw(clip, pass);
    const PeelPassCounts k = peel.pass(d.clip_positions, draw_state(d.state));
    d.gl.fragments = k.fragments;
    d.gl.samples_passed = k.samples;
    f.draws.push_back(std::move(d));
    if (k.samples == 0 || pass > 64) break;
  }
  f.end.draws = static_cast<std::uint32_t>(f.draws.size());
  const Ldi gl = peel.ldi();
  const mesh::CrossingReference ref(m, mesh::OrthoFrame{});
  f.technique_records.push_back(ldil_record(gl));
  f.technique_records.push_back(ldit_record(gl, ref, epsilon));
  return f;
}

// The record of `type` in a hand-made frame, and one of its fields, to damage them.
inline scene::TechniqueRecord& record(scene::Frame& f, std::uint32_t type) {
  for (scene::TechniqueRecord& r : f.technique_records)
    if (r.type == type) return r;
  throw std::logic_error("no such record");
}
inline scene::TechniqueField& field_of(scene::Frame& f, std::uint32_t type, const char* name) {
  for (scene::TechniqueField& x : record(f, type).fields)
    if (x.name == name) return x;
  throw std::logic_error("no such field");
}

}  // namespace nbsim::ldi::testing

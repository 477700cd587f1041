// LdiPeelTest: GL's depth peeling (traces/capture/ldi/peel.h) on llvmpipe against the exact crossing
// reference (model/mesh/crossings.h): every texel's layer list against the crossing depths along
// its centre line, for the procedural shapes from axis-aligned and oblique directions, and a box
// whose edges lie exactly on texel centres (the tie rule). Mismatching texels are printed with their
// distance to the nearest projected edge, in pixels: below GL's vertex snap (1/256 px) a
// disagreement is the snapping's, above it the reference's rule or view mapping.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "model/mesh/crossings.h"
#include "model/mesh/shapes.h"
#include "traces/capture/ldi/peel.h"
#include "tests/common/gl_context_suite.h"

namespace nbsim::capture {
namespace {

// Depth tolerance, per layer: the capture rounds each vertex's linear depth (computed in double)
// to float once (<= 2^-25 in [0.5, 1)), and llvmpipe interpolates the plane a0 + x dadx + y dady
// in float (a few more roundings of values of the order of 1): together below kFloatSlack = 2^-20.
// The larger term is GL's vertex snap: llvmpipe moves every vertex to its 1/256-pixel grid (up to
// 1/512 px in x and y), which tilts and shifts the triangle's depth plane; at the texel centre that
// changes the depth by about what moving the centre by the same distance does. So layer k's bound
// is kFloatSlack plus the largest change of the reference's k-th crossing depth when the texel-centre
// line moves by +-1/256 px in x or in y (twice the largest snap, for the tilt): steep faces near a
// silhouette get a wide bound, faces facing the view a tight one.
constexpr double kFloatSlack = 1.0 / 1048576.0;
constexpr double kSnapPx = 1.0 / 256.0;

struct Comparison {
  std::uint64_t texels = 0, layers = 0, count_mismatches = 0, snap_explained = 0;
  // The reference queried at the centre moved by (+1e-8, +1e-10) model units in (right, up): its
  // top-left rule then decides ties as a bottom-left rule (y up) would, i.e. as the centre moved by
  // (+e, +e^2). Counts GL's disagreements with that emulation.
  std::uint64_t count_mismatches_bottom_left = 0;
  std::uint64_t depth_violations = 0;  // layers beyond their bound
  double max_error = 0.0, max_error_ratio = 0.0, max_bound = 0.0;
  std::string first_mismatches;
};


// Distance, in pixels, from texel (x, y)'s centre to the nearest projected mesh edge.
double nearest_edge_px(const mesh::TriMesh& m, const OrthoMapping& map, int x, int y) {
  const double px = x + 0.5, py = y + 0.5;
  double best = 1e300;
  for (const mesh::Tri& t : m.triangles)
    for (int i = 0; i < 3; ++i) {
      const mesh::Vec3f& a = m.vertices[t[i]];
      const mesh::Vec3f& b = m.vertices[t[(i + 1) % 3]];
      const auto pa = map.project({a[0], a[1], a[2]}), pb = map.project({b[0], b[1], b[2]});
      const double ax = (pa[0] + 1) * map.width / 2, ay = (pa[1] + 1) * map.height / 2;
      const double bx = (pb[0] + 1) * map.width / 2, by = (pb[1] + 1) * map.height / 2;
      const double dx = bx - ax, dy = by - ay, len2 = dx * dx + dy * dy;
      const double s = len2 > 0 ? std::clamp(((px - ax) * dx + (py - ay) * dy) / len2, 0.0, 1.0) : 0.0;
      best = std::min(best, std::hypot(px - ax - s * dx, py - ay - s * dy));
    }
  return best;
}

Comparison compare(const mesh::TriMesh& m, const mesh::OrthoFrame& frame, int w, int h, const std::string& what) {
  const PeelResult r = peel_ldi(m, frame, {.width_px = w, .height_px = h, .max_layers = 64});
  const OrthoMapping map = OrthoMapping::fit_unit_cube(frame, w, h);
  const mesh::CrossingReference ref(m, frame);
  Comparison c;
  int shown = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      ++c.texels;
      const std::vector<double> t = ref.crossing_depths(map.texel_line_point(x, y));
      const int n = r.ldi.count(x, y);
      {
        mesh::Vec3d q = map.texel_line_point(x, y);
        for (int i = 0; i < 3; ++i) q[i] += 1e-8 * frame.right[i] + 1e-10 * frame.up[i];
        if (ref.crossing_depths(q).size() != static_cast<std::size_t>(n)) ++c.count_mismatches_bottom_left;
      }
      if (static_cast<std::size_t>(n) != t.size()) {
        ++c.count_mismatches;
        const double edge = nearest_edge_px(m, map, x, y);
        if (edge < 1.0 / 256.0) ++c.snap_explained;
        if (shown++ < 12)
          c.first_mismatches += what + ": texel (" + std::to_string(x) + ", " + std::to_string(y) + ") GL " +
                                std::to_string(n) + " layers, reference " + std::to_string(t.size()) +
                                ", nearest edge " + std::to_string(edge) + " px\n";
        continue;
      }
      // The snap bound: the reference's depths along lines moved by +-1/256 px.
      std::vector<double> bound(t.size(), kFloatSlack);
      const double du = (map.u1 - map.u0) / w * kSnapPx, dv = (map.v1 - map.v0) / h * kSnapPx;
      const double shifts[4][2] = {{du, 0}, {-du, 0}, {0, dv}, {0, -dv}};
      for (const auto& sh : shifts) {
        mesh::Vec3d q = map.texel_line_point(x, y);
        for (int i = 0; i < 3; ++i) q[i] += sh[0] * frame.right[i] + sh[1] * frame.up[i];
        const std::vector<double> ts = ref.crossing_depths(q);
        if (ts.size() != t.size()) continue;
        for (std::size_t k = 0; k < t.size(); ++k)
          bound[k] = std::max(bound[k], kFloatSlack + std::abs(map.linear_depth(ts[k]) - map.linear_depth(t[k])));
      }
      for (int k = 0; k < n; ++k) {
        ++c.layers;
        const double e = std::abs(double(r.ldi.depth(x, y, k)) - map.linear_depth(t[k]));
        c.max_error = std::max(c.max_error, e);
        c.max_error_ratio = std::max(c.max_error_ratio, e / bound[k]);
        c.max_bound = std::max(c.max_bound, bound[k]);
        if (e > bound[k]) ++c.depth_violations;
      }
    }
  std::cerr << what << ": " << c.texels << " texels, " << c.layers << " layers compared, d = "
            << r.ldi.depth_complexity() << ", " << r.passes.size() << " passes, count mismatches "
            << c.count_mismatches << " (" << c.snap_explained << " within 1/256 px of an edge; "
            << c.count_mismatches_bottom_left << " against a bottom-left tie rule), max depth error " << c.max_error
            << ", max error / bound " << c.max_error_ratio << ", largest bound " << c.max_bound << ", layers beyond bound "
            << c.depth_violations << "\n"
            << c.first_mismatches;
  return c;
}

mesh::TriMesh placed(const char* shape, std::optional<int> parameter = std::nullopt) {
  mesh::TriMesh m = mesh::make_shape(shape, parameter);
  mesh::normalize_to_unit_cube(m, 0.05);
  return m;
}

// An axis-aligned box [x0, x1] x [y0, y1] x [z0, z1], outward counter-clockwise.
mesh::TriMesh box(float x0, float x1, float y0, float y1, float z0, float z1) { return mesh::make_box({x0, y0, z0}, {x1, y1, z1}); }

class LdiPeelTest : public testing::GlContextSuite {};

std::vector<mesh::OrthoFrame> directions() {
  return {mesh::OrthoFrame::look_along({0, 0, -1}),  mesh::OrthoFrame::look_along({1, 0, 0}),
          mesh::OrthoFrame::look_along({0, -1, 0}, {0, 0, 1}), mesh::OrthoFrame::look_along({1, 2, -3}),
          mesh::OrthoFrame::look_along({-0.3, 0.7, 0.5})};
}

void expect_agrees(const mesh::TriMesh& m, const char* name) {
  const std::pair<int, int> sizes[] = {{64, 64}, {128, 96}};
  int dir = 0;
  for (const mesh::OrthoFrame& f : directions()) {
    for (auto [w, h] : sizes) {
      const std::string what = std::string(name) + " dir " + std::to_string(dir) + " " + std::to_string(w) + "x" +
                               std::to_string(h);
      const Comparison c = compare(m, f, w, h, what);
      EXPECT_GT(c.layers, 0u) << what << ": the shape must cover texels";
      EXPECT_EQ(c.count_mismatches, c.snap_explained)
          << what << ": every layer-count disagreement must lie within GL's 1/256 px vertex snap of an edge";
      EXPECT_EQ(c.depth_violations, 0u) << what << ": layer depths within the float + vertex-snap bound";
    }
    ++dir;
  }
}

// The paper's UV sphere (d = 2).
TEST_F(LdiPeelTest, SphereMatchesReference) { expect_agrees(placed("sphere"), "sphere"); }
// The torus knot (about 23,000 vertices).
TEST_F(LdiPeelTest, KnotMatchesReference) { expect_agrees(placed("knot"), "knot"); }
// Three nested shells (d = 6).
TEST_F(LdiPeelTest, NestedMatchesReference) { expect_agrees(placed("nested", 3), "nested"); }
// The coil spring (d grows with its turns).
TEST_F(LdiPeelTest, CoilMatchesReference) { expect_agrees(placed("coil"), "coil"); }

// A box whose edges lie exactly on texel centres seen along -z (texel columns 8 and 40, rows 10
// and 33): every silhouette edge is a tie, decided by the fill rule. Measured on llvmpipe (Mesa
// 22.3, rendering into an FBO, y up): the left column (x = 8) and the BOTTOM row (y = 10) are
// covered, the right column (x = 40) and the TOP row (y = 33) are not: a bottom-left rule in y-up
// window coordinates (llvmpipe's top-left rule in its y-down coordinates, with an FBO's row 0 at
// its "top"). The crossing reference (model/mesh/crossings.h) uses top-left in y up: it agrees on
// the columns and disagrees on both rows, 32 texels each (row 10: GL 2 layers, reference 0; row 33:
// GL 0, reference 2). Its horizontal-edge tie must become "dy == 0 and dx > 0" (the line moved by
// (+e, +e^2), not (+e, -e^2)); queried at the centre moved by (+1e-8, +1e-10) it matches GL exactly.
TEST_F(LdiPeelTest, BoxEdgesOnTexelCentresFollowTheTieRule) {
  const mesh::TriMesh m = box(8.5f / 64, 40.5f / 64, 10.5f / 64, 33.5f / 64, 0.25f, 0.75f);
  const Comparison c = compare(m, mesh::OrthoFrame::look_along({0, 0, -1}), 64, 64, "box on texel centres");
  // GL covers columns 8..39 and rows 10..32 with two layers.
  EXPECT_EQ(c.layers, 2u * 32u * 23u) << "two layers on the 32 x 23 texels both cover";
  EXPECT_EQ(c.count_mismatches_bottom_left, 0u) << "GL's ties follow a bottom-left rule (y up)";
  // The reference follows the same rule (model/mesh/crossings.h): every texel agrees.
  EXPECT_EQ(c.count_mismatches, 0u) << "the reference's tie rule is GL's";
  EXPECT_EQ(c.depth_violations, 0u) << "layer depths within the float + vertex-snap bound";
}

// Coplanar faces (the hard case): two closed boxes stacked along z, touching at z = 0.5, seen
// along -z. The reference lists 4 crossings on a line through both (the shared plane twice); the
// strict peel collapses the two equal depths into one layer, so GL has 3 layers there: an odd count
// on a closed solid, exactly one layer per distinct reference depth.
TEST_F(LdiPeelTest, CoplanarFacesCollapseIntoOneLayer) {
  mesh::TriMesh m = box(0.25f, 0.75f, 0.25f, 0.75f, 0.5f, 0.75f);
  const mesh::TriMesh lower = box(0.25f, 0.75f, 0.25f, 0.75f, 0.25f, 0.5f);
  const auto base = static_cast<std::uint32_t>(m.vertices.size());
  m.vertices.insert(m.vertices.end(), lower.vertices.begin(), lower.vertices.end());
  for (mesh::Tri t : lower.triangles) m.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  const mesh::OrthoFrame frame = mesh::OrthoFrame::look_along({0, 0, -1});
  const PeelResult r = peel_ldi(m, frame, {.width_px = 32, .height_px = 32, .max_layers = 8});
  const OrthoMapping map = OrthoMapping::fit_unit_cube(frame, 32, 32);
  const mesh::CrossingReference ref(m, frame);
  int odd = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      std::vector<double> t = ref.crossing_depths(map.texel_line_point(x, y));
      t.erase(std::unique(t.begin(), t.end()), t.end());
      ASSERT_EQ(static_cast<std::size_t>(r.ldi.count(x, y)), t.size())
          << "texel (" << x << ", " << y << "): one layer per distinct crossing depth";
      if (r.ldi.count(x, y) == 3) {
        ++odd;
        EXPECT_EQ(r.ldi.depth(x, y, 1), 0.5f) << "the shared plane is one layer at depth 0.5";
      }
    }
  EXPECT_EQ(odd, 16 * 16) << "every texel of the stacked boxes has 3 layers (odd)";
}

// Per pass, GL's counters: the same draw rasterizes the same fragments each pass, one per crossing
// of a texel-centre line (no culling, no equal depths on these shapes), so a pass's fragment count
// equals the LDI's total layer count; samples passed cover at least the texels holding layer k, and
// the last pass writes nothing.
TEST_F(LdiPeelTest, PassCountersMatchTheLayers) {
  for (const char* shape : {"sphere", "nested", "coil"}) {
    const PeelResult r = peel_ldi(placed(shape), mesh::OrthoFrame::look_along({1, 2, -3}),
                                  {.width_px = 64, .height_px = 48, .max_layers = 64});
    ASSERT_EQ(r.passes.size(), static_cast<std::size_t>(r.ldi.layer_count()) + 1) << shape;
    std::uint64_t total = 0;
    std::vector<std::uint64_t> texels_with(static_cast<std::size_t>(r.ldi.layer_count()) + 1, 0);
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 64; ++x) {
        total += static_cast<std::uint64_t>(r.ldi.count(x, y));
        for (int k = 0; k < r.ldi.count(x, y); ++k) ++texels_with[static_cast<std::size_t>(k)];
      }
    for (std::size_t k = 0; k < r.passes.size(); ++k) {
      EXPECT_EQ(r.passes[k].fragments, total) << shape << " pass " << k << ": one fragment per crossing";
      EXPECT_GE(r.passes[k].samples_passed, texels_with[k]) << shape << " pass " << k << ": layer k's texels";
    }
    EXPECT_EQ(r.passes.back().samples_passed, 0u) << shape << ": the last pass ends the peel";
  }
}

// A shape deeper than max_layers is refused, naming the limit.
TEST_F(LdiPeelTest, TooManyLayersIsRefused) {
  try {
    peel_ldi(placed("nested", 3), mesh::OrthoFrame::look_along({0, 0, -1}), {.width_px = 32, .height_px = 32, .max_layers = 4});
    FAIL() << "a d = 6 shape must not fit 4 layers";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("max_layers"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace nbsim::capture

// The procedural closed shapes of the layered-depth-image captures (Trapp & Doellner's test shapes
// and harder ones): a UV sphere of the paper's 994 vertices (d = 2), a (p, q) torus-knot tube of
// about 23,000 vertices, nested shells (d = 2k) and a coiled tube spring (d grows with its turns
// along its axis). Each is closed and outward-oriented (counter-clockwise seen from outside), with
// parameters and a name in one table, so that a capture can choose `--shape sphere|knot|nested|coil`.
// Model units are arbitrary: the capture places a shape with normalize_to_unit_cube (mesh.h).
#pragma once

#include <array>

#include <optional>
#include <span>
#include <string_view>

#include "model/mesh/mesh.h"

namespace nbsim::mesh {

// Latitude rings (poles excluded) x segments + 2 poles. The default is the paper's sphere:
// 31 x 32 + 2 = 994 vertices, 1,984 triangles.
struct SphereParams {
  int rings = 31;     // >= 1
  int segments = 32;  // >= 3
  double radius = 1.0;
};
TriMesh make_uv_sphere(const SphereParams& p = {});

// A tube of circular cross-section around the (p, q) torus knot on a torus of radii major/minor
// (the curve winds p times around the torus axis and q times through its hole; p and q coprime).
// curve_samples x tube_sides vertices: the default 720 x 32 = 23,040 (the paper's knot has about
// 23,000). The tube radius is chosen so that the tube never meets itself (tested).
struct TorusKnotParams {
  int p = 2, q = 3;
  int curve_samples = 720;  // >= 3
  int tube_sides = 32;      // >= 3
  double major_radius = 2.0, minor_radius = 0.8, tube_radius = 0.3;
};
TriMesh make_torus_knot(const TorusKnotParams& p = {});

// k concentric UV spheres of radii 1, (k-1)/k, ..., 1/k, alternately oriented (the outermost
// outward, the next inward, ...): the solid is k nested hollow shells, and a line through the centre
// crosses 2k surfaces, so d = 2k (k = 3 to 9 gives d = 6 to 18).
struct NestedParams {
  int shells = 3;     // k >= 1
  int rings = 15;     // per sphere
  int segments = 24;  // per sphere
};
TriMesh make_nested_shells(const NestedParams& p = {});

// A helical tube spring around the z axis with `turns` turns, closed by flat caps at both ends.
// Seen along its axis, a line through the coil's rim crosses the tube twice per turn (d = 2 turns, up
// to 2 turns + 2 where a line also meets an end cap);
// the pitch keeps successive turns apart (pitch > 2 tube radius, tested).
struct CoilParams {
  int turns = 4;               // >= 1
  int samples_per_turn = 96;   // >= 3
  int tube_sides = 24;         // >= 3
  double coil_radius = 1.0, tube_radius = 0.25, pitch = 0.7;  // pitch: rise per turn along z
};
TriMesh make_coil(const CoilParams& p = {});

// A core of `core_shells` nested shells (make_nested_shells, radius 1) with `beads` spheres of
// radius 1/2 strung after it along `axis`, apart from the core and each other (gap 1/10). Across the
// string a line meets at most the core (2 core_shells surfaces); along it, the core and every bead:
// d ranges from 2 core_shells to 2 (core_shells + beads) over the viewing directions, the spread of
// depth complexity over directions that Trapp & Doellner's Table 1 reports as d_min and d_max. The
// default axis is a view of the default 8x8 viewpoint grid (the paper's; grid_frame h 0, v 4:
// azimuth 22.5 degrees, y 1/8), so that the view along the string is one of the candidates.
struct BeadsParams {
  int core_shells = 1;  // >= 1
  int beads = 2;        // >= 0
  Vec3d axis = {0.9166333066528043, 0.125, 0.3796819473384877};  // the string's direction (normalized when used)
  int rings = 15;       // per sphere
  int segments = 24;    // per sphere
};
TriMesh make_beads(const BeadsParams& p = {});

// An axis-aligned cube [lo, hi]^3: 8 shared corners (bit 0 = x, bit 1 = y, bit 2 = z), 12
// triangles counter-clockwise seen from outside. The unit cube itself (the default) is the shape
// that touches every face of the LDI's cube, and its edges fall on texel centres: the tie cases.
TriMesh make_box(float lo = 0.0f, float hi = 1.0f);
// The box [lo.x, hi.x] x [lo.y, hi.y] x [lo.z, hi.z], the same 12 triangles.
TriMesh make_box(const std::array<float, 3>& lo, const std::array<float, 3>& hi);

// The shape table (a capture's `--shape NAME [--shape-param N]`): one row per shape. `parameter`
// names its one integer parameter ("" when it has none), with its default and limits. `beads`
// takes two numbers in one: KM (two digits, K core shells 1..9, M beads 0..9), so beads:12 is one
// shell and two beads (d 2 to 6).
struct ShapeEntry {
  std::string_view name;
  std::string_view summary;
  std::string_view parameter;
  int default_parameter;
  int min_parameter, max_parameter;
  TriMesh (*make)(int parameter);
};
std::span<const ShapeEntry> shape_table();
// Builds a shape by name; parameter defaults to the row's. Throws InputError (listing the names)
// for an unknown name, or for a parameter outside the row's limits or given to a shape without one.
TriMesh make_shape(std::string_view name, std::optional<int> parameter = std::nullopt);

}  // namespace nbsim::mesh

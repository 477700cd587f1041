// Closed triangle meshes for the layered depth images (Trapp & Doellner): the mesh type that the
// procedural shapes (shapes.h), the assimp loader (traces/capture/ldi/mesh_loader.h) and the exact
// crossing reference (crossings.h) share, its closedness check and its placement in the unit cube.
// Plain C++ (no SystemC, no GL). The volumetric parity test is only meaningful on a watertight,
// consistently oriented surface, so a mesh is checked here before it is peeled: a mesh with a hole is
// refused or reported, never silently peeled.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace nbsim::mesh {

using Vec3f = std::array<float, 3>;
using Vec3d = std::array<double, 3>;
using Tri = std::array<std::uint32_t, 3>;

// Float vertices (as GL receives them) and uint32 triangles, counter-clockwise seen from outside
// (the right-hand normal points out of the solid). Vertices may be duplicated at one position
// (STL files, seams of parametric shapes): check_mesh welds them by exact position.
struct TriMesh {
  std::vector<Vec3f> vertices;
  std::vector<Tri> triangles;
};

// What check_mesh found. Counts are over the whole mesh; `first_problem` names the first problem in
// the order of the checks below (empty "" when there is none), with the triangle and edge involved.
struct MeshReport {
  std::size_t vertex_count = 0;
  std::size_t triangle_count = 0;
  std::size_t welded_vertex_count = 0;        // distinct positions among the used vertices
  std::size_t out_of_range_triangles = 0;     // an index >= vertex_count (left out of the edge check)
  std::size_t non_finite_vertices = 0;        // a NaN or infinite coordinate
  std::size_t degenerate_triangles = 0;       // zero area in double, or two corners at one position
  std::size_t boundary_edges = 0;             // an edge used by one triangle (a hole's rim)
  std::size_t non_manifold_edges = 0;         // an edge used by three or more triangles
  std::size_t inconsistent_edges = 0;         // used twice, in the same direction (flipped triangle)
  std::size_t edge_count = 0;                 // undirected edges between welded positions
  std::string first_problem;

  // Watertight and consistently oriented: every edge used exactly twice, in opposite directions.
  bool closed() const noexcept {
    return triangle_count > 0 && out_of_range_triangles == 0 && boundary_edges == 0 && non_manifold_edges == 0 &&
           inconsistent_edges == 0;
  }
  // Fit for the parity test: closed, and nothing degenerate or non-finite.
  bool ok() const noexcept { return closed() && non_finite_vertices == 0 && degenerate_triangles == 0; }
};

// Checks a mesh, in this order: empty (no triangles), out-of-range indices, non-finite vertices,
// degenerate triangles (the cross product of two edges, computed in double from the float corners,
// is exactly zero, or two corners sit at one position), then closedness. Closedness is topological
// on positions: vertices are first welded by exact position (-0.0 and +0.0 are one position), then
// every undirected edge must be used by exactly two triangles that traverse it in opposite
// directions. Triangles with two corners at one position have no proper edges and are left out of
// the edge check (they are already counted as degenerate); zero-area triangles with three distinct
// positions take part. Never throws.
MeshReport check_mesh(const TriMesh& m);

// Throws InputError "<what>: <first problem>" unless check_mesh(m).ok(); returns the report.
MeshReport require_closed(const TriMesh& m, const std::string& what);

// Where normalize_to_unit_cube put the mesh: p' = p * scale + offset (per axis, in double).
struct UnitCubePlacement {
  double scale = 1.0;
  Vec3d offset{};
};

// Scales uniformly and translates the mesh into [0, 1]^3: the bounding box's longest axis maps onto
// [margin, 1 - margin] and the other axes are centred. margin is in [0, 0.5); with margin 0 the
// shape touches the two cube faces of its longest axis (its extreme vertices land on exactly 0.0 and
// 1.0, the "shape touching the cube's faces" hard case: its back face sits at the far depth 1.0).
// Computed in double and clamped to [0, 1] after the rounding to float, so no vertex leaves the cube.
// Throws InputError for an empty mesh, non-finite vertices, a zero-size bounding box or a bad margin.
UnitCubePlacement normalize_to_unit_cube(TriMesh& m, double margin);

// The enclosed volume (divergence theorem, in double): positive for an outward-oriented closed mesh.
double signed_volume(const TriMesh& m);

}  // namespace nbsim::mesh

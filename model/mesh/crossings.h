// The exact reference of the volumetric parity test (Trapp & Doellner): for an orthographic view
// and a line through a point parallel to the view direction, the surface crossings in front of the
// point and beyond it, and the distance along the line to the nearest one. The VPT's answer (odd
// number of layers in front = inside) is compared against this count, with points closer than a
// stated epsilon to a surface counted apart (nearest_distance says which). Plain C++, double
// precision; GL is not involved.
//
// Watertight by construction, as a rasterizer: triangles are projected onto the view plane, their
// corners snapped to a fine fixed-point grid (2^-40 of the mesh's projected extent, about 1e-12 in
// the unit cube, far below float's 6e-8; the query point's line is snapped to the same grid), and
// the three edge functions of each triangle evaluated exactly in 128-bit integers, so that the two
// triangles sharing an edge see exactly opposite values and a vertex's fan agrees on which triangle
// holds a line through it (double-precision edge functions can break both near an edge). Crossing
// depths come from the exact barycentric weights and the corners' double depths. A line exactly on
// an edge or a vertex is decided by
// llvmpipe's fill rule as GL applies it to an FBO: top-left in GL's y-down rasterizer space, whose
// row 0 is the FBO's bottom row, so bottom-left in the view plane's (right, up) coordinates, y up
// (measured: LdiPeelTest.BoxEdgesOnTexelCentresFollowTheTieRule). An edge function that is
// exactly zero counts as inside when the edge, walked in the triangle's order, runs downward
// (dy < 0) or exactly horizontal rightward (dy == 0, dx > 0). That is the same as moving the line
// by an infinitesimal (+e, +e^2) in (right, up), for both orientations of the projected triangle,
// so a line through a shared edge or vertex
// counts each crossing once, and one grazing a silhouette edge counts 0 or 2 (parity kept). A
// triangle whose projection has zero area (its plane contains the view direction: edge-on) counts 0.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "model/mesh/mesh.h"

namespace nbsim::mesh {

// An orthographic view: depth grows along `direction` (the way the camera looks); right and up
// span the view plane (right x up = -direction, as glm::lookAt's camera axes).
struct OrthoFrame {
  Vec3d direction{0.0, 0.0, -1.0};
  Vec3d right{1.0, 0.0, 0.0};
  Vec3d up{0.0, 1.0, 0.0};

  // The camera axes of glm::lookAt(eye, eye + direction, up_hint): right = normalize(direction x
  // up_hint), up = right x direction. Throws InputError for a zero or non-finite direction, or one
  // parallel to up_hint.
  static OrthoFrame look_along(const Vec3d& direction, const Vec3d& up_hint = {0.0, 1.0, 0.0});
};

struct CrossingCount {
  std::uint32_t in_front = 0;  // crossings strictly nearer than the point (depth < the point's)
  std::uint32_t beyond = 0;    // crossings strictly farther (depth > the point's)
  std::uint32_t at_point = 0;  // crossings at exactly the point's depth (the point is on the surface)
  double nearest_distance = std::numeric_limits<double>::infinity();  // |depth difference| to the nearest
  // The exact parity answer: inside a closed, outward-oriented mesh iff odd.
  bool inside() const noexcept { return in_front % 2 == 1; }
};

// Built once per mesh and view (projection, snapping, a uniform grid over the view plane), then
// queried per point; thread-compatible (const queries). The mesh should pass check_mesh (closed)
// for the counts to mean inside/outside; any mesh with in-range indices and finite vertices is
// accepted (InputError otherwise).
class CrossingReference {
 public:
  CrossingReference(const TriMesh& m, const OrthoFrame& frame);

  // Depths (dot(x, direction)) of every crossing of the line through `point`, ascending.
  std::vector<double> crossing_depths(const Vec3d& point) const;
  CrossingCount count(const Vec3d& point) const;

  const OrthoFrame& frame() const noexcept { return frame_; }
  // The grid step of the snapped view-plane coordinates (model units).
  double snap_step() const noexcept { return 1.0 / scale_; }

 private:
  struct Projected {
    std::int64_t x[3], y[3];  // snapped view-plane corners
    double depth[3];          // dot(corner, direction)
  };
  bool snap(const Vec3d& p, std::int64_t& x, std::int64_t& y) const;

  OrthoFrame frame_;
  double scale_ = 1.0;  // view-plane units -> grid units
  std::int64_t lo_x_ = 0, lo_y_ = 0, hi_x_ = 0, hi_y_ = 0;
  std::int64_t cell_ = 1;
  std::int64_t cells_x_ = 1, cells_y_ = 1;
  std::vector<Projected> tris_;
  std::vector<std::uint32_t> cell_start_, cell_tris_;
};

}  // namespace nbsim::mesh

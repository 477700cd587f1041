// The relief technique's camera on its box or reverse-perspective frustum (traces/capture/relief/
// relief.h): a perspective view from `angle_deg` off the up axis (0 head-on from above, 90 level,
// up to 180 from below) at `azimuth_deg`, framing the whole volume, and the ray frame of
// model/relief/walk.h computed from it in double and rounded to float once.
// The volume in world space: the box [0, 1]^2 x [0, box_height]; or, with apex > 0, the frustum over
// the same bottom face whose side edges meet at the apex (0.5, 0.5, -apex * box_height) below it (a
// reverse perspective: the top face is the larger), mapped onto texel space by the projective
// frustum_map (world -> texel space, homogeneous: x and y through the apex, the height so that the
// bottom and top faces land on z = 0 and 1).
#pragma once

#include <array>

#include "traces/capture/relief/gl_walk.h"

namespace nbsim::capture {

struct ReliefCamera {
  ReliefView view;                      // what GL and the model use
  std::array<double, 16> world_view{}, projection{};  // column-major
  std::array<double, 3> eye_world{};
};

// World to texel space, column-major 4x4 (the box: a scale; the frustum: projective).
std::array<double, 16> frustum_map(int field_size, double box_height, double apex);

ReliefCamera relief_camera(int field_size, double box_height, double angle_deg, double azimuth_deg, int width, int height,
                           double apex = 0.0);

// Any camera (view and projection, column-major, as GL takes them) on a volume mapped onto texel
// space by `world_to_texel` (column-major 4x4; affine: a box, its last row 0 0 0 1; else a frustum).
ReliefCamera relief_view(const std::array<double, 16>& view, const std::array<double, 16>& projection,
                         const std::array<double, 16>& world_to_texel, int width, int height);

}  // namespace nbsim::capture

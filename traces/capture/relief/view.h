// The relief technique's camera on the box (traces/capture/relief/relief.h): a perspective view of
// the box [0, 1]^2 x [0, box_height] (world) from `angle_deg` off its up axis at `azimuth_deg`,
// framing the whole box, and the ray frame of model/relief/walk.h computed from it in double.
#pragma once

#include <array>

#include "traces/capture/relief/gl_walk.h"

namespace nbsim::capture {

struct ReliefCamera {
  ReliefView view;                      // what GL and the model use
  std::array<double, 16> world_view{}, projection{};  // column-major
  std::array<double, 3> eye_world{};
  std::array<double, 3> origin{}, a{}, b{}, c{};  // the ray frame in double (texel space)
};

ReliefCamera relief_camera(int field_size, double box_height, double angle_deg, double azimuth_deg, int width, int height);

}  // namespace nbsim::capture

// The exact reference of a relief ray (heightfield.h's conventions): the first point where the ray
// meets the bilinear surface, in double precision. Cell by cell along the ray (every cell the ray's
// horizontal projection crosses, in order, the virtual border cells included), the height above
// the surface along the ray inside a cell is a quadratic in t; its first root in the cell's
// parameter interval is the hit (a tangent touch, a double root, counts as a hit).
#pragma once

#include <array>

#include "model/relief/heightfield.h"

namespace nbsim::relief {

struct ReferenceHit {
  bool hit = false;
  double t = 0.0;  // the ray parameter of the hit (valid when hit)
};

// The ray p(t) = origin + t * direction (texel space), from t_enter to t_exit (the caller's box
// interval, t_enter <= t_exit). A ray whose start is already below the surface hits at t_enter.
ReferenceHit reference_hit(const Heightfield& field, const std::array<double, 3>& origin, const std::array<double, 3>& direction,
                           double t_enter, double t_exit);

}  // namespace nbsim::relief

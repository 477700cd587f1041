// Hit error against the exact reference; see score.h.
#include "model/relief/score.h"

#include <cmath>

#include "model/relief/reference.h"

namespace nbsim::relief {

HitScore score_hit(const Heightfield& field, const FragmentRay& ray, bool hit, float t, double box_height, double tolerance) {
  const std::array<double, 3> o = {ray.o[0], ray.o[1], ray.o[2]}, d = {ray.d[0], ray.d[1], ray.d[2]};
  const ReferenceHit ref = reference_hit(field, o, d, ray.t_in, ray.t_out);
  HitScore s;
  s.reference_hit = ref.hit;
  if (hit && !ref.hit) {
    s.error = HitError::WrongHit;
  } else if (!hit && ref.hit) {
    s.error = HitError::WrongMiss;
  } else if (hit) {
    const double dt = static_cast<double>(t) - ref.t, zs = box_height * field.size;
    s.distance = std::abs(dt) * std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * zs * d[2] * zs);
    if (s.distance > tolerance) s.error = HitError::FarHit;
  }
  return s;
}

}  // namespace nbsim::relief

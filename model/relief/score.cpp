// Hit error against the exact reference; see score.h.
#include "model/relief/score.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "model/relief/reference.h"

namespace nbsim::relief {

HitScore score_hit(const Heightfield& field, const FragmentRay& ray, bool hit, float t, double box_height, double tolerance) {
  const std::array<double, 3> o = {ray.o[0], ray.o[1], ray.o[2]}, d = {ray.d[0], ray.d[1], ray.d[2]};
  // The reference's own interval: the double ray clipped to the box in double (the float interval,
  // taken over, would leave a ray that ends on the box's floor a hair above it: the floor of height
  // 0 is the box's bottom face, which every ray leaving through it has crossed).
  double t_in = 0.0, t_out = std::numeric_limits<double>::infinity();
  const double hi[3] = {static_cast<double>(field.size), static_cast<double>(field.size), 1.0};
  for (int k = 0; k < 3; ++k) {
    if (d[static_cast<std::size_t>(k)] == 0.0) continue;
    const double t1 = (0.0 - o[static_cast<std::size_t>(k)]) / d[static_cast<std::size_t>(k)];
    const double t2 = (hi[k] - o[static_cast<std::size_t>(k)]) / d[static_cast<std::size_t>(k)];
    t_in = std::max(t_in, std::min(t1, t2));
    t_out = std::min(t_out, std::max(t1, t2));
  }
  if (!(t_in <= t_out) || !std::isfinite(t_out)) t_in = t_out = static_cast<double>(ray.t_in);  // a grazing float ray: its one point
  const ReferenceHit ref = reference_hit(field, o, d, t_in, t_out);
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

// Hit error against the exact reference; see score.h.
#include "model/relief/score.h"

#include <algorithm>
#include <cmath>
#include <limits>


namespace nbsim::relief {

ReferenceHit reference_of(const Heightfield& field, const FragmentRay& ray, const ReferenceBlocks* blocks) {
  const std::array<double, 3> o = {ray.o[0], ray.o[1], ray.o[2]}, d = {ray.d[0], ray.d[1], ray.d[2]};
  // The reference's own interval: the double ray clipped to the box in double (the float interval,
  // taken over, would leave a ray that ends on the box's floor a hair above it: the floor of height
  // 0 is the box's bottom face, which every ray leaving through it has crossed).
  double t_in = 0.0, t_out = std::numeric_limits<double>::infinity();
  const double hi[3] = {static_cast<double>(field.size), static_cast<double>(field.size), 1.0};
  for (std::size_t k = 0; k < 3; ++k) {
    if (d[k] == 0.0) continue;
    const double t1 = (0.0 - o[k]) / d[k], t2 = (hi[k] - o[k]) / d[k];
    t_in = std::max(t_in, std::min(t1, t2));
    t_out = std::min(t_out, std::max(t1, t2));
  }
  if (!(t_in <= t_out) || !std::isfinite(t_out)) t_in = t_out = static_cast<double>(ray.t_in);  // a grazing float ray: its one point
  return reference_hit(field, o, d, t_in, t_out, blocks);
}

HitScore score_against(const ReferenceHit& ref, const FragmentRay& ray, int size, bool hit, float t, double box_height,
                       double tolerance) {
  HitScore s;
  s.reference_hit = ref.hit;
  if (hit && !ref.hit) {
    s.error = HitError::WrongHit;
  } else if (!hit && ref.hit) {
    s.error = HitError::WrongMiss;
  } else if (hit) {
    const double dx = ray.d[0], dy = ray.d[1], dz = static_cast<double>(ray.d[2]) * box_height * size;
    s.distance = std::abs(static_cast<double>(t) - ref.t) * std::sqrt(dx * dx + dy * dy + dz * dz);
    if (s.distance > tolerance) s.error = HitError::FarHit;
  }
  return s;
}

HitScore score_hit(const Heightfield& field, const FragmentRay& ray, bool hit, float t, double box_height, double tolerance) {
  return score_against(reference_of(field, ray), ray, field.size, hit, t, box_height, tolerance);
}

}  // namespace nbsim::relief

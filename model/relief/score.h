// Hit error of a relief walk against the exact reference (docs/architecture.md, "Definitions"): the
// fragment's float ray (walk.h fragment_ray) in double through reference.h, then
// - wrong_hit: the walk hit where the reference misses;
// - wrong_miss: the walk missed (or was capped) where the reference hits;
// - far_hit: both hit, but the walk's hit point is farther than `tolerance` texels from the
//   reference's (distance in texel units, the height axis scaled by box_height * N to texel
//   units: box_height is the box's height over its width).
// A fragment with any of the three is a hit error.
#pragma once

#include <cstdint>

#include "model/relief/heightfield.h"
#include "model/relief/reference.h"
#include "model/relief/walk.h"

namespace nbsim::relief {

enum class HitError : std::uint8_t { None = 0, WrongHit = 1, WrongMiss = 2, FarHit = 3 };

struct HitScore {
  HitError error = HitError::None;
  bool reference_hit = false;
  double distance = 0.0;  // texels between the two hit points (both hit), else 0
};

HitScore score_hit(const Heightfield& field, const FragmentRay& ray, bool hit, float t, double box_height, double tolerance);

// The two halves of score_hit, for a caller that scores several walks of one ray (the methods of a
// frame share their rays): the reference of the ray, then a walk's score against it. `blocks` (of
// `field`, may be null) only makes the reference faster.
ReferenceHit reference_of(const Heightfield& field, const FragmentRay& ray, const ReferenceBlocks* blocks = nullptr);
HitScore score_against(const ReferenceHit& reference, const FragmentRay& ray, int size, bool hit, float t, double box_height,
                       double tolerance);

// The default tolerance, texels (a quarter texel: the exact methods land within 1e-3).
inline constexpr double kDefaultHitTolerance = 0.25;

}  // namespace nbsim::relief

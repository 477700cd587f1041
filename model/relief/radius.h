// The safety radius of Baboud & Decoret's robust binary search, in texels (heightfield.h's
// conventions). The guarantee: for any point p whose horizontal position is inside texel (i, j)'s
// square [i, i + 1] x [j, j + 1], and any ray that starts at p strictly above the surface, in any
// horizontal direction and with any slope, the ray crosses the surface at most once while its
// horizontal distance from p is at most radius(i, j). (The paper's wording takes the maximum over
// ray directions; only the minimum keeps the guarantee for every ray: radius_test.cpp shows the
// maximum failing by brute force.)
//
// How it is computed: along one horizontal direction from p, the surface is a profile g(s); a line
// starting above g(0) crosses g at most once on (0, r] exactly when the slope from the start,
// (g(s) - g(0)) / s, never decreases on (0, r]. The radius of texel (i, j) is the minimum of that r
// over sampled start points of the square and sampled directions, rounded down to whole texels and
// capped at max_radius. Peaks (a local maximum, a ridge) get radius 0.
#pragma once

#include <string>
#include <vector>

#include "model/relief/heightfield.h"

namespace nbsim::relief {

struct SafetyRadius {
  int size = 0;              // N, the heightfield's
  std::vector<float> radius;  // N * N whole texels in [0, max_radius], y up, row-major
};

// The radius of every texel, capped at max_radius (1 to 255). `directions` horizontal directions
// (at least 8) and `samples` start points a side of each texel's square (at least 2: its corners).
SafetyRadius safety_radius(const Heightfield& field, int max_radius, int directions = 64, int samples = 3);

// Why `r` does not belong to `field`: a size that differs, a value that is NaN, negative, not whole,
// or larger than safety_radius(field, max_radius) allows at that texel ("texel (3, 4) has radius 5,
// but the heightfield allows at most 2"); empty when it is conservative.
std::string radius_problem(const Heightfield& field, const SafetyRadius& r, int max_radius);

}  // namespace nbsim::relief

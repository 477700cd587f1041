// The paper's safety radius (Baboud & Decoret 2006, 3.4-3.5), beside radius.h's strict one: only
// unblocked rays count (rays that reach the texel without passing under the surface), and an
// allowed error epsilon lets a ray pass under the surface by at most epsilon (heightfield units, the
// box's height = 1) without counting as a second crossing, so larger epsilon gives larger radii and
// misses silhouettes at most epsilon tall (the paper's Figure 12).
//
// Along one horizontal direction from a start point p the surface is a profile g(s) (s the
// horizontal distance, negative behind p, back to where the ray entered the box). The robust walk
// fails when a ray, above the surface from the box's edge up to p, passes under the surface by more
// than epsilon somewhere ahead (at s1) and is above it again (at s2) within one step. Such a line
// exists for s1 < s2 exactly when the line through (s1, g(s1) - epsilon) and (s2, g(s2)) lies
// strictly above g on [behind, 0] (any line below the first point and above the second is below
// that line behind p). With the slope from the second point: some s1 in (0, s2) has
// (g(s2) - g(s1) + epsilon) / (s2 - s1) < min over the back points b of (g(s2) - g(b)) / (s2 - b).
// The radius along that direction is the smallest such s2 (the extremal ray's second point of
// tangency, in the paper's terms), computed on profile samples `step` texels apart and taken one
// step short, in whole texels.
//
// A texel's radius per direction is the smallest over the start points (its square's corners and,
// with samples > 2, points between). Over the directions the paper keeps the maximum, which does
// not bound every ray (the walk reads one radius for every direction: a ray along a worse direction
// may cross twice within it); `combine` min keeps the bound. Sampled, not exact: the brute-force
// checks measure what it misses.
#pragma once

#include <array>
#include <optional>
#include <string_view>

#include "model/relief/heightfield.h"
#include "model/relief/radius.h"

namespace nbsim::relief {

// How the per-direction radii make the texel's: the paper's maximum, or the minimum.
enum class RadiusCombine : std::uint8_t { Max = 0, Min = 1 };
inline constexpr std::array<std::string_view, 2> kRadiusCombineNames = {"max", "min"};

struct PaperRadiusOptions {
  double epsilon = 0.0;  // 0 .. 1: how far (box heights) a ray may pass under the surface unnoticed
  RadiusCombine combine = RadiusCombine::Max;
  int directions = 16;   // horizontal directions, at least 4
  int samples = 2;       // start points a side of each texel's square, at least 2 (its corners)
  double step = 0.25;    // profile sample spacing, texels (0.05 .. 1)
};

// Why `o` is not usable ("epsilon 1.5 is outside 0 .. 1"), or empty.
std::string paper_radius_problem(const PaperRadiusOptions& o);

// The paper's radius of every texel, in whole texels capped at max_radius (1 to 255). Throws
// InputError for options that paper_radius_problem() refuses.
SafetyRadius paper_safety_radius(const Heightfield& field, int max_radius, const PaperRadiusOptions& o);

// The radius along one direction (dx, dy) (unit) from the point (px, py) (field coordinates), in
// texels, before rounding: the smallest s2 found, less one step; `limit` when none is found up to it.
double paper_point_radius(const Heightfield& field, double px, double py, double dx, double dy, double limit,
                          const PaperRadiusOptions& o);

}  // namespace nbsim::relief

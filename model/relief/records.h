// The relief technique's records as the model reads them (no traces/ include: the fields come from
// the frame's TechniqueRecords, decoded by the format library; traces/format/relief/relief_chunk.h
// documents them). Each reader checks what the model relies on and throws InputError naming the
// frame, the record and the problem (a missing record or field, a field of the wrong type, vector
// lengths, NaN, out-of-range values, radii that are not whole, an N-buffer that is not the max
// N-buffer of the heights, a fragment whose draw is not a relief_box draw of the frame).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "model/relief/heightfield.h"
#include "model/relief/radius.h"
#include "model/relief/walk.h"
#include "model/scene/frame.h"

namespace nbsim::relief {

inline constexpr std::uint32_t kReliefFieldRecordType = 0x48464C52u;      // fourcc "RLFH" (traces/format/relief/relief_chunk.h)
inline constexpr std::uint32_t kReliefFragmentsRecordType = 0x46464C52u;  // fourcc "RLFF"
inline constexpr std::uint32_t kReliefDepthRecordType = 0x44464C52u;      // fourcc "RLFD"

// RLFH, checked.
struct GlReliefField {
  Heightfield field;
  SafetyRadius radius;
  int max_radius = 0;
  int levels = 0;
  std::vector<float> nbuffer;  // levels * N * N as GL built it (checked equal to the model's build)
  std::string description;     // RLFH `field`
  WalkParams params;
  RayFrame ray;
  double view_angle = 0.0;
  double frustum_apex = 0.0;  // 0: the box; the ray frame is a frustum's (ray.frustum) otherwise

  FieldView view() const;  // spans into this record
};
GlReliefField read_relief_field(const scene::Frame& f);

// One RLFF, checked.
// The fragment fields are views into the frame's RLFF record (no copies): valid while the frame is.
struct GlReliefFragments {
  std::uint32_t draw = 0;
  Method method = Method::Binary;
  std::span<const std::uint32_t> pixel;  // strictly increasing
  std::span<const std::uint32_t> hit;    // 0 miss, 1 hit, 2 capped
  std::span<const float> t;
  std::span<const std::uint32_t> lookups, steps, bisections;
};
// Every RLFF of the frame, in record order; `viewport_pixels` bounds `pixel`.
std::vector<GlReliefFragments> read_relief_fragments(const scene::Frame& f, std::uint64_t viewport_pixels);

// RLFD, checked: what the box draws left in GL's depth buffer (box_depth.h).
struct GlReliefDepth {
  std::array<float, 16> texel_to_clip{};  // column-major
  std::vector<std::uint32_t> draws;       // the frame's relief_box draws, in order
  std::vector<std::uint32_t> depth_crc;   // per draw: CRC-32 of the depth buffer right after it
};
// The frame's RLFD. `required` (the header's relief_box_depth is box or exact): its absence is an
// InputError; otherwise absent gives an empty optional. Every relief_box draw of the frame must have
// its CRC, in order.
std::optional<GlReliefDepth> read_relief_depth(const scene::Frame& f, bool required);

}  // namespace nbsim::relief

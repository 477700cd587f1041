// The relief box's depth; see box_depth.h.
#include "model/relief/box_depth.h"

namespace nbsim::relief {

std::optional<BoxDepth> parse_box_depth(std::string_view s) noexcept {
  for (std::size_t i = 0; i < kBoxDepthNames.size(); ++i)
    if (kBoxDepthNames[i] == s) return static_cast<BoxDepth>(i);
  return std::nullopt;
}

float hit_depth(const std::array<float, 16>& m, const FragmentRay& ray, float t) noexcept {
  // relief.frag's hit_depth(), expression for expression (the project compiles with
  // -ffp-contract=off, the shader's expressions are `precise`).
  const float x = ray.o[0] + t * ray.d[0];
  const float y = ray.o[1] + t * ray.d[1];
  const float z = ray.o[2] + t * ray.d[2];
  const float cz = ((m[2] * x + m[6] * y) + m[10] * z) + m[14];
  const float cw = ((m[3] * x + m[7] * y) + m[11] * z) + m[15];
  return (cz / cw) * 0.5f + 0.5f;
}

}  // namespace nbsim::relief

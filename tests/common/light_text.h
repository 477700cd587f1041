// The shadows capture's --light value "X,Y,Z,TX,TY,TZ" from a light position and the point it
// looks at (metres), as the shadows tests write it (std::to_string: six decimals).
#pragma once

#include <glm/vec3.hpp>

#include <string>

namespace nbsim::testing {

inline std::string light_text(const glm::vec3& eye, const glm::vec3& target) {
  std::string out;
  for (float v : {eye.x, eye.y, eye.z, target.x, target.y, target.z}) {
    if (!out.empty()) out += ',';
    out += std::to_string(v);
  }
  return out;
}

}  // namespace nbsim::testing

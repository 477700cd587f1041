// Building a CaptureScene's geometry object by object (the terrain and boxes scenes): closed boxes
// and flat-shaded shapes appended to the current object, then the objects' bounds, triangle
// counts and BVH as the trace stores them. World space y up, metres, triangles counter-clockwise
// seen from outside.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <string_view>
#include <vector>

#include "traces/capture/scenes.h"

namespace nbsim::capture {

class MeshBuilder {
 public:
  explicit MeshBuilder(CaptureScene& scene) : scene_(scene) {}

  // Starts the next object (its id is the number of objects so far) of class `cls` ("tower").
  void begin(std::string_view cls);
  void end();    // closes it (at least one triangle)

  // An axis-aligned box [lo, hi]: 12 triangles sharing 8 corners (a closed surface).
  void box(glm::vec3 lo, glm::vec3 hi);
  // A vertex of the current object; its index (for triangle()).
  std::uint32_t vertex(glm::vec3 p);
  void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c);

  // After the last object: bounds, triangle counts and the BVH (city.h's build_bvh).
  void finish();

 private:
  CaptureScene& scene_;
};

}  // namespace nbsim::capture

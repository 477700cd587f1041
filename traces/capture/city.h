// The procedural city of the walkthrough (N-buffer paper, section 4.2): a street grid, buildings
// of varied footprint and height on every block, and smaller props along the streets (cars, lamp
// posts, trees, kiosks), with a bounding volume hierarchy over the objects. World space is y up,
// metres; the ground is the plane y = 0. Deterministic for a seed.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <vector>

#include "traces/format/records.h"

namespace nbsim::capture {

struct CityParams {
  std::uint32_t seed = 1;
  int objects = 6000;  // total objects, ground included; at least 2
  double block_m = 60.0;   // side of a block (tunable)
  double street_m = 16.0;  // street width (tunable)
};

enum class ObjectKind : std::uint8_t { Ground = 0, Building = 1, Car = 2, Lamp = 3, Tree = 4, Kiosk = 5 };

struct Object {
  ObjectKind kind = ObjectKind::Building;
  trace::Aabb bounds;
  std::uint32_t first_index = 0;  // into City::indices
  std::uint32_t index_count = 0;  // three per triangle
};

struct City {
  std::vector<glm::vec3> vertices;
  std::vector<std::uint32_t> indices;  // triangles, counter-clockwise seen from outside
  std::vector<Object> objects;
  int blocks_per_side = 0;
  double block_m = 0.0, street_m = 0.0;
  trace::SceneObjects scene;  // bounds, triangle counts and BVH, as the trace stores them

  double pitch_m() const { return block_m + street_m; }  // distance between street centre lines
  double extent_m() const { return blocks_per_side * pitch_m(); }
};

City make_city(const CityParams& params);

// A BVH over object bounds (binned SAH, at most 4 objects a leaf), stored as SceneObjects' node
// arrays. Node 0 is the root.
void build_bvh(const std::vector<trace::Aabb>& objects, trace::SceneObjects& out);

}  // namespace nbsim::capture

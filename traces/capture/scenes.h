// The scenes a capture can render, by name, from one table (scenes.cpp): each row builds a
// CaptureScene from its options. A CaptureScene is what every technique and camera path works on:
// triangles grouped into objects, the objects' bounds and BVH as the trace stores them, the site
// the camera paths move over and the header properties that describe it. Any technique works on
// any scene.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "model/scene/frame.h"
#include "traces/capture/camera.h"
#include "traces/capture/plugin.h"
#include "traces/format/records.h"

namespace nbsim::capture {

// One object's triangles: a range of CaptureScene::indices.
struct MeshRange {
  std::uint32_t first_index = 0;
  std::uint32_t index_count = 0;  // three per triangle
};

struct CaptureScene {
  std::vector<glm::vec3> vertices;     // world space, y up, metres
  std::vector<std::uint32_t> indices;  // triangles, counter-clockwise seen from outside
  std::vector<MeshRange> objects;      // index = object id
  // What each object is (index into class_names, one per object), for reports that split a count
  // by kind of object: the terrain's "ground", "tower" and "bird", the city's "building", "car"...
  std::vector<std::uint16_t> object_class;
  std::vector<std::string> class_names;
  scene::SceneObjects scene;           // bounds, triangle counts and BVH of the objects
  PathSite site;
  // Header properties written right after "scene" = the scene's name (e.g. seed, objects).
  trace::Properties properties;
};

// The index of class `name` in scene.class_names, added when new.
std::uint16_t scene_class(CaptureScene& scene, std::string_view name);

struct SceneRow {
  PluginInfo info;
  std::function<CaptureScene(const OptionValues&)> make;  // throws InputError on bad options
};

const std::vector<SceneRow>& scene_table();
// Throws InputError listing the known scenes.
const SceneRow& find_scene(std::string_view name);

}  // namespace nbsim::capture

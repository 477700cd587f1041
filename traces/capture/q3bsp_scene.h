// The q3bsp scene: a Quake 3 level (q3bsp.h reads it) as a CaptureScene. Objects group the
// world's faces by BSP leaf (each face in the first leaf that lists it), face type and, where a
// leaf is large (open areas often are one leaf), the cube of object_cell_m metres that holds the
// centre of the face's bounds, so that a walkthrough culls what the level's own partition
// separates at a grain finer than a whole courtyard: class "structure" (polygons), "patch"
// (tessellated Bezier patches) and "mesh" (models baked into the map). The level is moved
// so that its bounds start at the origin (x, y and z >= 0, extent_m the larger horizontal side,
// for the flyover); its site is enclosed, with waypoints at the spawn points and items (raised to
// eye height above the floor) and their clear links for the camera path `tour` (waypoints.h).
#pragma once

#include <string>

#include "traces/capture/q3bsp.h"
#include "traces/capture/scenes.h"
#include "traces/capture/waypoints.h"

namespace nbsim::capture {

struct Q3BspSceneParams {
  int patch_segments = kDefaultPatchSegments;  // what the map was read with, for the header
  double object_cell_m = 8.0;                  // 0: objects by leaf and type only (tunable: a room's width)
  WaypointParams waypoints;
};

// `name` (the file's name) goes into the header property "bsp".
CaptureScene make_q3bsp_scene(const BspMap& map, const std::string& name, const Q3BspSceneParams& params = {});

}  // namespace nbsim::capture

// The camera paths a capture can follow, by name, from one table (paths.cpp): each row makes one
// pose per frame over a scene's site (camera.h computes them). Any path that the scene's site
// allows combines with any scene and technique.
#pragma once

#include <functional>
#include <string_view>
#include <vector>

#include "traces/capture/camera.h"
#include "traces/capture/plugin.h"
#include "traces/capture/scenes.h"

namespace nbsim::capture {

struct PathRow {
  PluginInfo info;
  // `frames` poses; throws InputError when the scene's site does not allow the path.
  std::function<std::vector<CameraPose>(const CaptureScene&, int frames, const OptionValues&)> make;
};

const std::vector<PathRow>& path_table();
// Throws InputError listing the known camera paths.
const PathRow& find_path(std::string_view name);

}  // namespace nbsim::capture

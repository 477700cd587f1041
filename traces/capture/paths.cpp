// The camera-path table; see paths.h. A new path is a function in camera.cpp and one row here.
#include "traces/capture/paths.h"

#include "model/common/error.h"

namespace nbsim::capture {

namespace {

std::vector<CameraPose> walk(const CaptureScene& s, int frames, const OptionValues& options) {
  if (!s.site.has_streets())
    throw InputError(s.site.has_waypoint_links() ? "camera path 'walk' needs a scene with streets (e.g. city); use --path tour or fly"
                                                 : "camera path 'walk' needs a scene with streets (e.g. city); use --path fly");
  return walk_path(s.site, frames, static_cast<std::uint32_t>(options.integer(seed_option())));
}

std::vector<CameraPose> fly(const CaptureScene& s, int frames, const OptionValues&) { return fly_path(s.site, frames); }

std::vector<CameraPose> ground(const CaptureScene& s, int frames, const OptionValues& options) {
  if (s.site.enclosed)
    throw InputError(
        "camera path 'ground' needs a scene with open ground (e.g. terrain; its straight line would cross the walls of an enclosed "
        "scene); use --path tour or fly");
  return ground_path(s.site, frames, static_cast<std::uint32_t>(options.integer(seed_option())));
}

std::vector<CameraPose> tour(const CaptureScene& s, int frames, const OptionValues& options) {
  if (!s.site.has_waypoint_links())
    throw InputError(s.site.enclosed
                         ? "camera path 'tour' needs a scene with waypoints joined by a clear segment (this one has none); use --path fly"
                         : "camera path 'tour' needs a scene with waypoints (e.g. q3bsp); use --path walk, ground or fly");
  return tour_path(s.site, frames, static_cast<std::uint32_t>(options.integer(seed_option())));
}

}  // namespace

const std::vector<PathRow>& path_table() {
  static const std::vector<PathRow> table = {
      {{"walk", "Street-level walkthrough, 1.2 m a frame, turning at random crossings (needs streets)", {seed_option()}}, walk},
      {{"fly", "Flyover circling the scene once, looking at its centre", {}}, fly},
      {{"ground",
        "An observer on foot: 1.7 m above the ground, 1.2 m a frame on a straight line through the site's centre, "
        "looking ahead level (what is well above the eye is mostly out of view)",
        {seed_option()}},
       ground},
      {{"tour",
        "A walk through an enclosed scene (q3bsp): 1.2 m a frame at eye height between waypoints (spawn points, items), "
        "along segments clear of the scene's triangles, turning at random waypoints, looking ahead (needs waypoints)",
        {seed_option()}},
       tour},
  };
  return table;
}

const PathRow& find_path(std::string_view name) { return find_row(path_table(), name, "camera path"); }

}  // namespace nbsim::capture

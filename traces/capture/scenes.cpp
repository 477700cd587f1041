// The scene table; see scenes.h. A new scene is a file that builds its geometry and one row here.
#include "traces/capture/scenes.h"

#include <fmt/format.h>

#include "traces/capture/city.h"

namespace nbsim::capture {

namespace {

const OptionSpec kObjects{"objects", "Objects in the city, ground included", "6000", OptionSpec::Kind::Integer, 2, 1000000, {}};

CaptureScene make_city_scene(const OptionValues& options) {
  CityParams p;
  p.seed = static_cast<std::uint32_t>(options.integer(seed_option()));
  p.objects = static_cast<int>(options.integer(kObjects));
  City city = make_city(p);
  CaptureScene s;
  s.vertices = std::move(city.vertices);
  s.indices = std::move(city.indices);
  s.objects.reserve(city.objects.size());
  for (const Object& o : city.objects) s.objects.push_back({o.first_index, o.index_count});
  s.scene = std::move(city.scene);
  s.site.extent_m = city.extent_m();
  s.site.street_pitch_m = city.pitch_m();
  s.site.blocks_per_side = city.blocks_per_side;
  s.properties = {{"seed", std::to_string(p.seed)}, {"objects", std::to_string(s.objects.size())}};
  return s;
}

}  // namespace

const std::vector<SceneRow>& scene_table() {
  static const std::vector<SceneRow> table = {
      {{"city", "Procedural city: street grid, buildings and street props, with a BVH (N-buffer paper, 4.2)", {seed_option(), kObjects}},
       make_city_scene},
  };
  return table;
}

const SceneRow& find_scene(std::string_view name) { return find_row(scene_table(), name, "scene"); }

}  // namespace nbsim::capture

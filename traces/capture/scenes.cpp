// The scene table; see scenes.h. A new scene is a file that builds its geometry and one row here.
#include "traces/capture/scenes.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <string_view>

#include "model/common/error.h"

#include "traces/capture/boxes.h"
#include "traces/capture/city.h"
#include "traces/capture/q3bsp_scene.h"
#include "traces/capture/terrain.h"

namespace nbsim::capture {

namespace {

const OptionSpec kObjects = integer_option("objects", "Objects in the city, ground included", 6000, 2, 1000000);

CaptureScene make_city_scene(const OptionValues& options) {
  CityParams p;
  p.seed = static_cast<std::uint32_t>(options.integer(seed_option()));
  p.objects = static_cast<int>(options.integer(kObjects));
  City city = make_city(p);
  CaptureScene s;
  s.vertices = std::move(city.vertices);
  s.indices = std::move(city.indices);
  s.objects.reserve(city.objects.size());
  static constexpr std::array<std::string_view, 6> kKinds = {"ground", "building", "car", "lamp", "tree", "kiosk"};
  for (const Object& o : city.objects) {
    s.objects.push_back({o.first_index, o.index_count});
    s.object_class.push_back(scene_class(s, kKinds.at(static_cast<std::size_t>(o.kind))));
  }
  s.scene = std::move(city.scene);
  s.site.extent_m = city.extent_m();
  s.site.street_pitch_m = city.pitch_m();
  s.site.blocks_per_side = city.blocks_per_side;
  s.properties = {{"seed", std::to_string(p.seed)}, {"objects", std::to_string(s.objects.size())}};
  return s;
}

const OptionSpec kTowers = integer_option("towers", "Towers on the terrain", 40, 0, 10000);
const OptionSpec kBirds = integer_option("birds", "Birds (small flying casters) over the terrain and around it", 2000, 0, 200000);
const OptionSpec kBoxes = integer_option("boxes", "Boxes on the plane", 30, 0, 10000);

CaptureScene make_terrain_scene(const OptionValues& options) {
  TerrainParams p;
  p.seed = static_cast<std::uint32_t>(options.integer(seed_option()));
  p.towers = static_cast<int>(options.integer(kTowers));
  p.birds = static_cast<int>(options.integer(kBirds));
  return make_terrain(p);
}

CaptureScene make_boxes_scene(const OptionValues& options) {
  BoxesParams p;
  p.seed = static_cast<std::uint32_t>(options.integer(seed_option()));
  p.boxes = static_cast<int>(options.integer(kBoxes));
  return make_boxes(p);
}

const OptionSpec kBsp = text_option(
    "bsp", "Quake 3 level: a .bsp file, or PAK.pk3:maps/NAME.bsp for a member of a game package (read with unzip -p)", "none");
const OptionSpec kPatchSegments =
    integer_option("patch-segments", "Quads a side of each tessellated 3x3 Bezier patch of the level", kDefaultPatchSegments, 1,
                   kMaxPatchSegments);
const OptionSpec kObjectCell = integer_option(
    "object-cell", "The level's objects: faces by BSP leaf, type and cube of this side (m) holding their centre; 0: by leaf and type only",
    8, 0, 100000);

CaptureScene make_q3bsp(const OptionValues& options) {
  const std::string path = options.text(kBsp);
  if (path == "none") throw InputError("scene q3bsp needs --bsp FILE.bsp (a Quake 3 level, e.g. OpenArena's)");
  BspOptions o;
  o.patch_segments = static_cast<int>(options.integer(kPatchSegments));
  Q3BspSceneParams p;
  p.patch_segments = o.patch_segments;
  p.object_cell_m = static_cast<double>(options.integer(kObjectCell));
  return make_q3bsp_scene(load_bsp(path, o), path, p);
}

}  // namespace

std::uint16_t scene_class(CaptureScene& scene, std::string_view name) {
  const auto it = std::find(scene.class_names.begin(), scene.class_names.end(), name);
  if (it != scene.class_names.end()) return static_cast<std::uint16_t>(it - scene.class_names.begin());
  NBSIM_CHECK(scene.class_names.size() < 0xFFFFu, "too many object classes");
  scene.class_names.emplace_back(name);
  return static_cast<std::uint16_t>(scene.class_names.size() - 1);
}

const std::vector<SceneRow>& scene_table() {
  static const std::vector<SceneRow> table = {
      {{"city", "Procedural city: street grid, buildings and street props, with a BVH (N-buffer paper, 4.2)", {seed_option(), kObjects}},
       make_city_scene},
      {{"terrain", "Heightfield terrain with towers and many small flying casters (birds), most out of view (N-buffer paper, 4.4)",
        {seed_option(), kTowers, kBirds}},
       make_terrain_scene},
      {{"boxes", "Boxes on a plane: the N-buffer paper's simpler scenes (4.4)", {seed_option(), kBoxes}},
       make_boxes_scene},
      {{"q3bsp", "A Quake 3 level (OpenArena's .bsp maps): world polygons, meshes and tessellated patches, objects by BSP leaf and cell",
        {kBsp, kPatchSegments, kObjectCell}},
       make_q3bsp},
  };
  return table;
}

const SceneRow& find_scene(std::string_view name) { return find_row(scene_table(), name, "scene"); }

}  // namespace nbsim::capture

// CaptureRegistryTest: the capture's plug-in tables (techniques, scenes, camera paths) without GL:
// every name resolves to its row, unknown names are refused naming the known ones, options are
// declared with valid defaults and checked, and scenes and paths combine through the site.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include <algorithm>
#include <map>
#include <set>
#include <string>

#include "model/common/error.h"
#include "traces/capture/capture.h"
#include "traces/capture/paths.h"
#include "traces/capture/plugin.h"
#include "traces/capture/scenes.h"
#include "traces/capture/technique.h"

namespace nbsim::capture {
namespace {

// The InputError message of `f`, or "" when it does not throw one.
template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return {};
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

template <class Row>
void expect_rows_well_formed(const std::vector<Row>& table, const char* kind) {
  ASSERT_FALSE(table.empty()) << kind << " table is empty";
  std::set<std::string> names;
  for (const Row& r : table) {
    EXPECT_TRUE(names.insert(r.info.name).second) << kind << " '" << r.info.name << "' is in the table twice";
    EXPECT_FALSE(r.info.description.empty()) << kind << " '" << r.info.name << "' has no description";
    EXPECT_TRUE(r.make) << kind << " '" << r.info.name << "' has no factory";
    for (const OptionSpec& o : r.info.options) {
      EXPECT_EQ(option_problem(o, o.default_value), "") << kind << " '" << r.info.name << "': default of --" << o.name;
      EXPECT_FALSE(o.help.empty()) << "--" << o.name << " has no help";
    }
  }
}

// Every row has a unique name, a description, a factory and options whose defaults are valid.
TEST(CaptureRegistryTest, RowsAreWellFormed) {
  expect_rows_well_formed(technique_table(), "technique");
  expect_rows_well_formed(scene_table(), "scene");
  expect_rows_well_formed(path_table(), "camera path");
}

// Every technique, scene and path name finds its own row; the names the docs and scripts use are there.
TEST(CaptureRegistryTest, EveryNameResolves) {
  for (const auto& r : technique_table()) EXPECT_EQ(&find_technique(r.info.name), &r) << r.info.name;
  for (const auto& r : scene_table()) EXPECT_EQ(&find_scene(r.info.name), &r) << r.info.name;
  for (const auto& r : path_table()) EXPECT_EQ(&find_path(r.info.name), &r) << r.info.name;
  EXPECT_EQ(find_technique("occlusion_culling").info.name, "occlusion_culling");
  EXPECT_EQ(find_scene("city").info.name, "city");
  EXPECT_EQ(find_path("walk").info.name, "walk");
  EXPECT_EQ(find_path("fly").info.name, "fly");
}

// An unknown name is the user's error, and the message names it and lists every known name.
TEST(CaptureRegistryTest, UnknownNamesListTheKnownOnes) {
  const std::string t = input_error([] { find_technique("raytracing"); });
  EXPECT_TRUE(has(t, "unknown technique 'raytracing'")) << t;
  for (const auto& r : technique_table()) EXPECT_TRUE(has(t, r.info.name)) << t;
  const std::string s = input_error([] { find_scene("forest"); });
  EXPECT_TRUE(has(s, "unknown scene 'forest'")) << s;
  for (const auto& r : scene_table()) EXPECT_TRUE(has(s, r.info.name)) << s;
  const std::string p = input_error([] { find_path("orbit"); });
  EXPECT_TRUE(has(p, "unknown camera path 'orbit'")) << p;
  for (const auto& r : path_table()) EXPECT_TRUE(has(p, r.info.name)) << p;
}

// Option values are checked against their spec: out-of-range integers, non-integers and values
// outside a choice are refused naming the option and what it accepts.
TEST(CaptureRegistryTest, OptionValuesAreChecked) {
  const auto& t = find_technique("occlusion_culling").info.options;
  const OptionSpec* mode = nullptr;
  const OptionSpec* levels = nullptr;
  for (const auto& o : t) {
    if (o.name == "mode") mode = &o;
    if (o.name == "levels-every") levels = &o;
  }
  ASSERT_NE(mode, nullptr);
  ASSERT_NE(levels, nullptr);
  for (const char* m : {"oq", "oq_hier", "nb", "nb_hier", "none"}) EXPECT_EQ(option_problem(*mode, m), "") << m;
  EXPECT_TRUE(has(option_problem(*mode, "nb_fast"), "oq, oq_hier, nb, nb_hier, none")) << option_problem(*mode, "nb_fast");
  EXPECT_TRUE(has(option_problem(*levels, "-1"), "out of range")) << option_problem(*levels, "-1");
  EXPECT_TRUE(has(option_problem(*levels, "ten"), "not an integer")) << option_problem(*levels, "ten");
  EXPECT_TRUE(has(option_problem(*levels, "1x"), "not an integer")) << "trailing characters";
  const OptionValues v = {{"levels-every", "3"}};
  EXPECT_EQ(v.integer(*levels), 3);
  EXPECT_EQ(v.text(*mode), "nb_hier") << "unset options take their default";
  const OptionValues bad = {{"mode", "zbuffer"}};
  EXPECT_TRUE(has(input_error([&] { bad.text(*mode); }), "--mode 'zbuffer'"));
}

// A set option that none of the chosen plug-ins declares is refused, naming it and what they accept.
TEST(CaptureRegistryTest, UndeclaredOptionsAreRefused) {
  const auto& t = find_technique("occlusion_culling").info;
  const auto& s = find_scene("city").info;
  const auto& fly = find_path("fly").info;
  EXPECT_EQ(input_error([&] { check_options_declared({{"mode", "oq"}, {"seed", "2"}, {"objects", "9"}}, {&s, &fly, &t}); }), "");
  const std::string e = input_error([&] { check_options_declared({{"level-every", "1"}}, {&s, &fly, &t}); });
  EXPECT_TRUE(has(e, "--level-every")) << e;
  EXPECT_TRUE(has(e, "--levels-every")) << "lists the accepted options: " << e;
  // capture() checks before any GL work.
  CaptureOptions o;
  o.options = {{"sprite-size", "16"}};
  EXPECT_TRUE(has(input_error([&] { capture(o, "/nonexistent/never_written.nbt"); }), "--sprite-size"));
  o.options = {};
  o.scene = "forest";
  EXPECT_TRUE(has(input_error([&] { capture(o, "/nonexistent/never_written.nbt"); }), "known scenes are city"));
}

// Options that two plug-ins chosen together declare (the shared --seed) agree on kind, range and
// default. Techniques are chosen one at a time, so two techniques may mean different things by one
// name (--mode).
TEST(CaptureRegistryTest, SharedOptionsAgree) {
  std::vector<std::pair<const OptionSpec*, const void*>> all;  // option, its technique row (null: scene or path)
  for (const auto& r : technique_table())
    for (const auto& o : r.info.options) all.emplace_back(&o, &r);
  for (const auto& r : scene_table())
    for (const auto& o : r.info.options) all.emplace_back(&o, nullptr);
  for (const auto& r : path_table())
    for (const auto& o : r.info.options) all.emplace_back(&o, nullptr);
  for (const auto& [a, ta] : all)
    for (const auto& [b, tb] : all)
      if (a->name == b->name && !(ta && tb && ta != tb)) {
        EXPECT_EQ(a->kind, b->kind) << "--" << a->name;
        EXPECT_EQ(a->default_value, b->default_value) << "--" << a->name;
        EXPECT_EQ(a->min, b->min) << "--" << a->name;
        EXPECT_EQ(a->max, b->max) << "--" << a->name;
        EXPECT_EQ(a->choices, b->choices) << "--" << a->name;
      }
}

// Paths work on a scene's site, not on the city: the flyover circles any site at its centre; the
// walk needs streets and refuses a site without them; the city's site has streets.
TEST(CaptureRegistryTest, PathsWorkOnAnySite) {
  CaptureScene open;
  open.site.extent_m = 100.0;
  const auto poses = find_path("fly").make(open, 8, {});
  ASSERT_EQ(poses.size(), 8u);
  for (const auto& p : poses) {
    EXPECT_FLOAT_EQ(p.target.x, 50.0f) << "looks at the site's centre";
    EXPECT_FLOAT_EQ(p.target.z, 50.0f);
  }
  EXPECT_TRUE(has(input_error([&] { find_path("walk").make(open, 8, {}); }), "needs a scene with streets"));
  const CaptureScene city = find_scene("city").make({{"objects", "50"}, {"seed", "4"}});
  EXPECT_EQ(city.objects.size(), 50u);
  EXPECT_EQ(city.scene.objects.size(), 50u);
  EXPECT_TRUE(city.site.has_streets());
  EXPECT_EQ(find_path("walk").make(city, 5, {{"seed", "4"}}).size(), 5u);
}

// Every scene names each object's class, for the reports that split a count by kind of object.
TEST(CaptureRegistryTest, ScenesNameEveryObjectsClass) {
  const std::map<std::string, std::set<std::string>> expected = {
      {"city", {"ground", "building", "car", "lamp", "tree", "kiosk"}}, {"terrain", {"ground", "tower", "bird"}}, {"boxes", {"ground", "box"}}};
  for (const auto& [name, classes] : expected) {
    const CaptureScene s = find_scene(name).make({{"seed", "3"}, {"objects", "400"}, {"towers", "4"}, {"birds", "6"}, {"boxes", "5"}});
    ASSERT_EQ(s.object_class.size(), s.objects.size()) << name;
    std::set<std::string> used;
    for (std::uint16_t c : s.object_class) {
      ASSERT_LT(c, s.class_names.size()) << name;
      used.insert(s.class_names[c]);
    }
    EXPECT_EQ(used, classes) << name;
    EXPECT_EQ(s.class_names[s.object_class[0]], "ground") << name << ": object 0 is the ground";
  }
}

// The observer on foot: eye height above the scene's own ground (the terrain's hills), level gaze,
// 1.2 m a frame on a straight line through the site's centre, never off the site.
TEST(CaptureRegistryTest, GroundPathWalksAtEyeHeightOverTheGround) {
  const CaptureScene terrain = find_scene("terrain").make({{"seed", "9"}, {"towers", "3"}, {"birds", "5"}});
  ASSERT_TRUE(terrain.site.ground);
  const auto poses = find_path("ground").make(terrain, 40, {{"seed", "9"}});
  ASSERT_EQ(poses.size(), 40u);
  const float ext = static_cast<float>(terrain.site.extent_m);
  float lowest = 1e9f, highest = -1e9f;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const CameraPose& p = poses[i];
    const float ground = terrain.site.ground_at(p.eye.x, p.eye.z);
    lowest = std::min(lowest, ground), highest = std::max(highest, ground);
    EXPECT_NEAR(p.eye.y - ground, 1.7f, 1e-4f) << "frame " << i;
    EXPECT_FLOAT_EQ(p.target.y, p.eye.y) << "looks ahead level";
    EXPECT_GE(p.eye.x, 0.0f);
    EXPECT_LE(p.eye.x, ext);
    EXPECT_GE(p.eye.z, 0.0f);
    EXPECT_LE(p.eye.z, ext);
    if (i > 0) {
      EXPECT_NEAR(glm::length(glm::vec2(p.eye.x - poses[i - 1].eye.x, p.eye.z - poses[i - 1].eye.z)), 1.2f, 1e-3f);
    }
  }
  EXPECT_GT(highest - lowest, 0.01f) << "the walk follows the hills, not a plane";
  // The middle of the walk passes the site's centre.
  const CameraPose& mid = poses[poses.size() / 2];
  EXPECT_NEAR(glm::length(glm::vec2(mid.eye.x, mid.eye.z) - glm::vec2(0.5f * ext)), 0.6f, 0.61f);
  // A flat site: eye height above y = 0; another seed, another heading.
  CaptureScene open;
  open.site.extent_m = 100.0;
  const auto flat = find_path("ground").make(open, 3, {{"seed", "2"}});
  for (const CameraPose& p : flat) EXPECT_FLOAT_EQ(p.eye.y, 1.7f);
  const auto other = find_path("ground").make(terrain, 40, {{"seed", "10"}});
  EXPECT_NE(other.front().eye.x, poses.front().eye.x);
}

// The recorded command line spells out every option of the chosen rows in the current spelling.
TEST(CaptureRegistryTest, CanonicalCommandLineSpellsEverythingOut) {
  CaptureOptions o;
  o.width = 128;
  o.height = 96;
  o.frames = 8;
  o.options = {{"seed", "3"}, {"objects", "1200"}, {"mode", "oq"}, {"levels-every", "0"}};
  EXPECT_EQ(canonical_command_line(o, "t.nbt"),
            "nbsim capture occlusion_culling --scene city --path walk --size 128x96 --frames 8 --seed 3 --objects 1200 "
            "--mode oq --levels-every 0 --covering paper --align top -o t.nbt");
  o.path = "fly";
  o.reversed_z = true;
  o.options = {};
  EXPECT_EQ(canonical_command_line(o, "t.nbt"),
            "nbsim capture occlusion_culling --scene city --path fly --size 128x96 --frames 8 --seed 1 --objects 6000 "
            "--mode nb_hier --levels-every 10 --covering paper --align top --reversed-z -o t.nbt");
}

}  // namespace
}  // namespace nbsim::capture

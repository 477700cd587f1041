// Q3BspTest: the Quake 3 BSP reader (traces/capture/q3bsp.h) and the q3bsp scene
// (traces/capture/q3bsp_scene.h) on tiny .bsp files the test writes itself: a polygon, a mesh, a
// 3x3 and a 5x3 patch, faces that are skipped, entities; every kind of bad input refused by name;
// the waypoints and the camera path `tour` on a room with a pillar; one real OpenArena map when
// Debian's openarena-data is installed.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "tests/common/bsp_writer.h"
#include "tests/common/input_error.h"
#include "traces/capture/paths.h"
#include "traces/capture/q3bsp.h"
#include "traces/capture/q3bsp_scene.h"
#include "traces/capture/waypoints.h"

namespace nbsim::capture {
namespace {

using nbsim::testing::BspWriter;
using nbsim::testing::room_map;
using nbsim::testing::vtx;

// Byte offset of lump `l`'s (offset, length) entry in the header, and of a face's field.
constexpr std::size_t lump_entry(std::size_t l) { return 8 + 8 * l; }

void poke_i32(std::vector<std::uint8_t>& b, std::size_t at, std::int32_t v) { std::memcpy(b.data() + at, &v, 4); }
std::int32_t peek_i32(const std::vector<std::uint8_t>& b, std::size_t at) {
  std::int32_t v;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}


// The test map (Quake units, z up): face 0 a floor quad whose second triangle is wound against its
// normal; face 1 a mesh of two triangles, one wound against its vertex normals; face 2 a 3x3 bump
// patch whose net runs clockwise seen from its normals' side; face 3 a 5x3 patch (two 3x3 patches
// side by side) running counter-clockwise; face 4 nodraw, face 5 a billboard, face 6 sky, face 7
// in no leaf; model 1 (a brush model) holds face 8.
BspWriter test_map() {
  BspWriter w;
  w.textures = {{"textures/test/solid", 0, 1}, {"textures/common/nodraw", 0x80, 1}, {"textures/test/sky", 0x4, 1}};
  w.face(1, 0, {vtx(0, 0, 0), vtx(64, 0, 0), vtx(64, 64, 0), vtx(0, 64, 0)}, {0, 1, 2, 0, 3, 2}, {0, 0, 1});
  w.face(3, 0, {vtx(0, 0, 32, {1, 0, 0}), vtx(0, 16, 32, {1, 0, 0}), vtx(0, 16, 48, {1, 0, 0}), vtx(0, 0, 48, {1, 0, 0})},
         {0, 1, 2, 0, 3, 2});
  std::vector<BspWriter::Vertex> net3;  // x runs fastest; rows along -y so the net turns clockwise from above
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i)
      net3.push_back(vtx(100.0f + 32.0f * static_cast<float>(i), -32.0f * static_cast<float>(j), i == 1 && j == 1 ? 40.0f : 0.0f));
  w.face(2, 0, net3, {}, {}, {3, 3});
  std::vector<BspWriter::Vertex> net5;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 5; ++i)
      net5.push_back(vtx(200.0f + 16.0f * static_cast<float>(i), 16.0f * static_cast<float>(j), static_cast<float>(i % 2) * 8.0f));
  w.face(2, 0, net5, {}, {}, {5, 3});
  w.face(1, 1, {vtx(0, 0, 100), vtx(10, 0, 100), vtx(10, 10, 100)}, {0, 1, 2}, {0, 0, 1});
  w.face(4, 0, {vtx(5, 5, 5)}, {});
  w.face(1, 2, {vtx(0, 0, 200), vtx(10, 0, 200), vtx(10, 10, 200)}, {0, 1, 2}, {0, 0, 1});
  w.face(1, 0, {vtx(0, 0, 300), vtx(10, 0, 300), vtx(10, 10, 300)}, {0, 1, 2}, {0, 0, 1});
  w.face(1, 0, {vtx(0, 0, 400), vtx(10, 0, 400), vtx(10, 10, 400)}, {0, 1, 2}, {0, 0, 1});
  w.leaf({});
  w.leaf({0, 1});
  w.leaf({2, 3, 4, 5, 6, 0, 8});
  w.models = {{0, 8, 0, 0}, {8, 1, 0, 0}};
  w.entities =
      "{\n\"classname\" \"worldspawn\"\n}\n{\n\"classname\" \"info_player_deathmatch\"\n\"origin\" \"32 32 24\"\n}\n"
      "{\n\"origin\" \"100 -8 16\"\n\"classname\" \"weapon_rocketlauncher\"\n}\n{\n\"classname\" \"light\"\n\"origin\" \"0 0 64\"\n}\n";
  return w;
}

BspMap read(const BspWriter& w, int segments = kDefaultPatchSegments) {
  const std::vector<std::uint8_t> b = w.bytes();
  return read_bsp(b, "test.bsp", {segments});
}

glm::vec3 normal_of(const BspMap& m, std::uint32_t k) {
  const glm::vec3 a = m.vertices[m.indices[k]], b = m.vertices[m.indices[k + 1]], c = m.vertices[m.indices[k + 2]];
  return glm::cross(b - a, c - a);
}

// Scene parameters with objects in cubes of `m` metres (0: by leaf and type only).
Q3BspSceneParams cells(double m) {
  Q3BspSceneParams p;
  p.object_cell_m = m;
  return p;
}

// Polygons, meshes and patches are read, billboards, nodraw, sky, leafless and brush-model faces not.
TEST(Q3BspTest, ReadsTheDrawnFacesOfTheWorld) {
  const BspMap m = read(test_map());
  ASSERT_EQ(m.faces.size(), 4u) << "faces 0-3 are drawn";
  EXPECT_EQ(m.skipped_faces, 4u) << "nodraw, billboard, sky and the face in no leaf";
  const std::array<BspFaceType, 4> types = {BspFaceType::Polygon, BspFaceType::Mesh, BspFaceType::Patch, BspFaceType::Patch};
  const std::array<std::uint32_t, 4> leaves = {1, 1, 2, 2}, tris = {2, 2, 8 * 8 * 2, 2 * 8 * 8 * 2};
  for (std::size_t f = 0; f < 4; ++f) {
    EXPECT_EQ(m.faces[f].face, f);
    EXPECT_EQ(m.faces[f].type, types[f]) << "face " << f;
    EXPECT_EQ(m.faces[f].leaf, leaves[f]) << "face " << f << ": the first leaf that lists it";
    EXPECT_EQ(m.faces[f].index_count, 3 * tris[f]) << "face " << f << ": triangles";
  }
  EXPECT_EQ(m.indices.size(), 3u * (2 + 2 + 128 + 256));
  EXPECT_EQ(read(test_map(), 2).indices.size(), 3u * (2 + 2 + 8 + 16)) << "two segments a patch side";
}

// (x, y, z) inches -> (x, z, -y) metres: a proper rotation, so a quad's winding is kept.
TEST(Q3BspTest, ConvertsToYUpMetres) {
  const glm::vec3 v = quake_to_scene({1.0f, 2.0f, 3.0f});
  EXPECT_FLOAT_EQ(v.x, 0.0254f);
  EXPECT_FLOAT_EQ(v.y, 0.0762f);
  EXPECT_FLOAT_EQ(v.z, -0.0508f);
  const BspMap m = read(test_map());
  EXPECT_EQ(m.vertices[1], glm::vec3(quake_to_scene({64, 0, 0})));
  EXPECT_NEAR(m.vertices[2].z, -64 * 0.0254f, 1e-6f);
  const glm::vec3 x = quake_to_scene({1, 0, 0}), y = quake_to_scene({0, 1, 0}), z = quake_to_scene({0, 0, 1});
  EXPECT_GT(glm::dot(glm::cross(x, y), z), 0.0f) << "the conversion must keep handedness";
  EXPECT_EQ(glm::normalize(z), glm::vec3(0, 1, 0)) << "Quake's up is the scene's y";
  ASSERT_EQ(m.entities.size(), 2u) << "the spawn point and the weapon; worldspawn and light are not walked to";
  EXPECT_EQ(m.entities[0].classname, "info_player_deathmatch");
  EXPECT_EQ(m.entities[0].origin, quake_to_scene({32, 32, 24}));
  EXPECT_EQ(m.entities[1].classname, "weapon_rocketlauncher");
  EXPECT_EQ(m.entities[1].origin, quake_to_scene({100, -8, 16}));
}

// Every triangle counter-clockwise seen from the side its normals point to.
TEST(Q3BspTest, WindsTrianglesAgainstTheNormals) {
  const BspMap m = read(test_map());
  const std::array<glm::vec3, 4> front = {quake_to_scene({0, 0, 1}), quake_to_scene({1, 0, 0}), quake_to_scene({0, 0, 1}),
                                          quake_to_scene({0, 0, 1})};
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const BspFace& face = m.faces[f];
    for (std::uint32_t k = face.first_index; k < face.first_index + face.index_count; k += 3) {
      const glm::vec3 n = normal_of(m, k);
      EXPECT_GT(glm::dot(n, front[f]), 0.0f) << "face " << f << " triangle " << (k - face.first_index) / 3
                                             << " is wound against its normal";
    }
  }
}

// A patch passes through its corner control points and, at its centre, through the biquadratic
// Bezier's value (weights 1 2 1 / 2 4 2 / 1 2 1 over 16).
TEST(Q3BspTest, PatchInterpolatesItsCorners) {
  const BspWriter w = test_map();
  const BspMap m = read(w);
  const BspFace& p = m.faces[2];
  auto has_vertex = [&](glm::vec3 want, float tol) {
    for (std::uint32_t k = p.first_index; k < p.first_index + p.index_count; ++k)
      if (glm::length(m.vertices[m.indices[k]] - want) <= tol) return true;
    return false;
  };
  const std::int32_t first = w.faces[2].vertex;
  for (int c : {0, 2, 6, 8})
    EXPECT_TRUE(has_vertex(quake_to_scene(w.vertexes[static_cast<std::size_t>(first + c)].pos), 0.0f))
        << "control point " << c << " exactly";
  const glm::vec3 centre = quake_to_scene({132.0f, -32.0f, 40.0f * 4.0f / 16.0f});
  EXPECT_TRUE(has_vertex(centre, 1e-5f)) << "the patch's centre";
  EXPECT_FALSE(has_vertex(quake_to_scene({132.0f, -32.0f, 40.0f}), 1e-3f)) << "the middle control point is not on the surface";
}

// The scene: objects by (leaf, type[, cell]), tight bounds, the BVH holding every object once.
TEST(Q3BspTest, SceneObjectsBoundsAndBvhAgree) {
  const BspMap m = read(test_map());
  const CaptureScene s = make_q3bsp_scene(m, "dir/test.bsp", cells(0.0));
  ASSERT_EQ(s.objects.size(), 3u) << "(leaf 1, polygon), (leaf 1, mesh), (leaf 2, patch)";
  ASSERT_EQ(s.object_class.size(), 3u);
  EXPECT_EQ(s.class_names[s.object_class[0]], "structure");
  EXPECT_EQ(s.class_names[s.object_class[1]], "mesh");
  EXPECT_EQ(s.class_names[s.object_class[2]], "patch");
  EXPECT_EQ(s.objects[2].index_count, 3u * (128 + 256)) << "both patches of leaf 2 are one object";
  ASSERT_EQ(s.scene.objects.size(), 3u);
  glm::vec3 all_lo(INFINITY);
  for (std::size_t o = 0; o < s.objects.size(); ++o) {
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (std::uint32_t k = s.objects[o].first_index; k < s.objects[o].first_index + s.objects[o].index_count; ++k)
      lo = glm::min(lo, s.vertices[s.indices[k]]), hi = glm::max(hi, s.vertices[s.indices[k]]);
    all_lo = glm::min(all_lo, lo);
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(s.scene.objects[o].lo[a], lo[a]) << "object " << o << " bounds are not tight";
      EXPECT_EQ(s.scene.objects[o].hi[a], hi[a]) << "object " << o << " bounds are not tight";
    }
    EXPECT_EQ(s.scene.triangles[o], s.objects[o].index_count / 3);
  }
  EXPECT_EQ(all_lo, glm::vec3(0.0f)) << "the level is moved to start at the origin";
  std::vector<int> seen(s.objects.size(), 0);
  for (std::size_t n = 0; n < s.scene.node_left.size(); ++n)
    if (s.scene.node_left[n] < 0)
      for (std::uint32_t k = s.scene.node_first[n]; k < s.scene.node_first[n] + s.scene.node_count[n]; ++k) {
        const std::uint32_t o = s.scene.leaf_objects.at(k);
        ++seen.at(o);
        for (int a = 0; a < 3; ++a) {
          EXPECT_LE(s.scene.node_bounds[n].lo[a], s.scene.objects[o].lo[a]);
          EXPECT_GE(s.scene.node_bounds[n].hi[a], s.scene.objects[o].hi[a]);
        }
      }
  EXPECT_EQ(seen, std::vector<int>(s.objects.size(), 1)) << "every object in exactly one BVH leaf";
  const auto prop = [&](const std::string& k) {
    for (const auto& [key, value] : s.properties)
      if (key == k) return value;
    return std::string("(absent)");
  };
  EXPECT_EQ(prop("bsp"), "test.bsp");
  EXPECT_EQ(prop("objects"), "3");
  EXPECT_EQ(prop("triangles"), std::to_string(2 + 2 + 128 + 256));
  EXPECT_EQ(prop("patch_segments"), "8");
  EXPECT_EQ(make_q3bsp_scene(m, "test.bsp").objects.size(), 3u) << "8 m cells: the patches' centres share one";
  EXPECT_EQ(make_q3bsp_scene(m, "test.bsp", cells(1.0)).objects.size(), 4u) << "1 m cells split leaf 2's patches";
}

// The message read_bsp throws on `bytes` ("" when it reads).
std::string error_of(const std::vector<std::uint8_t>& bytes) {
  return nbsim::testing::input_error([&] { read_bsp(bytes, "bad.bsp"); });
}

// Every kind of bad input is an InputError naming the file and the problem, never a crash.
TEST(Q3BspTest, RefusesBadInputByName) {
  constexpr std::size_t kFaces = 13, kVertexes = 10, kFaceBytes = 104;
  const BspWriter good = test_map();
  const std::vector<std::uint8_t> base = good.bytes();
  const std::size_t faces_at = static_cast<std::size_t>(peek_i32(base, lump_entry(kFaces)));
  auto face_field = [&](std::size_t face, std::size_t word) { return faces_at + face * kFaceBytes + 4 * word; };
  struct Case {
    const char* why;
    std::function<void(std::vector<std::uint8_t>&)> damage;
    const char* message;
  };
  const std::vector<Case> cases = {
      {"truncated below the header", [](auto& b) { b.resize(100); }, "truncated: 100 bytes"},
      {"truncated inside a lump", [](auto& b) { b.resize(b.size() - 10); }, "outside the file"},
      {"wrong magic", [](auto& b) { b[0] = 'V'; }, "magic is not IBSP"},
      {"wrong version", [](auto& b) { poke_i32(b, 4, 47); }, "BSP version 47"},
      {"lump offset past the end", [&](auto& b) { poke_i32(b, lump_entry(kVertexes), 1 << 30); }, "lump vertexes"},
      {"negative lump length", [&](auto& b) { poke_i32(b, lump_entry(kFaces) + 4, -104); }, "lump faces"},
      {"lump of partial records", [&](auto& b) { poke_i32(b, lump_entry(kFaces) + 4, peek_i32(b, lump_entry(kFaces) + 4) - 4); },
       "not a whole number of 104-byte records"},
      {"texture index", [&](auto& b) { poke_i32(b, face_field(0, 0), 9); }, "face 0: texture 9 outside"},
      {"vertex range", [&](auto& b) { poke_i32(b, face_field(0, 3), 1000); }, "face 0: vertexes [1000, 1004) outside"},
      {"meshvert range", [&](auto& b) { poke_i32(b, face_field(1, 5), 500); }, "face 1: meshverts [500, 506) outside"},
      {"meshverts not triangles", [&](auto& b) { poke_i32(b, face_field(0, 6), 5); },
       "face 0: 5 meshverts, not a whole number of triangles"},
      {"meshvert offset", [&](auto& b) {
         const std::size_t mv = static_cast<std::size_t>(peek_i32(b, lump_entry(11)));
         poke_i32(b, mv + 4, 7);
       },
       "entry 1 (face 0): offset 7 outside the face's 4 vertexes"},
      {"leafface to no face", [&](auto& b) { poke_i32(b, static_cast<std::size_t>(peek_i32(b, lump_entry(5))), 99); },
       "lump leaffaces, entry 0 (leaf 1): face 99 outside"},
      {"leaf range", [&](auto& b) { poke_i32(b, static_cast<std::size_t>(peek_i32(b, lump_entry(4))) + 48 + 36, 77); },
       "lump leafs, leaf 1: leaffaces [0, 77) outside"},
      {"patch side even", [&](auto& b) { poke_i32(b, face_field(2, 24), 4); }, "face 2: patch of 4 x 3 control points"},
      {"patch side below 3", [&](auto& b) { poke_i32(b, face_field(3, 25), 1); }, "face 3: patch of 5 x 1 control points"},
      {"patch bigger than its vertexes", [&](auto& b) { poke_i32(b, face_field(2, 25), 5); },
       "patch of 3 x 5 control points but the face has 9"},
      {"face type", [&](auto& b) { poke_i32(b, face_field(1, 2), 7); }, "face 1: type 7"},
      {"NaN position", [&](auto& b) {
         const float nan = std::numeric_limits<float>::quiet_NaN();
         std::memcpy(b.data() + static_cast<std::size_t>(peek_i32(b, lump_entry(kVertexes))) + 44 + 4, &nan, 4);
       },
       "vertex 1 (face 0): position is not finite"},
      {"NaN patch control point", [&](auto& b) {
         const float inf = std::numeric_limits<float>::infinity();
         std::memcpy(b.data() + static_cast<std::size_t>(peek_i32(b, lump_entry(kVertexes))) + 44 * 9, &inf, 4);
       },
       "vertex 9 (face 2): position is not finite"},
      {"no world model", [&](auto& b) { poke_i32(b, lump_entry(7) + 4, 0); }, "no model 0"},
      {"world faces out of the lump", [&](auto& b) { poke_i32(b, static_cast<std::size_t>(peek_i32(b, lump_entry(7))) + 28, 50); },
       "model 0: faces [0, 50) outside"},
  };
  for (const Case& c : cases) {
    std::vector<std::uint8_t> b = base;
    c.damage(b);
    const std::string e = error_of(b);
    EXPECT_NE(e.find("'bad.bsp'"), std::string::npos) << c.why << ": the message must name the file: " << e;
    EXPECT_NE(e.find(c.message), std::string::npos) << c.why << ": expected '" << c.message << "' in: " << e;
  }
  // Whole maps that are wrong: nothing to draw, broken entities.
  BspWriter nodraw = test_map();
  for (auto& f : nodraw.faces) f.texture = 1;
  EXPECT_NE(error_of(nodraw.bytes()).find("no drawable triangles in the world's 8 faces"), std::string::npos) << error_of(nodraw.bytes());
  for (const auto& [text, message] : std::vector<std::pair<std::string, std::string>>{
           {"{ \"classname\" \"info_player_start\" ", "entity 0: not closed"},
           {"{ \"classname\" \"info_player_start\" \"origin\" \"1 2\" }",
            "entity 0 (info_player_start): origin '1 2' is not three numbers"},
           {"{ \"classname\" \"item_armor_body\" \"origin\" \"1 nan 2\" }", "origin '1 nan 2' is not three numbers"},
           {"{ \"classname } ", "not closed"},
           {"x", "'{' expected at byte 0"},
       }) {
    BspWriter w = test_map();
    w.entities = text;
    EXPECT_NE(error_of(w.bytes()).find(message), std::string::npos) << text << ": " << error_of(w.bytes());
  }
  EXPECT_NE(error_of({}).find("truncated: 0 bytes"), std::string::npos);
  // Random damage: any byte of the header or the face lump, never a crash (an InputError or a map).
  std::mt19937 rng(7);
  for (int k = 0; k < 2000; ++k) {
    std::vector<std::uint8_t> b = base;
    const std::size_t at = k % 2 ? rng() % 144 : faces_at + rng() % (9 * kFaceBytes);
    b[at] = static_cast<std::uint8_t>(rng());
    error_of(b);
  }
  EXPECT_THROW(load_bsp("/nonexistent/level.bsp"), InputError);
}

double distance_to_segment(glm::vec3 p, glm::vec3 a, glm::vec3 b) {
  const glm::vec3 d = b - a;
  const float t = glm::clamp(glm::dot(p - a, d) / glm::dot(d, d), 0.0f, 1.0f);
  return glm::length(p - (a + t * d));
}

// Waypoints at eye height above the floor, links only where the pillar does not stand between.
TEST(Q3BspTest, WaypointsLinkAroundThePillar) {
  const CaptureScene s = make_q3bsp_scene(read(room_map()), "room.bsp");
  ASSERT_EQ(s.site.waypoints.size(), 5u);
  for (const glm::vec3& p : s.site.waypoints) EXPECT_NEAR(p.y, 1.7f, 1e-4f) << "eye height above the floor";
  auto linked = [&](std::uint32_t a, std::uint32_t b) {
    for (const auto& l : s.site.waypoint_links)
      if ((l[0] == a && l[1] == b) || (l[0] == b && l[1] == a)) return true;
    return false;
  };
  EXPECT_TRUE(linked(0, 1));
  EXPECT_TRUE(linked(1, 2));
  EXPECT_TRUE(linked(0, 3));
  EXPECT_FALSE(linked(0, 2)) << "the diagonal crosses the pillar";
  EXPECT_FALSE(linked(1, 3)) << "the diagonal crosses the pillar";
  EXPECT_FALSE(linked(4, 2)) << "behind the pillar";
  EXPECT_TRUE(s.site.enclosed);
}

// The tour: every pose on a clear link, 1.2 m a frame at most, and deterministic for a seed; the
// paths that need an open site or streets are refused by name.
TEST(Q3BspTest, TourStaysOnClearLinks) {
  const CaptureScene s = make_q3bsp_scene(read(room_map()), "room.bsp");
  const TriangleCaster caster(s.vertices, s.indices);
  for (const auto& l : s.site.waypoint_links)
    EXPECT_TRUE(caster.segment_clear(s.site.waypoints[l[0]], s.site.waypoints[l[1]])) << "link " << l[0] << "-" << l[1];
  OptionValues opts;
  opts.set("seed", "3");
  const std::vector<CameraPose> poses = find_path("tour").make(s, 120, opts);
  ASSERT_EQ(poses.size(), 120u);
  for (std::size_t f = 0; f < poses.size(); ++f) {
    double best = INFINITY;
    for (const auto& l : s.site.waypoint_links)
      best = std::min(best, distance_to_segment(poses[f].eye, s.site.waypoints[l[0]], s.site.waypoints[l[1]]));
    EXPECT_LT(best, 1e-4) << "frame " << f << " is off the links";
    if (f > 0) {
      EXPECT_LE(glm::length(poses[f].eye - poses[f - 1].eye), 1.2f + 1e-4f) << "frame " << f;
    }
    EXPECT_GT(glm::length(poses[f].target - poses[f].eye), 0.5f);
  }
  int ahead = 0;
  for (std::size_t f = 1; f < poses.size(); ++f)
    ahead += glm::dot(glm::normalize(poses[f].eye - poses[f - 1].eye), glm::normalize(poses[f].target - poses[f].eye)) > 0.5f;
  EXPECT_GT(ahead, 100) << "the view must look where the walk goes (U-turns included), not backwards";
  const std::vector<CameraPose> again = find_path("tour").make(s, 120, opts);
  for (std::size_t f = 0; f < poses.size(); ++f) EXPECT_EQ(poses[f].eye, again[f].eye) << "frame " << f;
  for (const char* path : {"walk", "ground"}) {
    try {
      find_path(path).make(s, 10, opts);
      ADD_FAILURE() << path << " must be refused on an enclosed scene";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("tour"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(find_path("fly").make(s, 10, opts).size(), 10u);
  BspWriter lonely = room_map();
  lonely.entities = "{ \"classname\" \"info_player_start\" \"origin\" \"64 64 24\" }";
  const CaptureScene one = make_q3bsp_scene(read(lonely), "one.bsp");
  EXPECT_THROW(find_path("tour").make(one, 10, opts), InputError) << "one waypoint, no link";
}

// The BVH caster against every triangle one by one, on random segments through the room.
TEST(Q3BspTest, CasterAgreesWithBruteForce) {
  const CaptureScene s = make_q3bsp_scene(read(room_map()), "room.bsp");
  const TriangleCaster caster(s.vertices, s.indices);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 14.0f);
  int blocked = 0;
  for (int k = 0; k < 3000; ++k) {
    const glm::vec3 a(u(rng), u(rng) * 0.5f, u(rng)), b(u(rng), u(rng) * 0.5f, u(rng));
    bool brute = true;
    for (std::size_t t = 0; t < s.indices.size() && brute; t += 3) {
      const glm::vec3 p0 = s.vertices[s.indices[t]], p1 = s.vertices[s.indices[t + 1]], p2 = s.vertices[s.indices[t + 2]];
      const glm::vec3 n = glm::cross(p1 - p0, p2 - p0);
      const float da = glm::dot(a - p0, n), db = glm::dot(b - p0, n);
      if ((da > 0) == (db > 0) || da == db) continue;
      const glm::vec3 x = a + (b - a) * (da / (da - db));
      const bool inside = glm::dot(glm::cross(p1 - p0, x - p0), n) >= 0 && glm::dot(glm::cross(p2 - p1, x - p1), n) >= 0 &&
                          glm::dot(glm::cross(p0 - p2, x - p2), n) >= 0;
      if (inside) brute = false;
    }
    blocked += brute ? 0 : 1;
    EXPECT_EQ(caster.segment_clear(a, b), brute) << "segment " << k;
  }
  EXPECT_GT(blocked, 300) << "the random segments must test both answers";
}

// A real level (OpenArena's oa_dm5: polygons, meshes and patches) loads straight from its package,
// and its tour's links are clear; a missing member, a wildcard and a missing package are refused by
// name. Skipped without Debian's openarena-data or unzip.
TEST(Q3BspTest, OpenArenaLevelLoads) {
  const std::string pak = "/usr/share/games/openarena/baseoa/pak1-maps.pk3";
  if (!std::filesystem::exists(pak)) GTEST_SKIP() << pak << " absent (openarena-data)";
  if (std::system("unzip -v > /dev/null 2>&1") != 0) GTEST_SKIP() << "unzip is not installed";
  const auto t0 = std::chrono::steady_clock::now();
  const BspMap m = load_bsp(pak + ":maps/oa_dm5.bsp");
  const CaptureScene s = make_q3bsp_scene(m, pak + ":maps/oa_dm5.bsp");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::size_t patches = 0, meshes = 0;
  for (const BspFace& f : m.faces) patches += f.type == BspFaceType::Patch, meshes += f.type == BspFaceType::Mesh;
  EXPECT_GT(patches, 50u);
  EXPECT_GT(meshes, 10u);
  EXPECT_GT(s.objects.size(), 100u);
  EXPECT_GT(s.site.waypoint_links.size(), 20u);
  EXPECT_EQ(s.properties.front().second, "oa_dm5.bsp");
  const TriangleCaster caster(s.vertices, s.indices);
  for (const auto& l : s.site.waypoint_links)
    EXPECT_TRUE(caster.segment_clear(s.site.waypoints[l[0]], s.site.waypoints[l[1]])) << "link " << l[0] << "-" << l[1];
  EXPECT_EQ(find_path("tour").make(s, 60, OptionValues{}).size(), 60u);
  std::printf("oa_dm5: %zu faces, %zu triangles, %zu objects, %zu waypoints, %zu links; read and linked in %.3f s\n", m.faces.size(),
              s.indices.size() / 3, s.objects.size(), s.site.waypoints.size(), s.site.waypoint_links.size(), seconds);
  using nbsim::testing::input_error;
  EXPECT_NE(input_error([&] { load_bsp(pak + ":maps/no_such_level.bsp"); }).find("exit status 11"), std::string::npos);
  EXPECT_NE(input_error([&] { load_bsp(pak + ":maps/*.bsp"); }).find("no wildcard"), std::string::npos);
  EXPECT_NE(input_error([&] { load_bsp("/nonexistent.pk3:maps/oa_dm5.bsp"); }).find("no archive '/nonexistent.pk3'"), std::string::npos);
}

}  // namespace
}  // namespace nbsim::capture

// A Quake 3 .bsp writer for the tests (IBSP version 46, the lumps traces/capture/q3bsp.h reads,
// the others empty; the host is little-endian) and a small level made with it, a room with a
// pillar and spawn points: q3bsp_test.cpp checks the reader on such files, capture_test.cpp runs
// every technique on the room as the q3bsp scene.
#pragma once

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace nbsim::testing {

struct BspWriter {
  struct Texture {
    std::string name;
    std::uint32_t surface = 0, contents = 1;
  };
  struct Vertex {
    glm::vec3 pos{0.0f}, normal{0.0f, 0.0f, 1.0f};
  };
  struct Face {
    std::int32_t texture = 0, type = 1, vertex = 0, n_vertexes = 0, meshvert = 0, n_meshverts = 0;
    glm::vec3 normal{0.0f};
    std::int32_t size[2] = {0, 0};
  };
  std::string entities;
  std::vector<Texture> textures;
  std::vector<std::array<std::int32_t, 12>> leafs;
  std::vector<std::int32_t> leaffaces;
  std::vector<std::array<std::int32_t, 4>> models;  // face, n_faces, brush, n_brushes (bounds written as 0)
  std::vector<Vertex> vertexes;
  std::vector<std::int32_t> meshverts;
  std::vector<Face> faces;

  // A face of `type` over new vertexes; polygons and meshes take `tris` (offsets), patches `size`.
  std::int32_t face(std::int32_t type, std::int32_t texture, const std::vector<Vertex>& verts, const std::vector<std::int32_t>& tris,
                    glm::vec3 normal = glm::vec3(0.0f), std::array<std::int32_t, 2> size = {0, 0}) {
    Face f;
    f.texture = texture, f.type = type, f.normal = normal;
    f.vertex = static_cast<std::int32_t>(vertexes.size()), f.n_vertexes = static_cast<std::int32_t>(verts.size());
    f.meshvert = static_cast<std::int32_t>(meshverts.size()), f.n_meshverts = static_cast<std::int32_t>(tris.size());
    f.size[0] = size[0], f.size[1] = size[1];
    vertexes.insert(vertexes.end(), verts.begin(), verts.end());
    meshverts.insert(meshverts.end(), tris.begin(), tris.end());
    faces.push_back(f);
    return static_cast<std::int32_t>(faces.size() - 1);
  }
  // A leaf listing `fs`.
  void leaf(const std::vector<std::int32_t>& fs) {
    std::array<std::int32_t, 12> l{};
    l[8] = static_cast<std::int32_t>(leaffaces.size()), l[9] = static_cast<std::int32_t>(fs.size());
    leaffaces.insert(leaffaces.end(), fs.begin(), fs.end());
    leafs.push_back(l);
  }

  std::vector<std::uint8_t> bytes() const {
    std::array<std::vector<std::uint8_t>, 17> lumps;
    auto put = [](std::vector<std::uint8_t>& out, const void* p, std::size_t n) {
      const auto* b = static_cast<const std::uint8_t*>(p);
      out.insert(out.end(), b, b + n);
    };
    auto i32 = [&](std::vector<std::uint8_t>& out, std::int32_t v) { put(out, &v, 4); };  // the test host is little-endian
    auto f32 = [&](std::vector<std::uint8_t>& out, float v) { put(out, &v, 4); };
    put(lumps[0], entities.data(), entities.size());
    for (const Texture& t : textures) {
      char name[64] = {};
      std::strncpy(name, t.name.c_str(), 63);
      put(lumps[1], name, 64);
      i32(lumps[1], static_cast<std::int32_t>(t.surface));
      i32(lumps[1], static_cast<std::int32_t>(t.contents));
    }
    for (const auto& l : leafs)
      for (std::int32_t v : l) i32(lumps[4], v);
    for (std::int32_t v : leaffaces) i32(lumps[5], v);
    for (const auto& m : models) {
      for (int k = 0; k < 6; ++k) f32(lumps[7], 0.0f);
      for (std::int32_t v : m) i32(lumps[7], v);
    }
    for (const Vertex& v : vertexes) {
      for (int k = 0; k < 3; ++k) f32(lumps[10], v.pos[k]);
      for (int k = 0; k < 4; ++k) f32(lumps[10], 0.0f);
      for (int k = 0; k < 3; ++k) f32(lumps[10], v.normal[k]);
      i32(lumps[10], -1);
    }
    for (std::int32_t v : meshverts) i32(lumps[11], v);
    for (const Face& f : faces) {
      for (std::int32_t v : {f.texture, 0, f.type, f.vertex, f.n_vertexes, f.meshvert, f.n_meshverts, -1, 0, 0, 0, 0}) i32(lumps[13], v);
      for (int k = 0; k < 9; ++k) f32(lumps[13], 0.0f);
      for (int k = 0; k < 3; ++k) f32(lumps[13], f.normal[k]);
      i32(lumps[13], f.size[0]);
      i32(lumps[13], f.size[1]);
    }
    std::vector<std::uint8_t> out = {'I', 'B', 'S', 'P'};
    i32(out, 46);
    std::int32_t offset = 8 + 17 * 8;
    for (const auto& l : lumps) {
      i32(out, offset);
      i32(out, static_cast<std::int32_t>(l.size()));
      offset += static_cast<std::int32_t>(l.size());
    }
    for (const auto& l : lumps) put(out, l.data(), l.size());
    return out;
  }
};

inline BspWriter::Vertex vtx(float x, float y, float z, glm::vec3 n = {0.0f, 0.0f, 1.0f}) { return {{x, y, z}, n}; }

// A room of 512 x 512 x 256 units with a pillar in the middle and spawn points in its corners.
inline BspWriter room_map() {
  BspWriter w;
  w.textures = {{"textures/test/solid", 0, 1}};
  std::vector<std::int32_t> all;
  auto quad = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
    const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    all.push_back(w.face(1, 0, {{a, n}, {b, n}, {c, n}, {d, n}}, {0, 1, 2, 0, 2, 3}, n));
  };
  auto box = [&](glm::vec3 lo, glm::vec3 hi, bool inward) {
    const glm::vec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {lo.x, hi.y, lo.z}, {hi.x, hi.y, lo.z},
                            {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z}};
    const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& f : faces)
      if (inward) quad(c[f[3]], c[f[2]], c[f[1]], c[f[0]]);
      else quad(c[f[0]], c[f[1]], c[f[2]], c[f[3]]);
  };
  box({0, 0, 0}, {512, 512, 256}, true);
  box({192, 192, 0}, {320, 320, 256}, false);
  w.leaf(all);
  w.models = {{0, static_cast<std::int32_t>(w.faces.size()), 0, 0}};
  w.entities = "{ \"classname\" \"worldspawn\" }";
  for (const char* o : {"64 64 24", "448 64 24", "448 448 24", "64 448 24", "224 64 24"})
    w.entities += std::string("{ \"classname\" \"info_player_deathmatch\" \"origin\" \"") + o + "\" }";
  return w;
}


// Writes `w` to `path`.
inline void write_bsp(const BspWriter& w, const std::filesystem::path& path) {
  const std::vector<std::uint8_t> b = w.bytes();
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

}  // namespace nbsim::testing

// Quake 3 BSP levels (IBSP version 46: OpenArena's maps, Debian's openarena-data) read into
// triangles for the capture's q3bsp scene (q3bsp_scene.h). The whole file is in memory and read
// little-endian; every lump offset and length, every record count and every index is checked, and
// a bad file is an InputError naming the file, the lump and the record, never a crash.
//
// What is read:
// - Model 0 only (the world). The brush models (doors, platforms, triggers) move in the game or
//   are invisible, and a still capture would show them at their rest position: left out.
// - Faces of type 1 (polygon) and 3 (mesh): triangles through meshverts (offsets added to the
//   face's first vertex); type 2 (patch): a grid of size[0] x size[1] control points, odd and at
//   least 3 each way, cut into 3x3 biquadratic Bezier patches, each tessellated into
//   patch_segments x patch_segments quads (two triangles each) on one grid per face, so that the
//   patches of a face share their seams. Type 4 (billboard, a flare) and type 0 (unused) are
//   skipped.
// - Faces whose shader cannot hide anything are skipped: surface flags nodraw (0x80, caulk, clip,
//   triggers) and sky (0x4); content flags fog (0x40), water (0x20) and translucent (0x20000000,
//   glass, beams, liquids drawn blended). Lava and slime stay (opaque in OpenArena). The shader
//   scripts are not read, so a blended or alpha-tested surface that carries none of these flags
//   (a flame, a grate) is drawn as a solid surface.
// - Faces that no BSP leaf lists are skipped: the game draws the world leaf by leaf, so these
//   are never drawn.
// - The entities lump (text): the spawn points and items an observer walks between, each with its
//   "origin": info_player_deathmatch, info_player_start, team_CTF_* (CTF spawns and flags),
//   weapon_*, item_*, ammo_*.
//
// Units and axes: Quake is z up, 1 unit = 1 inch = 0.0254 m (the usual convention: a player is 56
// units tall, 1.42 m). Positions become the scene's y up, metres, by the proper rotation
// (x, y, z) -> (x, z, -y) (determinant +1, so handedness and windings are kept) and that scale.
// Triangles are counter-clockwise seen from the front: a polygon's triangle whose winding
// disagrees with the face's stored normal is flipped, a mesh's against the sum of its three
// vertex normals; a patch face is flipped as a whole when its tessellated triangles, wound
// the same way as its control net, disagree on the whole with its control points' normals.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace nbsim::capture {

// Metres per Quake unit (fixed by the convention above).
inline constexpr double kQuakeUnitM = 0.0254;
// Quads a side of each 3x3 Bezier patch by default (tunable: 8 keeps a curved pillar round at
// 1.5 m without multiplying the triangles of a map more than 2 to 3 times).
inline constexpr int kDefaultPatchSegments = 8;
inline constexpr int kMaxPatchSegments = 32;
// Largest control grid side accepted (Quake 3's own limit, MAX_PATCH_SIZE, is 32).
inline constexpr int kMaxPatchSide = 65;

struct BspOptions {
  int patch_segments = kDefaultPatchSegments;  // 1..kMaxPatchSegments
};

enum class BspFaceType : std::uint8_t { Polygon = 1, Patch = 2, Mesh = 3 };

// One drawn face: a range of BspMap::indices.
struct BspFace {
  std::uint32_t face = 0;  // index in the faces lump
  BspFaceType type = BspFaceType::Polygon;
  std::uint32_t leaf = 0;  // the first leaf that lists the face
  std::uint32_t first_index = 0;
  std::uint32_t index_count = 0;  // three per triangle
};

struct BspEntity {
  std::string classname;
  glm::vec3 origin{0.0f};  // scene axes, metres
};

struct BspMap {
  std::vector<glm::vec3> vertices;     // scene axes (y up), metres
  std::vector<std::uint32_t> indices;  // triangles, counter-clockwise seen from the front
  std::vector<BspFace> faces;          // in the faces lump's order
  std::vector<BspEntity> entities;     // spawn points and items, in the lump's order
  std::uint32_t skipped_faces = 0;     // world faces left out (type, shader or no leaf)
};

// Quake's (x, y, z) in units to the scene's axes in metres.
glm::vec3 quake_to_scene(glm::vec3 quake);

// Reads a .bsp file held in `bytes`; `name` is the file's name for messages. Throws InputError
// on a truncated file, a wrong magic or version, a lump outside the file or of a length that is
// not a whole number of records, an index out of range, a patch with an even side or one below 3,
// a position that is not finite, a malformed entities lump, or a map with no drawable triangle.
BspMap read_bsp(std::span<const std::uint8_t> bytes, const std::string& name, const BspOptions& options = {});
// Reads the file at `path` (InputError when it cannot be read). `PAK.pk3:maps/NAME.bsp` reads the
// member maps/NAME.bsp of the zip archive PAK.pk3 (a game's package) through `unzip -p`, run
// without a shell; a member name with a wildcard (* ? [ ]) is refused, so that exactly one file is
// read, and a missing unzip, archive or member is an InputError.
BspMap load_bsp(const std::string& path, const BspOptions& options = {});
// The bytes of `path` as load_bsp reads them (the file, or the archive member).
std::vector<std::uint8_t> read_bsp_bytes(const std::string& path);

}  // namespace nbsim::capture

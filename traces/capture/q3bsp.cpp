// The Quake 3 BSP reader; see q3bsp.h. Record layouts are those of the IBSP version 46 file
// (little-endian 32-bit ints and floats): the header is the magic, the version and 17 lump entries
// (offset, length).
#include "traces/capture/q3bsp.h"

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string_view>

#include "model/common/error.h"

extern char** environ;

namespace nbsim::capture {

namespace {

constexpr std::array<std::string_view, 17> kLumpNames = {
    "entities", "textures", "planes", "nodes",     "leafs",   "leaffaces", "leafbrushes", "models",  "brushes",
    "brushsides", "vertexes", "meshverts", "effects", "faces", "lightmaps", "lightvols",  "visdata"};
enum Lump : std::size_t {
  kEntities = 0, kTextures = 1, kLeafs = 4, kLeafFaces = 5, kModels = 7, kVertexes = 10, kMeshVerts = 11, kFaces = 13
};
constexpr std::size_t kHeaderBytes = 8 + 8 * kLumpNames.size();
constexpr int kVersion = 46;

// Record sizes in bytes (fixed by the format).
constexpr std::size_t kTextureBytes = 72, kLeafBytes = 48, kLeafFaceBytes = 4, kModelBytes = 40, kVertexBytes = 44,
                      kMeshVertBytes = 4, kFaceBytes = 104;

// Shader flags that make a face skipped (see q3bsp.h).
constexpr std::uint32_t kSurfSky = 0x4, kSurfNodraw = 0x80;
constexpr std::uint32_t kContentsWater = 0x20, kContentsFog = 0x40, kContentsTranslucent = 0x20000000;

struct LumpView {
  std::size_t offset = 0, length = 0, count = 0;
};

class Reader {
 public:
  Reader(std::span<const std::uint8_t> bytes, const std::string& name, const BspOptions& options)
      : bytes_(bytes), name_(name), options_(options) {}

  BspMap read();

 private:
  template <class... Args>
  [[noreturn]] void fail(fmt::format_string<Args...> f, Args&&... args) const {
    throw InputError(fmt::format("q3bsp file '{}': {}", name_, fmt::format(f, std::forward<Args>(args)...)));
  }
  std::uint32_t u32(std::size_t at) const {
    return static_cast<std::uint32_t>(bytes_[at]) | static_cast<std::uint32_t>(bytes_[at + 1]) << 8 |
           static_cast<std::uint32_t>(bytes_[at + 2]) << 16 | static_cast<std::uint32_t>(bytes_[at + 3]) << 24;
  }
  std::int32_t i32(std::size_t at) const { return static_cast<std::int32_t>(u32(at)); }
  float f32(std::size_t at) const {
    const std::uint32_t u = u32(at);
    float f;
    std::memcpy(&f, &u, sizeof f);
    return f;
  }
  // Field `word` (4-byte words) of record `i` of lump `l`.
  std::size_t at(Lump l, std::size_t record_bytes, std::size_t i, std::size_t word) const {
    return lumps_[l].offset + i * record_bytes + 4 * word;
  }
  glm::dvec3 vec3_at(std::size_t at) const { return {f32(at), f32(at + 4), f32(at + 8)}; }

  void read_header();
  void read_leafs();
  void read_face(std::uint32_t f);
  // Output vertex of the face's vertex `v` (a vertexes index, already checked).
  std::uint32_t emit_vertex(std::uint32_t face, std::uint32_t v);
  void triangles(std::uint32_t f, BspFaceType type, std::uint32_t first_vertex, std::uint32_t n_vertexes, const glm::dvec3& normal);
  void patch(std::uint32_t f, std::uint32_t first_vertex, std::uint32_t n_vertexes);
  void entities();

  std::span<const std::uint8_t> bytes_;
  const std::string& name_;
  BspOptions options_;
  std::array<LumpView, kLumpNames.size()> lumps_{};
  std::vector<std::int64_t> leaf_of_;  // per face: the first leaf listing it, -1 none
  BspMap map_;
};

glm::dvec3 to_scene(const glm::dvec3& q) { return glm::dvec3(q.x, q.z, -q.y); }

bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void Reader::read_header() {
  if (bytes_.size() < kHeaderBytes)
    fail("truncated: {} bytes, the header alone takes {}", bytes_.size(), kHeaderBytes);
  if (std::memcmp(bytes_.data(), "IBSP", 4) != 0) fail("not a Quake 3 BSP file (magic is not IBSP)");
  if (const std::int32_t v = i32(4); v != kVersion) fail("BSP version {}, only {} (Quake 3, OpenArena) is read", v, kVersion);
  static constexpr std::array<std::size_t, kLumpNames.size()> kRecord = {
      1, kTextureBytes, 1, 1, kLeafBytes, kLeafFaceBytes, 1, kModelBytes, 1, 1, kVertexBytes, kMeshVertBytes, 1, kFaceBytes, 1, 1, 1};
  for (std::size_t l = 0; l < kLumpNames.size(); ++l) {
    const std::int64_t offset = i32(8 + 8 * l), length = i32(12 + 8 * l);
    if (offset < 0 || length < 0 || static_cast<std::uint64_t>(offset + length) > bytes_.size())
      fail("lump {} ({} bytes at offset {}) lies outside the file's {} bytes (truncated?)", kLumpNames[l], length, offset,
           bytes_.size());
    if (length % static_cast<std::int64_t>(kRecord[l]) != 0)
      fail("lump {} is {} bytes, not a whole number of {}-byte records", kLumpNames[l], length, kRecord[l]);
    lumps_[l] = {static_cast<std::size_t>(offset), static_cast<std::size_t>(length),
                 static_cast<std::size_t>(length) / kRecord[l]};
  }
}

void Reader::read_leafs() {
  const std::size_t faces = lumps_[kFaces].count, leaffaces = lumps_[kLeafFaces].count;
  leaf_of_.assign(faces, -1);
  for (std::size_t l = 0; l < lumps_[kLeafs].count; ++l) {
    const std::int64_t first = i32(at(kLeafs, kLeafBytes, l, 8)), n = i32(at(kLeafs, kLeafBytes, l, 9));
    if (first < 0 || n < 0 || static_cast<std::uint64_t>(first + n) > leaffaces)
      fail("lump leafs, leaf {}: leaffaces [{}, {}) outside the lump's {}", l, first, first + n, leaffaces);
    for (std::int64_t k = first; k < first + n; ++k) {
      const std::int64_t f = i32(at(kLeafFaces, kLeafFaceBytes, static_cast<std::size_t>(k), 0));
      if (f < 0 || static_cast<std::uint64_t>(f) >= faces)
        fail("lump leaffaces, entry {} (leaf {}): face {} outside the lump faces' {}", k, l, f, faces);
      if (leaf_of_[static_cast<std::size_t>(f)] < 0) leaf_of_[static_cast<std::size_t>(f)] = static_cast<std::int64_t>(l);
    }
  }
}

std::uint32_t Reader::emit_vertex(std::uint32_t face, std::uint32_t v) {
  const glm::dvec3 p = vec3_at(at(kVertexes, kVertexBytes, v, 0));
  if (!finite(p)) fail("lump vertexes, vertex {} (face {}): position is not finite", v, face);
  map_.vertices.push_back(glm::vec3(to_scene(p) * kQuakeUnitM));
  return static_cast<std::uint32_t>(map_.vertices.size() - 1);
}

void Reader::triangles(std::uint32_t f, BspFaceType type, std::uint32_t first_vertex, std::uint32_t n_vertexes,
                       const glm::dvec3& face_normal) {
  const std::size_t fa = at(kFaces, kFaceBytes, f, 0);
  const std::int64_t first = i32(fa + 4 * 5), n = i32(fa + 4 * 6);
  if (first < 0 || n < 0 || static_cast<std::uint64_t>(first + n) > lumps_[kMeshVerts].count)
    fail("lump faces, face {}: meshverts [{}, {}) outside the lump's {}", f, first, first + n, lumps_[kMeshVerts].count);
  if (n % 3 != 0) fail("lump faces, face {}: {} meshverts, not a whole number of triangles", f, n);
  const auto base = static_cast<std::uint32_t>(map_.vertices.size());
  for (std::uint32_t v = 0; v < n_vertexes; ++v) emit_vertex(f, first_vertex + v);
  const glm::dvec3 n_scene = to_scene(face_normal);
  const bool use_face_normal = type == BspFaceType::Polygon && finite(n_scene) && glm::dot(n_scene, n_scene) > 0.0;
  for (std::int64_t k = first; k < first + n; k += 3) {
    std::array<std::uint32_t, 3> tri{};
    for (std::size_t c = 0; c < 3; ++c) {
      const std::int64_t o = i32(at(kMeshVerts, kMeshVertBytes, static_cast<std::size_t>(k) + c, 0));
      if (o < 0 || static_cast<std::uint64_t>(o) >= n_vertexes)
        fail("lump meshverts, entry {} (face {}): offset {} outside the face's {} vertexes", k + static_cast<std::int64_t>(c), f, o,
             n_vertexes);
      tri[c] = static_cast<std::uint32_t>(o);
    }
    glm::dvec3 ref = n_scene;
    if (!use_face_normal) {
      ref = glm::dvec3(0.0);
      for (std::uint32_t c : tri) ref += to_scene(vec3_at(at(kVertexes, kVertexBytes, first_vertex + c, 7)));
    }
    const glm::dvec3 a = map_.vertices[base + tri[0]], b = map_.vertices[base + tri[1]], c = map_.vertices[base + tri[2]];
    if (glm::dot(glm::cross(b - a, c - a), ref) < 0.0) std::swap(tri[1], tri[2]);
    for (std::uint32_t t : tri) map_.indices.push_back(base + t);
  }
}

void Reader::patch(std::uint32_t f, std::uint32_t first_vertex, std::uint32_t n_vertexes) {
  const std::size_t fa = at(kFaces, kFaceBytes, f, 0);
  const std::int64_t w = i32(fa + 4 * 24), h = i32(fa + 4 * 25);
  for (const std::int64_t side : {w, h})
    if (side < 3 || side % 2 == 0 || side > kMaxPatchSide)
      fail("lump faces, face {}: patch of {} x {} control points (each side must be odd, 3 to {})", f, w, h, kMaxPatchSide);
  if (static_cast<std::uint64_t>(w * h) > n_vertexes)
    fail("lump faces, face {}: patch of {} x {} control points but the face has {} vertexes", f, w, h, n_vertexes);
  std::vector<glm::dvec3> pos(static_cast<std::size_t>(w * h)), nrm(pos.size());
  for (std::size_t k = 0; k < pos.size(); ++k) {
    const std::size_t va = at(kVertexes, kVertexBytes, first_vertex + k, 0);
    const glm::dvec3 p = vec3_at(va);
    if (!finite(p)) fail("lump vertexes, vertex {} (face {}): position is not finite", first_vertex + k, f);
    pos[k] = to_scene(p) * kQuakeUnitM;
    nrm[k] = to_scene(vec3_at(va + 4 * 7));
  }
  const auto segs = static_cast<std::size_t>(options_.patch_segments);
  const std::size_t px = static_cast<std::size_t>(w - 1) / 2, py = static_cast<std::size_t>(h - 1) / 2;
  const std::size_t gu = px * segs + 1, gv = py * segs + 1;
  const auto base = static_cast<std::uint32_t>(map_.vertices.size());
  std::vector<glm::dvec3> grid_pos(gu * gv), grid_nrm(gu * gv);
  auto bernstein = [](double t) { return std::array<double, 3>{(1 - t) * (1 - t), 2 * t * (1 - t), t * t}; };
  for (std::size_t b = 0; b < gv; ++b) {
    const std::size_t pj = std::min(b / segs, py - 1);
    const auto bv = bernstein(static_cast<double>(b - pj * segs) / static_cast<double>(segs));
    for (std::size_t a = 0; a < gu; ++a) {
      const std::size_t pi = std::min(a / segs, px - 1);
      const auto bu = bernstein(static_cast<double>(a - pi * segs) / static_cast<double>(segs));
      glm::dvec3 p(0.0), n(0.0);
      for (std::size_t m = 0; m < 3; ++m)
        for (std::size_t k = 0; k < 3; ++k) {
          const std::size_t c = (2 * pj + m) * static_cast<std::size_t>(w) + 2 * pi + k;
          p += bv[m] * bu[k] * pos[c];
          n += bv[m] * bu[k] * nrm[c];
        }
      grid_pos[b * gu + a] = p;
      grid_nrm[b * gu + a] = n;
      map_.vertices.push_back(glm::vec3(p));
    }
  }
  // Every quad split the same way and wound as the control net runs; the face's orientation from
  // its normals as a whole (a tessellated triangle may be degenerate where control points meet).
  const auto first_index = map_.indices.size();
  double agree = 0.0;
  for (std::size_t b = 0; b + 1 < gv; ++b)
    for (std::size_t a = 0; a + 1 < gu; ++a) {
      const std::size_t v00 = b * gu + a, v10 = v00 + 1, v01 = v00 + gu, v11 = v01 + 1;
      for (const std::array<std::size_t, 3> t : {std::array{v00, v10, v11}, std::array{v00, v11, v01}}) {
        const glm::dvec3 cr = glm::cross(grid_pos[t[1]] - grid_pos[t[0]], grid_pos[t[2]] - grid_pos[t[0]]);
        agree += glm::dot(cr, grid_nrm[t[0]] + grid_nrm[t[1]] + grid_nrm[t[2]]);
        for (std::size_t v : t) map_.indices.push_back(base + static_cast<std::uint32_t>(v));
      }
    }
  if (agree < 0.0)
    for (std::size_t k = first_index; k < map_.indices.size(); k += 3) std::swap(map_.indices[k + 1], map_.indices[k + 2]);
}

void Reader::read_face(std::uint32_t f) {
  const std::size_t fa = at(kFaces, kFaceBytes, f, 0);
  const std::int32_t type = i32(fa + 4 * 2);
  if (type < 0 || type > 4) fail("lump faces, face {}: type {} (1 polygon, 2 patch, 3 mesh, 4 billboard)", f, type);
  if (type == 0 || type == 4 || leaf_of_[f] < 0) {
    ++map_.skipped_faces;
    return;
  }
  const std::int64_t texture = i32(fa);
  if (texture < 0 || static_cast<std::uint64_t>(texture) >= lumps_[kTextures].count)
    fail("lump faces, face {}: texture {} outside the lump textures' {}", f, texture, lumps_[kTextures].count);
  const std::uint32_t surface = u32(at(kTextures, kTextureBytes, static_cast<std::size_t>(texture), 16));
  const std::uint32_t contents = u32(at(kTextures, kTextureBytes, static_cast<std::size_t>(texture), 17));
  if ((surface & (kSurfSky | kSurfNodraw)) != 0 || (contents & (kContentsWater | kContentsFog | kContentsTranslucent)) != 0) {
    ++map_.skipped_faces;
    return;
  }
  const std::int64_t first_vertex = i32(fa + 4 * 3), n_vertexes = i32(fa + 4 * 4);
  if (first_vertex < 0 || n_vertexes < 0 || static_cast<std::uint64_t>(first_vertex + n_vertexes) > lumps_[kVertexes].count)
    fail("lump faces, face {}: vertexes [{}, {}) outside the lump's {}", f, first_vertex, first_vertex + n_vertexes,
         lumps_[kVertexes].count);
  const auto first_index = static_cast<std::uint32_t>(map_.indices.size());
  const auto kind = static_cast<BspFaceType>(type);
  if (kind == BspFaceType::Patch)
    patch(f, static_cast<std::uint32_t>(first_vertex), static_cast<std::uint32_t>(n_vertexes));
  else
    triangles(f, kind, static_cast<std::uint32_t>(first_vertex), static_cast<std::uint32_t>(n_vertexes), vec3_at(fa + 4 * 21));
  const auto count = static_cast<std::uint32_t>(map_.indices.size()) - first_index;
  if (count == 0) {
    ++map_.skipped_faces;
    return;
  }
  map_.faces.push_back({f, kind, static_cast<std::uint32_t>(leaf_of_[f]), first_index, count});
}

// The entities lump: `{ "key" "value" ... }` blocks of quoted strings, up to its end or a NUL.
void Reader::entities() {
  const LumpView& l = lumps_[kEntities];
  std::string_view text(reinterpret_cast<const char*>(bytes_.data() + l.offset), l.length);
  text = text.substr(0, text.find('\0'));
  std::size_t pos = 0;
  auto skip_space = [&] {
    while (pos < text.size() && std::isspace(static_cast<unsigned char>(text[pos]))) ++pos;
  };
  auto quoted = [&](int entity) {
    if (pos >= text.size() || text[pos] != '"') fail("lump entities, entity {}: a quoted key or value expected at byte {}", entity, pos);
    const std::size_t end = text.find('"', pos + 1);
    if (end == std::string_view::npos) fail("lump entities, entity {}: a string opened at byte {} is not closed", entity, pos);
    std::string s(text.substr(pos + 1, end - pos - 1));
    pos = end + 1;
    return s;
  };
  for (int entity = 0;; ++entity) {
    skip_space();
    if (pos >= text.size()) break;
    if (text[pos] != '{') fail("lump entities: '{{' expected at byte {} (entity {})", pos, entity);
    ++pos;
    std::map<std::string, std::string> keys;
    for (;;) {
      skip_space();
      if (pos >= text.size()) fail("lump entities, entity {}: not closed by '}}'", entity);
      if (text[pos] == '}') break;
      std::string key = quoted(entity);
      skip_space();
      keys[key] = quoted(entity);
    }
    ++pos;
    const std::string& cls = keys["classname"];
    const bool wanted = cls == "info_player_deathmatch" || cls == "info_player_start" || cls.starts_with("team_CTF_") ||
                        cls.starts_with("weapon_") || cls.starts_with("item_") || cls.starts_with("ammo_");
    const auto origin = keys.find("origin");
    if (!wanted || origin == keys.end()) continue;
    std::array<double, 3> q{};
    const char* p = origin->second.c_str();
    for (double& x : q) {
      char* end = nullptr;
      x = std::strtod(p, &end);
      if (end == p || !std::isfinite(x))
        fail("lump entities, entity {} ({}): origin '{}' is not three numbers", entity, cls, origin->second);
      p = end;
    }
    map_.entities.push_back({cls, glm::vec3(to_scene({q[0], q[1], q[2]}) * kQuakeUnitM)});
  }
}

BspMap Reader::read() {
  if (options_.patch_segments < 1 || options_.patch_segments > kMaxPatchSegments)
    throw InputError(fmt::format("patch segments {} outside [1, {}]", options_.patch_segments, kMaxPatchSegments));
  read_header();
  read_leafs();
  if (lumps_[kModels].count == 0) fail("lump models is empty: no model 0 (the world)");
  const std::int64_t first = i32(at(kModels, kModelBytes, 0, 6)), n = i32(at(kModels, kModelBytes, 0, 7));
  if (first < 0 || n < 0 || static_cast<std::uint64_t>(first + n) > lumps_[kFaces].count)
    fail("lump models, model 0: faces [{}, {}) outside the lump faces' {}", first, first + n, lumps_[kFaces].count);
  for (auto f = static_cast<std::uint32_t>(first); f < static_cast<std::uint32_t>(first + n); ++f) read_face(f);
  if (map_.indices.empty())
    fail("no drawable triangles in the world's {} faces (billboards, nodraw, sky, fog, water, translucent or in no leaf)", n);
  entities();
  return std::move(map_);
}

}  // namespace

glm::vec3 quake_to_scene(glm::vec3 q) { return glm::vec3(to_scene(glm::dvec3(q)) * kQuakeUnitM); }

BspMap read_bsp(std::span<const std::uint8_t> bytes, const std::string& name, const BspOptions& options) {
  return Reader(bytes, name, options).read();
}

std::vector<std::uint8_t> read_bsp_bytes(const std::string& path) {
  const std::size_t colon = path.find(".pk3:");
  if (colon == std::string::npos) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(fmt::format("q3bsp file '{}' cannot be read (missing or not readable)", path));
    std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    if (in.bad()) throw InputError(fmt::format("q3bsp file '{}' cannot be read", path));
    return bytes;
  }
  const std::string pak = path.substr(0, colon + 4), member = path.substr(colon + 5);
  if (member.empty() || member.find_first_of("*?[]") != std::string::npos)
    throw InputError(fmt::format("q3bsp file '{}': the member name '{}' must name one file (no wildcard)", path, member));
  if (!std::filesystem::is_regular_file(pak)) throw InputError(fmt::format("q3bsp file '{}': no archive '{}'", path, pak));
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0)
    throw std::runtime_error(fmt::format("cannot make a pipe to read '{}': {}", path, std::strerror(errno)));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  std::string arg0 = "unzip", arg1 = "-p", arg2 = pak, arg3 = member;
  char* argv[] = {arg0.data(), arg1.data(), arg2.data(), arg3.data(), nullptr};
  pid_t pid = 0;
  const int spawned = ::posix_spawnp(&pid, "unzip", &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[1]);
  if (spawned != 0) {
    ::close(fds[0]);
    throw InputError(fmt::format("q3bsp file '{}': cannot run unzip ({}); extract it with unzip -p {} {} > FILE.bsp", path,
                                 std::strerror(spawned), pak, member));
  }
  std::vector<std::uint8_t> bytes;
  constexpr std::size_t kMaxBytes = std::size_t{1} << 30;  // a level is a few MB; 1 GiB means a wrong member
  bool too_big = false;
  for (;;) {
    std::uint8_t buf[1 << 16];
    const ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    bytes.insert(bytes.end(), buf, buf + n);
    if (bytes.size() > kMaxBytes) {
      too_big = true;
      ::kill(pid, SIGKILL);
      break;
    }
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (too_big) throw InputError(fmt::format("q3bsp file '{}': the member is larger than {} bytes", path, kMaxBytes));
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw InputError(fmt::format("q3bsp file '{}': unzip -p {} {} failed (exit status {}; 11: no such member, 9: not a zip archive)",
                                 path, pak, member, WIFEXITED(status) ? WEXITSTATUS(status) : -1));
  return bytes;
}

BspMap load_bsp(const std::string& path, const BspOptions& options) { return read_bsp(read_bsp_bytes(path), path, options); }

}  // namespace nbsim::capture

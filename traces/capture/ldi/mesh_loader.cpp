// Mesh files through libassimp; see mesh_loader.h.
#include "traces/capture/ldi/mesh_loader.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

#include "model/common/error.h"

namespace nbsim::capture {
namespace {

// Appends every mesh under `node`, placed by the transform accumulated from the root.
void append_node(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent, mesh::TriMesh& out) {
  const aiMatrix4x4 transform = parent * node.mTransformation;
  const bool mirrored = transform.Determinant() < 0.0f;
  for (unsigned k = 0; k < node.mNumMeshes; ++k) {
    const aiMesh& m = *scene.mMeshes[node.mMeshes[k]];
    const auto base = static_cast<std::uint32_t>(out.vertices.size());
    for (unsigned v = 0; v < m.mNumVertices; ++v) {
      const aiVector3D p = transform * m.mVertices[v];
      out.vertices.push_back({p.x, p.y, p.z});
    }
    for (unsigned f = 0; f < m.mNumFaces; ++f) {
      const aiFace& face = m.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      mesh::Tri t = {base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]};
      if (mirrored) std::swap(t[1], t[2]);
      out.triangles.push_back(t);
    }
  }
  for (unsigned c = 0; c < node.mNumChildren; ++c) append_node(scene, *node.mChildren[c], transform, out);
}

}  // namespace
}  // namespace nbsim::capture

// Debian's libassimp 5.2 is built with its internal checks on, and a failed one (ai_assert) calls
// Assimp::aiAssertViolation, which prints and aborts the process: a malformed file
// (assimp-testmodels' invalid/OutOfMemory.off fails one in the triangulation) would crash the capture.
// The library exports that function and calls it through the dynamic linker, so this definition
// replaces it: it throws instead, Importer::ReadFile's exception region catches the exception and
// returns no scene, and load_mesh reports the file as not loading. Process-wide, deliberately.
namespace Assimp {
void aiAssertViolation(const char* failed, const char* file, int line) {
  throw std::runtime_error(fmt::format("assimp's internal check failed: {} ({}:{})", failed, file, line));
}
}  // namespace Assimp

namespace nbsim::capture {

namespace {

// Reads the file in this process (the child's side of load_mesh).
mesh::TriMesh load_here(const std::string& path) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
  if (scene == nullptr || scene->mRootNode == nullptr)
    throw InputError(fmt::format("mesh file '{}' does not load: {}", path, importer.GetErrorString()));
  mesh::TriMesh out;
  append_node(*scene, *scene->mRootNode, aiMatrix4x4(), out);
  if (out.triangles.empty())
    throw InputError(fmt::format("mesh file '{}' has no triangles ({} meshes, only points or lines, or none)", path,
                                 scene->mNumMeshes));
  return out;
}

// The child's answer on the pipe: a tag byte, then for 'M' the vertex and triangle counts (u64 each)
// and their data as laid out in memory, for 'E' the message's bytes.
bool write_all(int fd, const void* data, std::size_t n) {
  const auto* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    p += w, n -= static_cast<std::size_t>(w);
  }
  return true;
}

[[noreturn]] void child_main(int fd, const std::string& path, const MeshLoadLimits& limits) {
#if !defined(__SANITIZE_ADDRESS__)
  if (limits.address_space_bytes > 0) {  // a memory bomb fails an allocation instead of taking the machine
    const rlimit r{static_cast<rlim_t>(limits.address_space_bytes), static_cast<rlim_t>(limits.address_space_bytes)};
    ::setrlimit(RLIMIT_AS, &r);
  }
#else
  (void)limits;  // ASan reserves terabytes of shadow address space: an address-space limit would stop it
#endif
  bool ok = false;
  try {
    const mesh::TriMesh m = load_here(path);
    const std::uint64_t counts[2] = {m.vertices.size(), m.triangles.size()};
    ok = write_all(fd, "M", 1) && write_all(fd, counts, sizeof counts) &&
         write_all(fd, m.vertices.data(), m.vertices.size() * sizeof(mesh::Vec3f)) &&
         write_all(fd, m.triangles.data(), m.triangles.size() * sizeof(mesh::Tri));
  } catch (const std::bad_alloc&) {
    const std::string e = fmt::format("mesh file '{}' does not load: it needs more than the {} GiB an import may use", path,
                                      limits.address_space_bytes >> 30);
    ok = write_all(fd, "E", 1) && write_all(fd, e.data(), e.size());
  } catch (const std::exception& ex) {
    const std::string e = dynamic_cast<const InputError*>(&ex) ? ex.what() : fmt::format("mesh file '{}' does not load: {}", path, ex.what());
    ok = write_all(fd, "E", 1) && write_all(fd, e.data(), e.size());
  }
  ::_exit(ok ? 0 : 3);  // no atexit handlers, no destructors of the parent's state
}

}  // namespace

mesh::TriMesh load_mesh(const std::string& path, const MeshLoadLimits& limits) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(fmt::format("mesh file '{}' does not load: no such file", path));
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(fmt::format("cannot make a pipe to read '{}': {}", path, std::strerror(errno)));
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]), ::close(fds[1]);
    throw std::runtime_error(fmt::format("cannot fork to read '{}': {}", path, std::strerror(errno)));
  }
  if (pid == 0) {
    ::close(fds[0]);
    child_main(fds[1], path, limits);
  }
  ::close(fds[1]);
  std::string got;
  bool timed_out = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(limits.seconds);
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) {
      timed_out = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int r = ::poll(&p, 1, static_cast<int>(std::min<long long>(left, 1000)));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) continue;
    char buf[1 << 16];
    const ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // EOF: the child is done (or died)
    got.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  if (timed_out) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (timed_out)
    throw InputError(fmt::format("mesh file '{}' does not load: assimp did not finish reading it within {} s", path, limits.seconds));
  if (WIFSIGNALED(status))
    throw InputError(fmt::format("mesh file '{}' does not load: assimp crashed reading it (signal {}, {})", path, WTERMSIG(status),
                                 ::strsignal(WTERMSIG(status))));
  if (!got.empty() && got[0] == 'E') throw InputError(got.substr(1));
  std::uint64_t counts[2] = {0, 0};
  if (got.size() < 1 + sizeof counts || got[0] != 'M')
    // (A sanitizer build's handler turns a crash into exit status 1.)
    throw InputError(fmt::format("mesh file '{}' does not load: assimp crashed or stopped reading it (its process exited with "
                                 "status {} without an answer)",
                                 path, WIFEXITED(status) ? WEXITSTATUS(status) : -1));
  std::memcpy(counts, got.data() + 1, sizeof counts);
  const std::uint64_t need = 1 + sizeof counts + counts[0] * sizeof(mesh::Vec3f) + counts[1] * sizeof(mesh::Tri);
  if (counts[0] > got.size() || counts[1] > got.size() || got.size() != need)
    throw InputError(fmt::format("mesh file '{}' does not load: the reader's answer is cut short (exit status {})", path,
                                 WIFEXITED(status) ? WEXITSTATUS(status) : -1));
  mesh::TriMesh out;
  out.vertices.resize(counts[0]);
  out.triangles.resize(counts[1]);
  const char* at = got.data() + 1 + sizeof counts;
  std::memcpy(out.vertices.data(), at, counts[0] * sizeof(mesh::Vec3f));
  std::memcpy(out.triangles.data(), at + counts[0] * sizeof(mesh::Vec3f), counts[1] * sizeof(mesh::Tri));
  return out;
}

}  // namespace nbsim::capture

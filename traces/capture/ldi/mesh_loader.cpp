// Mesh files through libassimp; see mesh_loader.h.
#include "traces/capture/ldi/mesh_loader.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include <filesystem>
#include <stdexcept>
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

mesh::TriMesh load_mesh(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(fmt::format("mesh file '{}' does not load: no such file", path));
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

}  // namespace nbsim::capture

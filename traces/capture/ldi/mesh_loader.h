// Real meshes for the layered-depth-image captures (docs/ldi_meshes.md), renderer side: a model
// file read with libassimp (PLY, OBJ, STL, OFF and the other formats assimp knows) into the model's
// TriMesh (model/mesh/mesh.h). Nothing here repairs a mesh: the capture runs check_mesh on the
// result and refuses or reports a mesh that is not closed, instead of silently peeling it.
#pragma once

#include <cstdint>
#include <string>

#include "model/mesh/mesh.h"

namespace nbsim::capture {

// Reads every mesh of the file's scene, each instance placed by its node's accumulated transform
// (a mirroring transform, negative determinant, reverses the instance's triangles so that they stay
// counter-clockwise outward), merged into one TriMesh. Post-processing is aiProcess_Triangulate |
// aiProcess_JoinIdenticalVertices only: polygons are fanned into triangles and identical vertices
// shared, nothing else (no hole filling, no normal fixing, no degenerate removal). Point and line
// primitives are left out. Throws InputError naming the file and the reason when the file does not
// load (missing, unreadable, unknown or malformed format) or holds no triangle.
//
// assimp runs in a child process (fork): some of its readers crash on malformed input (Debian's
// 5.2 segfaults on assimp-testmodels' RAW files) or loop, and a bad file must never take the
// capture down. The child sends the mesh back through a pipe; a child that crashes, runs past
// `limits.seconds` (it is killed) or exceeds `limits.address_space_bytes` (RLIMIT_AS; not applied
// in AddressSanitizer builds) is reported as an InputError naming the file and what happened.
struct MeshLoadLimits {
  double seconds = 60.0;                                       // tunable
  std::uint64_t address_space_bytes = std::uint64_t{8} << 30;  // tunable; 0: no limit
};
mesh::TriMesh load_mesh(const std::string& path, const MeshLoadLimits& limits = {});

}  // namespace nbsim::capture

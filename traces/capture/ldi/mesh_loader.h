// Real meshes for the layered-depth-image captures (issue 14), renderer side: a model file read with
// libassimp (PLY, OBJ, STL, OFF and the other formats assimp knows) into the model's TriMesh
// (model/mesh/mesh.h). Nothing here repairs a mesh: the capture runs check_mesh on the result and
// refuses or reports a mesh that is not closed, instead of silently peeling it.
#pragma once

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
mesh::TriMesh load_mesh(const std::string& path);

}  // namespace nbsim::capture

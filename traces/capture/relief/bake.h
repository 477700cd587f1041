// Heightfields baked from a mesh on GL (--field-mesh; docs/relief.md): the mesh,
// fitted into the unit cube (model/mesh/mesh.h normalize_to_unit_cube, margin 0) and shrunk in x and
// y to leave a one-texel ring at height 0, is rendered orthographically from above into an N x N
// DEPTH_COMPONENT32F target (clip control ZERO_TO_ONE, window depth = 1 - height, LESS against 1.0,
// no culling); a texel's height is 1 - its depth where a fragment landed, 0 elsewhere: the upper
// envelope of the mesh sampled at texel centres, as GL's rasterizer samples it.
#pragma once

#include <string>

#include "model/mesh/mesh.h"
#include "model/relief/heightfield.h"

namespace nbsim::capture {

// With apex > 0 the same mesh, placed in the world box [0, 1]^2 x [0, box_height] as above, is
// baked in the reverse-perspective frustum of view.h (frustum_map): each vertex through the
// projective map onto texel space, the height its texel-space z; triangles stay triangles under a
// projective map, so GL's rasterization of the mapped triangles is the mesh's upper envelope along
// the frustum's rays through its apex.
// The GL context must be current. Throws InputError for an unusable mesh or size.
relief::Heightfield bake_heightfield(mesh::TriMesh m, int size, double box_height = 1.0, double apex = 0.0);

}  // namespace nbsim::capture

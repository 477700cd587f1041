// Depth peeling of a closed shape into a layered depth image on GL (Trapp & Doellner), the first GL
// pass of the LDI technique: the shape in the unit cube, an orthographic view along an OrthoFrame
// (model/mesh/crossings.h), one R32F layer per peel pass in a GL_TEXTURE_2D_ARRAY, read back into
// an ldi::Ldi (model/ldi/ldi.h: linear depth in [0, 1], texel (x, y) y up, +inf where a texel has
// no more layers).
//
// The view mapping, shared with the exact reference (CrossingReference) so both look along the same
// lines: in the frame's view-plane coordinates u = dot(p, right), v = dot(p, up) and depth
// t = dot(p, direction), the unit cube's eight corners span [u0, u1] x [v0, v1] x [t0, t1]; that
// rectangle maps onto the W x H viewport exactly (stretched when the aspects differ), texel (x, y)
// is the line u = u0 + (x + 0.5) (u1 - u0) / W, v = v0 + (y + 0.5) (v1 - v0) / H, and the linear
// depth is (t - t0) / (t1 - t0). The capture projects the vertices in double and rounds once to
// float; GL then snaps them to its 1/256-pixel grid.
//
// Depth on GL (so that a model can replay the passes bit-exactly): during the peel the clip
// control is (LOWER_LEFT, ZERO_TO_ONE) and the vertex stage emits gl_Position = (ndc x, ndc y,
// linear depth, 1), so GL's window depth IS the linear depth; the layer written is gl_FragCoord.z
// (no gl_FragDepth write), the depth buffer (DEPTH_COMPONENT32F, cleared to 1.0 each pass) is
// tested with LEQUAL, and the strict test against the previous layer uses the same gl_FragCoord.z.
// The previous clip control is restored afterwards.
//
// Duplicate and coplanar faces: the test against the previous layer is strict (depth > previous),
// so surfaces at equal float depth at a texel collapse into ONE layer, where the exact reference
// lists one crossing per face. A shape with a duplicated face therefore shows an odd layer count
// there (the "coplanar and duplicate faces" hard case); the peel keeps the collapsed count.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "model/ldi/ldi.h"
#include "model/mesh/crossings.h"
#include "model/mesh/mesh.h"

namespace nbsim::capture {

// The orthographic mapping described above (all in double).
struct OrthoMapping {
  mesh::OrthoFrame frame;
  int width = 1, height = 1;
  double u0 = 0, u1 = 1, v0 = 0, v1 = 1, t0 = 0, t1 = 1;

  // Fits the unit cube's projection onto a width x height viewport. Throws InputError for sizes
  // outside [1, ldi::kMaxSideTexels].
  static OrthoMapping fit_unit_cube(const mesh::OrthoFrame& frame, int width, int height);
  // A point on texel (x, y)'s centre line (at depth t0), for CrossingReference queries.
  mesh::Vec3d texel_line_point(int x, int y) const;
  // Linear depth in [0, 1] of a depth t = dot(p, direction).
  double linear_depth(double t) const { return (t - t0) / (t1 - t0); }
  // (NDC x, NDC y, linear depth) of a point, in double.
  std::array<double, 3> project(const mesh::Vec3d& p) const;
};

struct PeelConfig {
  int width_px = 64;
  int height_px = 64;
  // Most layers the peel stores (tunable; at most ldi::kMaxLayers). A shape needing more is refused
  // with an InputError naming this limit.
  int max_layers = 64;
  // Read the depth attachment back after every pass that wrote a layer and compare it with the
  // layer (PeelResult::depth_buffer_mismatches): the check that gl_FragCoord.z is the depth-tested
  // z. For tests (a read-back per pass).
  bool verify_depth_buffer = false;
  // Keep GL's layered texture for further GL passes (crop, compression): PeelResult::gl_layers.
  bool keep_gl_layers = false;
};

// One peel pass's GL counters.
struct PeelPass {
  std::uint64_t fragments = 0;       // rasterized fragments (SSBO atomic, before discard and depth test)
  std::uint64_t samples_passed = 0;  // GL_SAMPLES_PASSED: passed the previous-layer test and the depth test
};

struct PeelResult {
  ldi::Ldi ldi;
  // Every pass run, including the last one that wrote nothing (which ends the peel); so
  // passes.size() == ldi.layer_count() + 1.
  std::vector<PeelPass> passes;
  // With verify_depth_buffer: texels (over all passes that wrote a layer) where the layer's bits and
  // the depth buffer's differ, among those where the layer is valid; and how many were compared.
  std::uint64_t depth_buffer_mismatches = 0, depth_buffer_checked = 0;
  // With keep_gl_layers: the GL_TEXTURE_2D_ARRAY (R32F, width x height x max_layers, +inf past the
  // layers) holding the LDI; the caller owns it (glDeleteTextures). 0 otherwise.
  std::uint32_t gl_layers = 0;
};

class DrawRecorder;

// Peels the mesh (vertices in the unit cube; not checked for closedness here: see mesh.h's
// require_closed) on the current GL context. No face culling. With a recorder, every pass (the last,
// empty one included) is recorded as a draw of role LdiPeel with its clip positions (transform
// feedback) and counters; the passes' `fragments` are then 0 here and come with the records
// (DrawRecorder::collect), while `samples_passed` is filled either way. Throws InputError for a bad config or
// when more than max_layers layers exist (naming max_layers), std::runtime_error for a GL failure.
PeelResult peel_ldi(const mesh::TriMesh& m, const mesh::OrthoFrame& frame, const PeelConfig& config,
                    DrawRecorder* recorder = nullptr);

}  // namespace nbsim::capture

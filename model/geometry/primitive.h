// Window-space triangles and points: the data the geometry stage (model/geometry) hands to
// triangle and point setup (model/raster), with the face state setup needs to orient and cull
// triangles.
// Conventions (model/common/depth.h): x, y in pixels with y up and pixel centres at +0.5, z is GL
// window depth in [0, 1].
#pragma once

#include <array>
#include <cstdint>

namespace nbsim::geometry {

// One vertex after clipping, perspective divide and viewport transform.
struct WindowVertex {
  float x = 0.0f;      // pixels; pixel i covers [i, i + 1) and has its centre at i + 0.5
  float y = 0.0f;      // pixels, y up
  float z = 0.0f;      // window depth
  float inv_w = 0.0f;  // 1 / w_clip (for perspective-correct attributes; depth does not use it)
};

// One triangle in the order Mesa's draw module emits it (for a clipped polygon: a fan whose
// provoking vertex, the polygon's first, comes last).
struct WindowTriangle {
  std::array<WindowVertex, 3> v{};
};

// One point sprite that passed clipping: its vertex and gl_PointSize as the vertex shader wrote it
// (finite; point setup clamps it to llvmpipe's range, model/raster/point_setup.h).
struct WindowPoint {
  WindowVertex v;
  float size = 1.0f;  // pixels
};

// Which faces are dropped. Fixed values, GL's order, equal to scene::CullFace of trace files.
enum class CullFace : std::uint8_t { None = 0, Back = 1, Front = 2, FrontAndBack = 3 };

// Facing as GL defines it (glFrontFace, glCullFace) for a y-up render target, i.e. an FBO:
// front_ccw means counter-clockwise in window coordinates with y up is the front face.
struct FaceState {
  CullFace cull = CullFace::Back;
  bool front_ccw = true;
};

}  // namespace nbsim::geometry

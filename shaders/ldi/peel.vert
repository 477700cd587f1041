// Depth peeling of a layered depth image (traces/capture/ldi/peel.cpp): the vertex stage. The
// capture has already projected each vertex in double precision (OrthoMapping): xy in NDC and its
// linear depth in [0, 1] along the view direction, rounded to float once. The depth goes on as a
// noperspective varying (w = 1, so llvmpipe interpolates the plane a0 + x dadx + y dady).
#version 450 core
layout(location = 0) in vec3 ndc_xy_depth;
noperspective out float linear_depth;
void main() {
  linear_depth = ndc_xy_depth.z;
  gl_Position = vec4(ndc_xy_depth.xy, 2.0 * ndc_xy_depth.z - 1.0, 1.0);
}

// Depth peeling of a layered depth image (traces/capture/ldi/peel.cpp): the vertex stage. The
// capture has already projected each vertex in double precision (OrthoMapping): xy in NDC and its
// linear depth in [0, 1] along the view direction, rounded to float once. With clip control
// ZERO_TO_ONE during the peel and w = 1, GL's window depth is that linear depth itself, so the
// rasterizer's interpolated gl_FragCoord.z is both the layer value and the depth-tested value.
#version 450 core
layout(location = 0) in vec3 ndc_xy_depth;
void main() { gl_Position = vec4(ndc_xy_depth, 1.0); }

// The relief box: its corners in texel space ([0, N]^2 x [0, 1], model/relief/heightfield.h)
// through the draw's texel-to-clip matrix. Nothing is interpolated: the fragment shader rebuilds
// its ray from gl_FragCoord (relief.frag).
#version 450 core
layout(location = 0) in vec3 position;
uniform mat4 texel_to_clip;
void main() { gl_Position = texel_to_clip * vec4(position, 1.0); }

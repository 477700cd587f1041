// The litmap pass (shadows technique): scene geometry seen from the spot light. The fragment stage
// rebuilds each fragment's position from gl_FragCoord, so nothing is passed on.
#version 450 core
layout(location = 0) in vec3 position;
uniform mat4 light_view_proj;
void main() { gl_Position = light_view_proj * vec4(position, 1.0); }

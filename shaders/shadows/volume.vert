// Shadow-volume geometry (shadows technique): homogeneous world positions (w = 0 for the points at
// infinity of an infinite volume) to the observer's clip space. gl_Position is captured with
// transform feedback, so the trace holds the volume as GL rasterized it.
#version 450 core
layout(location = 0) in vec4 position;
uniform mat4 view_proj;
void main() { gl_Position = view_proj * position; }

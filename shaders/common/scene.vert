// Scene geometry and bounding boxes: world-space positions to clip space. gl_Position is captured
// with transform feedback, so the trace holds the clip coordinates exactly as GL computed them.
#version 450 core
layout(location = 0) in vec3 position;
uniform mat4 view_proj;
void main() { gl_Position = view_proj * vec4(position, 1.0); }

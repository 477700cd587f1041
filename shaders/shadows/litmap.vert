// The litmap pass (shadows technique): scene geometry seen from the spot light. The world position
// goes on to the fragment stage, which reprojects it into the observer's view.
#version 450 core
layout(location = 0) in vec3 position;
uniform mat4 light_view_proj;
out vec3 world;
void main() {
  world = position;
  gl_Position = light_view_proj * vec4(position, 1.0);
}

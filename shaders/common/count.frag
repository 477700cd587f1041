// Counts every rasterized fragment of a draw (no early fragment tests, so the count is taken
// before the depth test: one depth test per fragment) and writes the object id for the ID buffer.
#version 450 core
layout(std430, binding = 0) buffer Fragments { uint fragments[]; };
uniform uint draw_slot;
uniform uint object_id;
layout(location = 0) out uint id;
void main() {
  atomicAdd(fragments[draw_slot], 1u);
  id = object_id + 1u;
}

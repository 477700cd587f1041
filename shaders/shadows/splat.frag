// The receiver splat's fragments (see splat.vert): each is counted (no early fragment tests, so
// before the depth test); the depth is the point's, written with the litmap's depth func.
#version 450 core
layout(std430, binding = 0) buffer Fragments { uint fragments[]; };
uniform uint draw_slot;
void main() { atomicAdd(fragments[draw_slot], 1u); }

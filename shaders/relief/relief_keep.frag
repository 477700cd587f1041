// The relief box's conservative depth (model/relief/box_depth.h, "box"): the box drawn again right
// after its walk (relief.frag, which left every fragment's record in `results`), depth writes on, a
// fragment whose ray missed discarded. No memory write and no gl_FragDepth, so llvmpipe tests depth
// early and writes it late, for the hits only: the depth the paper's single draw leaves.
#version 450 core
layout(std430, binding = 1) readonly buffer Results { uint results[]; };
uniform int viewport_width;
void main() {
  uint pixel = uint(gl_FragCoord.y) * uint(viewport_width) + uint(gl_FragCoord.x);
  if (results[6u * pixel + 1u] != 1u) discard;
}

// Cropping (traces/capture/ldi/build.cpp): the bounding rectangle of the texels whose layer 0 is
// valid (finite; +inf marks "no layer"), by atomicMin/atomicMax over the LDI's texels.
#version 450 core
layout(local_size_x = 8, local_size_y = 8) in;
uniform sampler2DArray layers;
uniform ivec2 size;
layout(std430, binding = 0) buffer Bounds { int lo_x, lo_y, hi_x, hi_y; };
void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= size.x || p.y >= size.y) return;
  if (isinf(texelFetch(layers, ivec3(p, 0), 0).r)) return;
  atomicMin(lo_x, p.x);
  atomicMin(lo_y, p.y);
  atomicMax(hi_x, p.x);
  atomicMax(hi_y, p.y);
}

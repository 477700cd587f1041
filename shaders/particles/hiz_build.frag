// One level of a Hi-Z max (min under reversed Z) mip pyramid: level k has ceil(W / 2^k) x
// ceil(H / 2^k) texels, texel (x, y) the farthest of level k-1's (2x, 2y) .. (2x+1, 2y+1) that lie
// inside level k-1 (so it covers exactly the pixels [x 2^k, (x+1) 2^k) x [y 2^k, (y+1) 2^k) of the
// image). Level 0 is a copy of the depth buffer. Level k-1 is read from the corner of layer k-1.
#version 450 core
uniform sampler2DArray levels;
uniform sampler2D depth;
uniform int source_level;
uniform ivec2 source_size;  // level k-1's texels
uniform bool source_is_depth;
layout(std430, binding = 0) buffer Fragments { uint fragments[]; };
uniform uint draw_slot;
layout(location = 0) out float farthest;

float fetch(ivec2 p) { return texelFetch(levels, ivec3(p, source_level), 0).r; }

void main() {
  atomicAdd(fragments[draw_slot], 1u);
  const ivec2 p = ivec2(gl_FragCoord.xy);
  if (source_is_depth) {
    farthest = texelFetch(depth, p, 0).r;
    return;
  }
  const ivec2 q = 2 * p;
  const bool right = q.x + 1 < source_size.x, up = q.y + 1 < source_size.y;
  float v = fetch(q);
  if (right) v = FAR(v, fetch(q + ivec2(1, 0)));
  if (up) v = FAR(v, fetch(q + ivec2(0, 1)));
  if (right && up) v = FAR(v, fetch(q + ivec2(1, 1)));
  farthest = v;
}

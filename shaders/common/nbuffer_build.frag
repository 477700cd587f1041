// N-buffer construction (Décoret 2005, Fig. 2): level i+1 at (x, y) is the farthest of level i at
// (x, y), (x+s, y), (x, y+s), (x+s, y+s) with s = 2^i; texels outside the image are skipped.
// FAR(a, b) is max for depth func LESS and min for reversed Z / min-litmaps (defined by the host).
// Level 0 is a copy of the depth buffer (source_is_depth).
#version 450 core
uniform sampler2DArray levels;   // the N-buffer, one layer per level (R32F)
uniform sampler2D depth;         // the depth buffer (DEPTH_COMPONENT32F, no compare mode)
uniform int source_level;        // level i that is read
uniform int step;                // s = 2^i
uniform bool source_is_depth;
layout(std430, binding = 0) buffer Fragments { uint fragments[]; };
uniform uint draw_slot;
layout(location = 0) out float farthest;

float fetch(ivec2 p) {
  return source_is_depth ? texelFetch(depth, p, 0).r : texelFetch(levels, ivec3(p, source_level), 0).r;
}

void main() {
  atomicAdd(fragments[draw_slot], 1u);
  const ivec2 size = textureSize(depth, 0);
  const ivec2 p = ivec2(gl_FragCoord.xy);
  float v = fetch(p);
  if (!source_is_depth) {
    const bool right = p.x + step < size.x, up = p.y + step < size.y;
    if (right) v = FAR(v, fetch(p + ivec2(step, 0)));
    if (up) v = FAR(v, fetch(p + ivec2(0, step)));
    if (right && up) v = FAR(v, fetch(p + ivec2(step, step)));
  }
  farthest = v;
}

// N-buffer query (Décoret 2005, section 3.2): the farthest depth of a screen rectangle from at most
// four texels of one level, as model/nbuffer/covering.h defines the covering. An object is hidden
// when its nearest depth is strictly farther than that (FARTHER_THAN defined by the host).
#version 450 core
layout(local_size_x = 64) in;
struct Query { ivec4 rect; float nearest; uint always_visible; uint pad0, pad1; };
layout(std430, binding = 1) readonly buffer Queries { Query queries[]; };
layout(std430, binding = 2) writeonly buffer Results { uint visible[]; };
uniform sampler2DArray levels;
uniform int top_level;
uniform uint count;

int floor_log2(int v) { return findMSB(v); }

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  const Query q = queries[i];
  const int w = q.rect.z, h = q.rect.w;
  const int n = min(floor_log2(max(w, h)), top_level);
  const int s = 1 << n;
  const int x1 = w > s ? q.rect.x + w - s : q.rect.x;
  const int y1 = h > s ? q.rect.y + h - s : q.rect.y;
  float f = texelFetch(levels, ivec3(q.rect.x, q.rect.y, n), 0).r;
  f = FAR(f, texelFetch(levels, ivec3(x1, q.rect.y, n), 0).r);
  f = FAR(f, texelFetch(levels, ivec3(q.rect.x, y1, n), 0).r);
  f = FAR(f, texelFetch(levels, ivec3(x1, y1, n), 0).r);
  visible[i] = (q.always_visible != 0u || !FARTHER_THAN(q.nearest, f)) ? 1u : 0u;
}

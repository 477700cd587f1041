// N-buffer query (Décoret 2005, section 2): the farthest depth of a screen rectangle from at most
// four texels of one level, placed by the covering the host inserts (covering.glsl, the twin of
// model/nbuffer/covering.h). An object is hidden when its nearest depth is strictly farther than
// that (FARTHER_THAN defined by the host).
#version 450 core
layout(local_size_x = 64) in;
struct Query { ivec4 rect; float nearest; uint always_visible; uint pad0, pad1; };
layout(std430, binding = 1) readonly buffer Queries { Query queries[]; };
layout(std430, binding = 2) writeonly buffer Results { uint visible[]; };
uniform sampler2DArray levels;
uniform int top_level;
uniform uint count;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  const Query q = queries[i];
  int level;
  ivec2 squares[4];
  const int n = nb_cover(q.rect, top_level, level, squares);
  float f = texelFetch(levels, ivec3(squares[0], level), 0).r;
  for (int k = 1; k < n; ++k) f = FAR(f, texelFetch(levels, ivec3(squares[k], level), 0).r);
  visible[i] = (q.always_visible != 0u || !FARTHER_THAN(q.nearest, f)) ? 1u : 0u;
}

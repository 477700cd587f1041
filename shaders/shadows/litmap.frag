// The litmaps of the N-buffer paper (3.3): the scene seen from the light, keeping only what the
// observer sees. Each fragment is reprojected into the observer's view and discarded when it lies
// outside it or behind the farthest observer depth of the 3x3 pixels around it (by more than a
// tolerance): the neighbourhood and the tolerance keep the test conservative at depth
// discontinuities and on slanted surfaces (a hidden surface kept only widens [z_min, z_max]; a
// visible one dropped would lose a shadow). Dropped fragments are discarded, never written at
// depth 2.0: GL 4.5 clamps a written depth to [0, 1], so 2.0 would land in the max litmap as 1.0.
// Rasterized fragments are counted (no early fragment tests). Depth func LEQUAL (min litmap, clear
// 1) or GEQUAL (max litmap, clear 0) is the host's.
#version 450 core
layout(std430, binding = 0) buffer Fragments { uint fragments[]; };
uniform uint draw_slot;
uniform sampler2D observer_depth;  // the observer's depth (window depth, LESS, [-1, 1] clip z)
uniform mat4 view_proj;            // the observer's
uniform vec2 near_far;             // the observer's near and far planes, metres
uniform float tolerance_rel;       // relative distance tolerance (tunable; see shadows.cpp)
uniform float tolerance_m;         // absolute distance tolerance, metres
in vec3 world;

// Window depth -> distance along the view axis, metres.
float view_distance(float d) {
  const float n = near_far.x, f = near_far.y;
  return 2.0 * n * f / (f + n - (2.0 * d - 1.0) * (f - n));
}

void main() {
  atomicAdd(fragments[draw_slot], 1u);
  const vec4 c = view_proj * vec4(world, 1.0);
  if (c.w <= 0.0) discard;
  const vec3 ndc = c.xyz / c.w;
  if (any(greaterThan(abs(ndc), vec3(1.0)))) discard;  // outside the observer's frustum
  const ivec2 size = textureSize(observer_depth, 0);
  const ivec2 p = clamp(ivec2((ndc.xy * 0.5 + 0.5) * vec2(size)), ivec2(0), size - 1);
  float farthest = 0.0;
  for (int j = -1; j <= 1; ++j)
    for (int i = -1; i <= 1; ++i) farthest = max(farthest, texelFetch(observer_depth, clamp(p + ivec2(i, j), ivec2(0), size - 1), 0).r);
  const float seen = view_distance(farthest);
  if (view_distance(ndc.z * 0.5 + 0.5) > seen * (1.0 + tolerance_rel) + tolerance_m) discard;
}

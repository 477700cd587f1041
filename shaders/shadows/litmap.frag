// The litmaps of the N-buffer paper (3.3): the scene seen from the light, keeping only what the
// observer sees. Each fragment is reprojected into the observer's view from its gl_FragCoord (the
// litmap pixel centre and depth) and discarded when it lies outside that view or behind the
// farthest observer depth of the 3x3 pixels around it (by more than a tolerance): the neighbourhood
// and the tolerance keep the test conservative at depth discontinuities and on slanted surfaces (a
// hidden surface kept only widens [z_min, z_max]; a visible one dropped would lose a shadow).
// The twin of model/shadows/litmap.cpp (LitmapReprojection), expression for expression: every
// float is `precise`, so no product and sum are fused and the order is the written one; change
// one, change the other. Dropped fragments are discarded, never written at depth 2.0: GL 4.5 clamps
// a written depth to [0, 1], so 2.0 would land in the max litmap as 1.0. Rasterized fragments are
// counted (no early fragment tests). Depth func LEQUAL (min litmap, clear 1) or GEQUAL (max
// litmap, clear 0) is the host's.
#version 450 core
layout(std430, binding = 0) buffer Fragments { uint fragments[]; };
uniform uint draw_slot;
uniform sampler2D observer_depth;  // the observer's depth (window depth, LESS, [-1, 1] clip z)
// Observer clip = rows * (gl_FragCoord.xyz, 1): the observer's view_proj times the inverse of the
// light's times the litmap's window-to-NDC map (litmap.cpp reprojection_rows).
uniform vec4 reproject_x, reproject_y, reproject_z, reproject_w;
uniform vec2 near_far;             // the observer's near and far planes, metres
uniform float tolerance_rel;       // relative distance tolerance (the capture's --reproject-tolerance)
uniform float tolerance_m;         // absolute distance tolerance, metres

// Window depth -> distance along the view axis, metres.
float view_distance(float d) {
  precise float n = near_far.x, f = near_far.y;
  precise float num = (2.0 * n) * f;
  precise float den = (f + n) - ((2.0 * d - 1.0) * (f - n));
  precise float r = num / den;
  return r;
}

float row(vec4 m, float x, float y, float z) {
  precise float r = ((m.x * x + m.y * y) + m.z * z) + m.w;
  return r;
}

void main() {
  atomicAdd(fragments[draw_slot], 1u);
  precise float fx = gl_FragCoord.x, fy = gl_FragCoord.y, fz = gl_FragCoord.z;
  precise vec4 c = vec4(row(reproject_x, fx, fy, fz), row(reproject_y, fx, fy, fz), row(reproject_z, fx, fy, fz),
                        row(reproject_w, fx, fy, fz));
  if (!(c.w > 0.0)) discard;
  precise float nx = c.x / c.w, ny = c.y / c.w, nz = c.z / c.w;
  if (abs(nx) > 1.0 || abs(ny) > 1.0 || abs(nz) > 1.0) discard;  // outside the observer's frustum
  const ivec2 size = textureSize(observer_depth, 0);
  precise float sx = (nx * 0.5 + 0.5) * float(size.x), sy = (ny * 0.5 + 0.5) * float(size.y);
  const ivec2 p = clamp(ivec2(int(sx), int(sy)), ivec2(0), size - 1);
  float farthest = 0.0;
  for (int j = -1; j <= 1; ++j)
    for (int i = -1; i <= 1; ++i) farthest = max(farthest, texelFetch(observer_depth, clamp(p + ivec2(i, j), ivec2(0), size - 1), 0).r);
  precise float seen = view_distance(farthest);
  precise float slack = 1.0 + tolerance_rel;
  precise float limit = seen * slack + tolerance_m;
  precise float here = nz * 0.5 + 0.5;
  if (view_distance(here) > limit) discard;
}

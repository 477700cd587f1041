// Point-sprite particles (N-buffer paper, 3.2 and 4.3): a world position per vertex to a sprite of
// gl_PointSize pixels whose fragments all lie at the vertex's window depth, culled here, in the
// vertex stage, by moving the vertex outside the clip volume. The host defines one mode:
//   MODE_NONE    no test;
//   MODE_CENTER  one lookup of the scene depth at the centre pixel (the baseline that pops);
//   MODE_NB      the max (min under reversed Z) N-buffer: the sprite's pixel rectangle (clipped to the
//                viewport) covered by at most four squares of one level (nb_cover_sprite of the
//                covering library the host inserts: one square when the rectangle is a
//                power-of-two square), kept untested when the whole sprite needs a level above the
//                ones built;
//   MODE_HIZ     the Hi-Z mip pyramid: the lowest level where the rectangle spans at most 2x2 texels.
// HIDDEN(d, f) says a sprite at depth d is behind a farthest depth f (host: LESS or reversed Z, with
// a margin). REFERENCE: the reference pass (no test, no decisions written, the particle's id out).
#version 450 core
layout(location = 0) in vec4 particle;  // world x, y, z; w unused
uniform mat4 view_proj;
uniform ivec2 viewport;     // pixels
uniform float fixed_size;   // > 0: every sprite this side; 0: attenuated
uniform float atten_px_m;   // attenuated side = atten_px_m / clip w, rounded, in [min_size, max_size]
uniform float min_size, max_size;
uniform float margin;
uniform int top_level;      // highest level built (MODE_NB, MODE_HIZ)
uniform sampler2D depth;         // MODE_CENTER: the scene depth (a copy)
uniform sampler2DArray levels;   // MODE_NB: N-buffer, MODE_HIZ: Hi-Z (level k in the corner of layer k)
struct Decision { vec4 window; uint culled; uint lookups; uint pad0; uint pad1; };
layout(std430, binding = 3) writeonly buffer Decisions { Decision decisions[]; };
flat out uint particle_id;

// Near a pixel-centre tie the rasterizer's snapping may start the sprite one pixel lower: widen.
const float kTie = 1.0 / 64.0;

void main() {
  const vec4 clip = view_proj * vec4(particle.xyz, 1.0);
  const float size = fixed_size > 0.0 ? fixed_size : clamp(round(atten_px_m / max(clip.w, 1e-3)), min_size, max_size);
  gl_PointSize = size;
  gl_Position = clip;
  particle_id = uint(gl_VertexID);
#ifndef REFERENCE
  const vec3 ndc = clip.xyz / clip.w;
  const vec2 win = (ndc.xy * 0.5 + 0.5) * vec2(viewport);
#ifdef ZERO_TO_ONE
  const float d = ndc.z;
  const bool inside_z = clip.w > 0.0 && clip.z >= 0.0 && clip.z <= clip.w;
#else
  const float d = ndc.z * 0.5 + 0.5;
  const bool inside_z = clip.w > 0.0 && clip.z >= -clip.w && clip.z <= clip.w;
#endif
  bool culled = false;
  uint lookups = 0u;
  // The pixels whose centres the sprite covers: [x0, x0 + w) x [y0, y0 + h), clipped to the viewport.
  const vec2 a = win - 0.5 - 0.5 * size;
  const vec2 nearest = round(a);
  const bvec2 tie = lessThan(abs(a - nearest), vec2(kTie));
  const ivec2 lo = ivec2(mix(ceil(a), nearest, vec2(tie)));
  const ivec2 hi = lo + ivec2(size) + ivec2(tie);  // exclusive
  const ivec2 c0 = max(lo, ivec2(0)), c1 = min(hi, viewport);
  const bool on_screen = inside_z && all(lessThan(c0, c1));
#if defined(MODE_CENTER)
  const ivec2 centre = ivec2(floor(win));
  if (on_screen && all(greaterThanEqual(centre, ivec2(0))) && all(lessThan(centre, viewport))) {
    lookups = 1u;
    culled = HIDDEN(d, texelFetch(depth, centre, 0).r);
  }
#elif defined(MODE_NB)
  if (on_screen) {
    if (findMSB(max(hi.x - lo.x, hi.y - lo.y)) <= top_level) {
      int level;
      ivec2 squares[4];
      const int n = nb_cover_sprite(ivec4(c0, c1 - c0), top_level, level, squares);
      float f = texelFetch(levels, ivec3(squares[0], level), 0).r;
      for (int k = 1; k < n; ++k) f = FAR(f, texelFetch(levels, ivec3(squares[k], level), 0).r);
      lookups = uint(n);
      culled = HIDDEN(d, f);
    }
  }
#elif defined(MODE_HIZ)
  if (on_screen) {
    int k = 0;
    while (k <= top_level && (((c1.x - 1) >> k) - (c0.x >> k) > 1 || ((c1.y - 1) >> k) - (c0.y >> k) > 1)) ++k;
    if (k <= top_level) {
      const ivec2 t0 = c0 >> k, t1 = (c1 - 1) >> k;
      float f = texelFetch(levels, ivec3(t0, k), 0).r;
      lookups = 1u;
      if (t1.x != t0.x) { f = FAR(f, texelFetch(levels, ivec3(t1.x, t0.y, k), 0).r); lookups += 1u; }
      if (t1.y != t0.y) { f = FAR(f, texelFetch(levels, ivec3(t0.x, t1.y, k), 0).r); lookups += 1u; }
      if (t1.x != t0.x && t1.y != t0.y) { f = FAR(f, texelFetch(levels, ivec3(t1, k), 0).r); lookups += 1u; }
      culled = HIDDEN(d, f);
    }
  }
#endif
  decisions[gl_VertexID] = Decision(vec4(win, d, size), culled ? 1u : 0u, lookups, 0u, 0u);
  if (culled) gl_Position = vec4(0.0, 0.0, 2.0, 1.0);  // beyond the far plane in both conventions
#endif
}

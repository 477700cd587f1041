// One relief ray per box fragment, with the draw's method: the twin of model/relief/walk.cpp,
// expression for expression (every float is `precise`, so no product and sum are fused and the
// order is the written one); change one, change the other. BOX_DEPTH (model/relief/box_depth.h)
// says what the draw leaves in the depth buffer:
//  0 none, 1 box: early fragment tests, depth writes off here: the walk runs only for fragments that
//    pass the depth test against the box face's depth, and the fragment counter counts those. (Box:
//    the paper's conservative depth is written by relief_keep.frag right after, for the hits: GL
//    cannot record a discarded fragment's walk without a memory write, and a memory write turns
//    llvmpipe's early test off; with early_fragment_tests a discarded fragment would still write.)
//  2 exact: gl_FragDepth is the hit's depth (hit_depth, box_depth.cpp's twin), so the test runs after
//    the shader: every rasterized fragment walks and is counted, and the draw writes depth.
// Per fragment: a record of six words at results[6 * pixel]: 1 (the shader ran), hit (0 miss,
// 1 hit, 2 capped), the hit's t (bits), lookups, steps, bisections. A miss discards.
#version 450 core
#ifndef BOX_DEPTH
#define BOX_DEPTH 0
#endif
#if BOX_DEPTH != 2
layout(early_fragment_tests) in;
#else
uniform mat4 texel_to_clip;  // the vertex shader's: the hit point's clip position
#endif
layout(std430, binding = 0) buffer Fragments { uint fragments[]; };
layout(std430, binding = 1) buffer Results { uint results[]; };
uniform uint draw_slot;
uniform int viewport_width;
uniform sampler2D heights;       // R32F, N x N
uniform sampler2D radii;         // R32F, N x N (robust methods)
uniform sampler2DArray levels;   // R32F, the heightfield's max N-buffer, one layer a level
uniform int size, top_level, method, linear_steps, binary_steps, root_steps;
uniform vec3 origin, ray_a, ray_b, ray_c;
uniform bool frustum;
uniform vec4 eye_h, ray_qa, ray_qb, ray_qc;
layout(location = 0) out uint hit_mask;

const float kFar = 3.0e38;
precise vec3 o, d;
precise float t_in, t_out;
bool floor_exit = false;
uint lookups = 0u, steps = 0u, bisections = 0u;
bool capped = false;

float height_at(int i, int j) {
  lookups += 1u;
  if (i < 0 || j < 0 || i >= size || j >= size) return 0.0;
  return texelFetch(heights, ivec2(i, j), 0).r;
}
float radius_at(int i, int j) {
  lookups += 1u;
  return texelFetch(radii, ivec2(i, j), 0).r;
}
float level_at(int l, int i, int j) {
  lookups += 1u;
  return texelFetch(levels, ivec3(i, j, l), 0).r;
}
float along(float oo, float t, float dd) {
  precise float r = oo + t * dd;
  return r;
}
float bilerp(float h00, float h10, float h01, float h11, float fx, float fy) {
  precise float a = h00 + fx * (h10 - h00);
  precise float b = h01 + fx * (h11 - h01);
  precise float r = a + fy * (b - a);
  return r;
}
float above(float t) {
  precise float u = along(o.x, t, d.x) - 0.5;
  precise float v = along(o.y, t, d.y) - 0.5;
  int i = int(floor(u)), j = int(floor(v));
  precise float fx = u - float(i);
  precise float fy = v - float(j);
  float h00 = height_at(i, j), h10 = height_at(i + 1, j), h01 = height_at(i, j + 1), h11 = height_at(i + 1, j + 1);
  precise float r = along(o.z, t, d.z) - bilerp(h00, h10, h01, h11, fx, fy);
  return r;
}
int cell_index(float oo, float t, float dd) {
  precise float u = along(oo, t, dd) - 0.5;
  int c = dd < 0.0 ? int(ceil(u)) - 1 : int(floor(u));
  return clamp(c, -1, size - 1);
}
float cell_exit(float oo, float dd, int c) {
  precise float r = kFar;
  if (dd > 0.0) r = ((float(c) + 1.5) - oo) / dd;
  else if (dd < 0.0) r = ((float(c) + 0.5) - oo) / dd;
  return r;
}

// The cell walker's state (walk.cpp's CellWalk and Cell).
int ci, cj;
precise float cw_t;
precise float c00, c10, c01, c11;

void cell_start(float from) {
  cw_t = from;
  ci = cell_index(o.x, from, d.x);
  cj = cell_index(o.y, from, d.y);
}
bool cell_inside() { return ci >= -1 && cj >= -1 && ci < size && cj < size; }
float cell_above(float t) {
  precise float fx = (along(o.x, t, d.x) - 0.5) - float(ci);
  precise float fy = (along(o.y, t, d.y) - 0.5) - float(cj);
  precise float r = along(o.z, t, d.z) - bilerp(c00, c10, c01, c11, fx, fy);
  return r;
}
float refine_in_cell(float a0, float b0) {
  precise float a = a0, b = b0;
  for (int k = 0; k < root_steps; ++k) {
    precise float m = (a + b) * 0.5;
    if (cell_above(m) <= 0.0) b = m;
    else a = m;
  }
  bisections += uint(root_steps);
  return b;
}
float cell_test(float ta, float tb, bool full) {
  precise float fa = cell_above(ta);
  if (fa <= 0.0) return ta;
  precise float fb = cell_above(tb);
  if (fb <= 0.0) return refine_in_cell(ta, tb);
  if (!full) return -1.0;
  precise float tm = (ta + tb) * 0.5;
  precise float fm = cell_above(tm);
  if (fm <= 0.0) return refine_in_cell(ta, tm);
  precise float q2 = 2.0 * ((fa - 2.0 * fm) + fb);
  if (!(q2 > 0.0)) return -1.0;
  precise float q1 = (fb - fa) - q2;
  precise float s = -q1 / (2.0 * q2);
  if (!(s > 0.0 && s < 1.0)) return -1.0;
  precise float tv = ta + s * (tb - ta);
  if (cell_above(tv) > 0.0) return -1.0;
  return refine_in_cell(ta, tv);
}
float cell_step(bool full) {
  precise float tx = cell_exit(o.x, d.x, ci);
  precise float ty = cell_exit(o.y, d.y, cj);
  precise float tb = max(cw_t, min(min(tx, ty), t_out));
  c00 = height_at(ci, cj);
  c10 = height_at(ci + 1, cj);
  c01 = height_at(ci, cj + 1);
  c11 = height_at(ci + 1, cj + 1);
  steps += 1u;
  precise float hit = cell_test(cw_t, tb, full);
  if (hit >= 0.0) return hit;
  if (tx < ty) ci += d.x > 0.0 ? 1 : -1;
  else if (ty < tx) cj += d.y > 0.0 ? 1 : -1;
  else {
    ci += d.x > 0.0 ? 1 : -1;
    cj += d.y > 0.0 ? 1 : -1;
  }
  cw_t = tb;
  return -1.0;
}

float bisect(float a0, float b0) {
  precise float a = a0, b = b0;
  for (int k = 0; k < binary_steps; ++k) {
    precise float m = (a + b) * 0.5;
    if (above(m) <= 0.0) b = m;
    else a = m;
  }
  bisections += uint(binary_steps);
  return b;
}

float inverse_horizontal() {
  if (d.x == 0.0 && d.y == 0.0) return 0.0;
  precise float r = 1.0 / sqrt(d.x * d.x + d.y * d.y);
  return r;
}
float advance(float t, float texels, float inv) {
  if (inv == 0.0) return t_out;
  precise float r = min(t + texels * inv, t_out);
  return r;
}

// Each walk returns the hit's t, or -1 for a miss (capped sets `capped`).
float walk_binary() {
  precise float dt = (t_out - t_in) / float(linear_steps);
  precise float prev = t_in;
  for (int k = 1; k <= linear_steps; ++k) {
    precise float t = t_in + dt * float(k);
    steps += 1u;
    if (above(t) <= 0.0) return bisect(prev, t);
    prev = t;
  }
  return -1.0;
}
float walk_exact(int cap) {
  cell_start(t_in);
  for (int n = 0; n < cap; ++n) {
    if (!cell_inside() || cw_t >= t_out) return -1.0;
    precise float hit = cell_step(false);
    if (hit >= 0.0) return hit;
  }
  capped = true;
  return -1.0;
}
float walk_robust(bool clamp_zero, int cap) {
  precise float inv = inverse_horizontal();
  precise float t = t_in;
  for (int it = 0; it < cap; ++it) {
    int i = clamp(int(floor(along(o.x, t, d.x))), 0, size - 1);
    int j = clamp(int(floor(along(o.y, t, d.y))), 0, size - 1);
    precise float rad = radius_at(i, j);
    if (rad == 0.0) {
      if (clamp_zero) {
        rad = 1.0;
      } else {
        cell_start(t);
        for (int k = 0; k < 2 && cell_inside() && cw_t < t_out; ++k) {
          precise float hit = cell_step(true);
          if (hit >= 0.0) return hit;
        }
        if (!cell_inside() || cw_t >= t_out) return -1.0;
        t = cw_t;
        continue;
      }
    }
    precise float next = advance(t, rad, inv);
    steps += 1u;
    if (above(next) <= 0.0) return bisect(t, next);
    if (next >= t_out) return -1.0;
    t = next;
  }
  capped = true;
  return -1.0;
}
float nbuffer_max(float x0, float x1, float y0, float y1) {
  int i0 = clamp(int(floor(x0 - 0.5)), 0, size - 1), i1 = clamp(int(floor(x1 - 0.5)) + 1, 0, size - 1);
  int j0 = clamp(int(floor(y0 - 0.5)), 0, size - 1), j1 = clamp(int(floor(y1 - 0.5)) + 1, 0, size - 1);
  int level;
  ivec2 squares[4];
  const int n = nb_cover(ivec4(i0, j0, i1 - i0 + 1, j1 - j0 + 1), top_level, level, squares);
  float m = level_at(level, squares[0].x, squares[0].y);
  for (int k = 1; k < n; ++k) m = max(m, level_at(level, squares[k].x, squares[k].y));
  return m;
}
float walk_nbuffer(int cap) {
  precise float inv = inverse_horizontal();
  precise float t = t_in;
  int s = 0;
  bool walking = false;
  for (int it = 0; it < cap; ++it) {
    steps += 1u;
    precise float te = advance(t, float(1 << s), inv);
    precise float xa = along(o.x, t, d.x), xb = along(o.x, te, d.x);
    precise float ya = along(o.y, t, d.y), yb = along(o.y, te, d.y);
    float top_height = nbuffer_max(min(xa, xb), max(xa, xb), min(ya, yb), max(ya, yb));
    precise float lowest = min(along(o.z, t, d.z), along(o.z, te, d.z));
    if (lowest > top_height) {
      if (te >= t_out) return -1.0;
      t = te;
      walking = false;
      s = min(s + 1, top_level);
    } else if (s > 0) {
      s -= 1;
    } else {
      if (!walking) cell_start(t);
      if (!cell_inside() || cw_t >= t_out) return -1.0;
      precise float hit = cell_step(true);
      if (hit >= 0.0) return hit;
      t = cw_t;
      walking = true;
      if (!cell_inside() || t >= t_out) return -1.0;
    }
  }
  capped = true;
  return -1.0;
}

// The ray of this pixel centre, clipped to the box (walk.cpp's fragment_ray): false on a miss.
bool fragment_ray(float px, float py) {
  if (frustum) {
    precise vec4 q;
    q.x = (ray_qa.x * px + ray_qb.x * py) + ray_qc.x;
    q.y = (ray_qa.y * px + ray_qb.y * py) + ray_qc.y;
    q.z = (ray_qa.z * px + ray_qb.z * py) + ray_qc.z;
    q.w = (ray_qa.w * px + ray_qb.w * py) + ray_qc.w;
    if (!(q.w > 0.0)) return false;
    o.x = q.x / q.w;
    o.y = q.y / q.w;
    o.z = q.z / q.w;
    d.x = eye_h.w * q.x - q.w * eye_h.x;
    d.y = eye_h.w * q.y - q.w * eye_h.y;
    d.z = eye_h.w * q.z - q.w * eye_h.z;
  } else {
    o = origin;
    d.x = (ray_a.x * px + ray_b.x * py) + ray_c.x;
    d.y = (ray_a.y * px + ray_b.y * py) + ray_c.y;
    d.z = (ray_a.z * px + ray_b.z * py) + ray_c.z;
  }
  precise float tmin = 0.0, tmax = kFar, t_floor = kFar;
  for (int k = 0; k < 3; ++k) {
    precise float oo = o[k], dd = d[k];
    precise float hi = k < 2 ? float(size) : 1.0;
    if (dd == 0.0) {
      if (oo < 0.0 || oo > hi) return false;
      continue;
    }
    precise float t1 = (0.0 - oo) / dd;
    precise float t2 = (hi - oo) / dd;
    tmin = max(tmin, min(t1, t2));
    tmax = min(tmax, max(t1, t2));
    if (k == 2 && dd < 0.0) t_floor = t1;
  }
  if (!(tmin <= tmax)) return false;
  t_in = tmin;
  t_out = tmax;
  floor_exit = t_floor == tmax;
  return true;
}

#if BOX_DEPTH == 2
float hit_depth(float t) {
  precise float x = along(o.x, t, d.x);
  precise float y = along(o.y, t, d.y);
  precise float z = along(o.z, t, d.z);
  precise float cz = ((texel_to_clip[0][2] * x + texel_to_clip[1][2] * y) + texel_to_clip[2][2] * z) + texel_to_clip[3][2];
  precise float cw = ((texel_to_clip[0][3] * x + texel_to_clip[1][3] * y) + texel_to_clip[2][3] * z) + texel_to_clip[3][3];
  precise float r = (cz / cw) * 0.5 + 0.5;
  return r;
}
#endif

void main() {
  atomicAdd(fragments[draw_slot], 1u);
  uint pixel = uint(gl_FragCoord.y) * uint(viewport_width) + uint(gl_FragCoord.x);
  precise float hit_t = -1.0;
  uint code = 0u;
  if (fragment_ray(gl_FragCoord.x, gl_FragCoord.y)) {
    int cap = 16 * (size + 2) + 64;
    if (above(t_in) <= 0.0) hit_t = t_in;
    else if (method == 0) hit_t = walk_binary();
    else if (method == 1) hit_t = walk_exact(cap);
    else if (method == 2) hit_t = walk_robust(false, cap);
    else if (method == 3) hit_t = walk_robust(true, cap);
    else hit_t = walk_nbuffer(cap);
    if (!capped && hit_t < 0.0 && floor_exit) hit_t = t_out;
    code = capped ? 2u : (hit_t >= 0.0 ? 1u : 0u);
  }
  results[6u * pixel + 0u] = 1u;
  results[6u * pixel + 1u] = code;
  results[6u * pixel + 2u] = code == 1u ? floatBitsToUint(hit_t) : 0u;
  results[6u * pixel + 3u] = lookups;
  results[6u * pixel + 4u] = steps;
  results[6u * pixel + 5u] = bisections;
  if (code != 1u) discard;
#if BOX_DEPTH == 2
  gl_FragDepth = hit_depth(hit_t);
#endif
  hit_mask = 1u;
}

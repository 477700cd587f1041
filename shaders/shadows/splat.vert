// The receiver splat (ours, beside the paper's litmaps): every observer pixel whose surface point
// lies inside the light's frustum, as a one-pixel point at that point's light position and depth,
// drawn into both litmaps with their depth funcs (LEQUAL min, GEQUAL max). The litmaps' object
// draws sample receivers at lexel centres only; a receiver the observer sees may have no lexel
// centre on it (smaller than a lexel, at a grazing angle to the light, or hidden from the lexel
// centres' rays by an intermediate occluder). The splat puts every receiver the shadow mask samples
// into the lexel it projects to, so each caster's [z_min, z_max] brackets them.
// One vertex per observer pixel (no attributes): gl_VertexID = y * width + x. The surface point is
// the observer's depth at the pixel centre, taken to the light's clip space in double precision by
// one matrix (litmap.cpp ReceiverSplat, the twin of this shader expression for expression: every
// double is `precise`). A pixel with no surface or outside the light's frustum is clipped.
#version 450 core
uniform sampler2D observer_depth;  // the observer's depth (window depth, LESS, [-1, 1] clip z)
// Light clip = rows * (x + 0.5, y + 0.5, depth, 1): the light's view_proj times the inverse of the
// observer's times the observer's window-to-NDC map.
uniform dvec4 splat_x, splat_y, splat_z, splat_w;
uniform ivec2 size;                // the observer's viewport, pixels

double row(dvec4 m, double x, double y, double z) {
  precise double r = ((m.x * x + m.y * y) + m.z * z) + m.w;
  return r;
}

void main() {
  const ivec2 p = ivec2(gl_VertexID % size.x, gl_VertexID / size.x);
  const float d = texelFetch(observer_depth, p, 0).r;
  gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // outside every clip plane: no point
  if (d >= 1.0) return;                     // the far plane: no surface
  precise double x = double(p.x) + 0.5, y = double(p.y) + 0.5, z = double(d);
  precise dvec4 q = dvec4(row(splat_x, x, y, z), row(splat_y, x, y, z), row(splat_z, x, y, z), row(splat_w, x, y, z));
  if (!(q.w > 0.0 && abs(q.x) <= q.w && abs(q.y) <= q.w && abs(q.z) <= q.w)) return;  // outside the light's frustum
  // Pulled inside by 2^-20 of w so that rounding to f32 cannot clip a receiver on the frustum's
  // border (a shift far below a lexel and the clamp margin).
  precise double inner = q.w * (1.0 - 1.0 / 1048576.0);
  gl_Position = vec4(min(max(q.x, -inner), inner), min(max(q.y, -inner), inner), min(max(q.z, -inner), inner), q.w);
}

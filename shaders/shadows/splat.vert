// The receiver splat (ours, beside the paper's litmaps): every observer pixel whose surface point
// lies inside the light's frustum, as a one-pixel point at that point's light position and depth,
// drawn into both litmaps with their depth funcs (LEQUAL min, GEQUAL max). The litmaps' object
// draws sample receivers at lexel centres only; a receiver the observer sees may have no lexel
// centre on it (smaller than a lexel, at a grazing angle to the light, or hidden from the lexel
// centres' rays by an intermediate occluder). The splat puts every receiver the shadow mask samples
// into the lexel it projects to, so each caster's [z_min, z_max] brackets them.
// One vertex per observer pixel (no attributes): gl_VertexID = y * width + x. The surface point is
// the observer's depth buffer unprojected at the pixel centre, in double precision (the depth the
// stencil test compares with). A pixel with no surface or outside the light's frustum is clipped.
#version 450 core
uniform sampler2D observer_depth;  // the observer's depth (window depth, LESS, [-1, 1] clip z)
uniform dmat4 unproject;           // inverse of the observer's view_proj
uniform dmat4 light_view_proj;
uniform ivec2 size;                // the observer's viewport, pixels

void main() {
  const ivec2 p = ivec2(gl_VertexID % size.x, gl_VertexID / size.x);
  const double d = double(texelFetch(observer_depth, p, 0).r);
  gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // outside every clip plane: no point
  if (d >= 1.0) return;                     // the far plane: no surface
  const dvec4 w = unproject * dvec4((dvec2(p) + 0.5) / dvec2(size) * 2.0 - 1.0, 2.0 * d - 1.0, 1.0);
  dvec4 q = light_view_proj * dvec4(w.xyz / w.w, 1.0);
  if (!(q.w > 0.0 && all(lessThanEqual(abs(q.xyz), dvec3(q.w))))) return;  // outside the light's frustum
  // Pulled inside by 2^-20 of w so that rounding to f32 cannot clip a receiver on the frustum's
  // border (a shift far below a lexel and the clamp margin).
  const double inner = q.w * (1.0 - 1.0 / 1048576.0);
  q.xyz = clamp(q.xyz, dvec3(-inner), dvec3(inner));
  gl_Position = vec4(q);
}

// The volumetric parity test per scene fragment (the LDI applications: clipping and 3D lenses): the
// twin of model/ldi/clip.cpp (VolumeTest), expression for expression; change one, change the other.
// The fragment's point is rebuilt from gl_FragCoord with each volume's window-to-texel matrix (every
// float `precise`: no product and sum fused, the written order), then tested against the volumes in
// order with the draw's reader until one holds it:
//   reader 0, layers: the cropped layers nearest first up to the first not in front (early exit);
//   reader 1, all: every one of the d layers (the paper's reader);
//   reader 2, ranges: the compressed RG32UI texture, its index then the ranges up to the answer.
// keep_inside false (clipping, a lens's context pass) discards a fragment inside any volume; true (a
// lens's focus pass) discards one outside every volume. No early fragment tests: the test runs for
// every rasterized fragment and the depth test follows for the kept ones (llvmpipe tests late when a
// shader can discard).
// Per draw slot, four words at decisions[4 * slot]: fragments discarded, texels fetched, and two sums
// of a hash of each discarded fragment's (pixel, gl_FragCoord.z bits): GL's decisions, fragment by
// fragment, in a form the atomics' order cannot change.
#version 450 core
#define MAX_VOLUMES 4
layout(std430, binding = 0) buffer Fragments { uint fragments[]; };
layout(std430, binding = 3) buffer Decisions { uint decisions[]; };
uniform uint draw_slot;
uniform uint object_id;
uniform int viewport_width;
uniform int volume_count;
uniform int reader;
uniform bool keep_inside;
uniform mat4 window_to_texel[MAX_VOLUMES];
uniform ivec4 crop[MAX_VOLUMES];  // x, y, w, h in the LDI's texels
uniform int depth_complexity[MAX_VOLUMES];
uniform uint comp_side[MAX_VOLUMES];
uniform sampler2DArray layers[MAX_VOLUMES];
uniform usampler2D compressed[MAX_VOLUMES];
layout(location = 0) out uint id;

uint fetches = 0u;

uint mix_bits(uint x) {
  x ^= x >> 16;
  x *= 0x85ebca6bu;
  x ^= x >> 13;
  x *= 0xc2b2ae35u;
  x ^= x >> 16;
  return x;
}

vec3 texel_point(mat4 m) {
  precise vec4 h = ((m[0] * gl_FragCoord.x + m[1] * gl_FragCoord.y) + m[2] * gl_FragCoord.z) + m[3];
  precise vec3 t = h.xyz / h.w;
  return t;
}

bool test_layers(sampler2DArray l, ivec2 xy, float z, int d) {
  uint in_front = 0u;
  for (int k = 0; k < d; ++k) {
    ++fetches;
    if (!(texelFetch(l, ivec3(xy, k), 0).r < z)) break;
    ++in_front;
  }
  return (in_front & 1u) == 1u;
}

bool test_all(sampler2DArray l, ivec2 xy, float z, int d) {
  uint in_front = 0u;
  for (int k = 0; k < d; ++k) {
    ++fetches;
    if (texelFetch(l, ivec3(xy, k), 0).r < z) ++in_front;
  }
  return (in_front & 1u) == 1u;
}

bool test_ranges(usampler2D c, uint side, ivec2 xy, int crop_w, float z) {
  uint t = uint(xy.y * crop_w + xy.x);
  ++fetches;
  uvec2 index = texelFetch(c, ivec2(int(t % side), int(t / side)), 0).rg;
  for (uint j = 0u; j < index.y; ++j) {
    ++fetches;
    uint r = index.x + j;
    uvec2 range = texelFetch(c, ivec2(int(r % side), int(r / side)), 0).rg;
    if (z <= uintBitsToFloat(range.x)) return false;
    if (z <= uintBitsToFloat(range.y)) return true;
  }
  return false;
}

bool inside_volume(sampler2DArray l, usampler2D c, int v) {
  vec3 t = texel_point(window_to_texel[v]);
  ivec4 r = crop[v];
  // Outside the crop (NaN included): outside, nothing read.
  if (!(t.x >= float(r.x) && t.x < float(r.x + r.z) && t.y >= float(r.y) && t.y < float(r.y + r.w))) return false;
  ivec2 xy = ivec2(t.xy) - r.xy;
  if (reader == 0) return test_layers(l, xy, t.z, depth_complexity[v]);
  if (reader == 1) return test_all(l, xy, t.z, depth_complexity[v]);
  return test_ranges(c, comp_side[v], xy, r.z, t.z);
}

void main() {
  atomicAdd(fragments[draw_slot], 1u);
  bool inside = false;
  for (int v = 0; v < volume_count && !inside; ++v) {
    // Constant sampler indices (a loop index is not a constant expression).
    if (v == 0) inside = inside_volume(layers[0], compressed[0], 0);
    else if (v == 1) inside = inside_volume(layers[1], compressed[1], 1);
    else if (v == 2) inside = inside_volume(layers[2], compressed[2], 2);
    else inside = inside_volume(layers[3], compressed[3], 3);
  }
  atomicAdd(decisions[4u * draw_slot + 1u], fetches);
  if (inside != keep_inside) {
    uint pixel = uint(gl_FragCoord.y) * uint(viewport_width) + uint(gl_FragCoord.x);
    uint key = mix_bits(pixel ^ mix_bits(floatBitsToUint(gl_FragCoord.z)));
    atomicAdd(decisions[4u * draw_slot + 0u], 1u);
    atomicAdd(decisions[4u * draw_slot + 2u], key);
    atomicAdd(decisions[4u * draw_slot + 3u], mix_bits(key + 0x9e3779b9u));
    discard;
  }
  id = object_id + 1u;
}

// The volumetric parity test on GL (traces/capture/ldi/build.cpp), both readers of
// model/ldi/vpt.h with its tie rule and fetch counting, one invocation per test point:
// - layers: the cropped layered texture (d layers of w_crop x h_crop); a point outside the crop is
//   outside with 0 fetches; layers are read nearest first up to and including the first one that is
//   not in front (depth >= z, +inf included); inside iff an odd number was in front (depth < z);
// - all layers (the paper's reader): every one of the d layers read, the ones in front counted;
// - ranges: the compressed RG32UI texture: 1 index fetch (offset, k), then the ranges nearest first
//   until z <= start (outside) or z <= end (inside: start < z <= end); behind every range: outside.
#version 450 core
layout(local_size_x = 64) in;
uniform sampler2DArray cropped;
uniform usampler2D compressed;
uniform ivec4 crop;            // x, y, w, h in the LDI's texels
uniform int depth_complexity;  // d
uniform uint side;             // w_c
uniform uint count;
layout(std430, binding = 0) readonly buffer Points { ivec4 point[]; };  // x, y, bits of z, unused
layout(std430, binding = 1) writeonly buffer Answers { uvec4 answer[]; };  // inside, fetches (layers), inside, fetches (ranges)
layout(std430, binding = 2) writeonly buffer AllAnswers { uvec2 all_answer[]; };  // inside, fetches (all layers)
uvec2 fetch_compressed(uint t) { return texelFetch(compressed, ivec2(int(t % side), int(t / side)), 0).rg; }
void main() {
  uint p = gl_GlobalInvocationID.x;
  if (p >= count) return;
  ivec2 xy = point[p].xy - crop.xy;
  float z = intBitsToFloat(point[p].z);
  if (xy.x < 0 || xy.y < 0 || xy.x >= crop.z || xy.y >= crop.w) {
    answer[p] = uvec4(0u);
    all_answer[p] = uvec2(0u);
    return;
  }
  uint in_front = 0u, layer_fetches = 0u;
  for (int k = 0; k < depth_complexity; ++k) {
    ++layer_fetches;
    if (!(texelFetch(cropped, ivec3(xy, k), 0).r < z)) break;
    ++in_front;
  }
  uint all_in_front = 0u, all_fetches = 0u;
  for (int k = 0; k < depth_complexity; ++k) {
    ++all_fetches;
    if (texelFetch(cropped, ivec3(xy, k), 0).r < z) ++all_in_front;
  }
  all_answer[p] = uvec2(all_in_front & 1u, all_fetches);
  uint t = uint(xy.y * crop.z + xy.x);
  uvec2 index = fetch_compressed(t);
  uint range_fetches = 1u, inside = 0u;
  for (uint j = 0u; j < index.y; ++j) {
    ++range_fetches;
    uvec2 r = fetch_compressed(index.x + j);
    if (z <= uintBitsToFloat(r.x)) break;
    if (z <= uintBitsToFloat(r.y)) {
      inside = 1u;
      break;
    }
  }
  answer[p] = uvec4(in_front & 1u, layer_fetches, inside, range_fetches);
}

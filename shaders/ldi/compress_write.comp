// Compression, step 3 (traces/capture/ldi/build.cpp, model/ldi/compression.h's layout): per cropped
// texel i, the index texel i = (I + its exclusive offset, k) and its ranges at texels I + offset + j
// = (bits(layer 2j), bits(layer 2j + 1)), the lone last layer of an odd count paired with bits(+inf),
// into the RG32UI texture of side w_c (texel t at (t % w_c, t / w_c)), which was cleared to zero.
#version 450 core
layout(local_size_x = 8, local_size_y = 8) in;
uniform sampler2DArray layers;  // the full LDI
uniform ivec4 crop;
uniform uint index_texels;      // I
uniform uint side;              // w_c
layout(rg32ui, binding = 0) writeonly uniform uimage2D compressed;
layout(std430, binding = 0) readonly buffer Counts { uint layer_count[]; };
layout(std430, binding = 1) readonly buffer Ranges { uint range_count[]; };
layout(std430, binding = 2) readonly buffer Offsets { uint offset[]; };
ivec2 at(uint t) { return ivec2(int(t % side), int(t / side)); }
void main() {
  ivec2 c = ivec2(gl_GlobalInvocationID.xy);
  if (c.x >= crop.z || c.y >= crop.w) return;
  uint i = uint(c.y * crop.z + c.x);
  uint n = layer_count[i], k = range_count[i], first = index_texels + offset[i];
  imageStore(compressed, at(i), uvec4(first, k, 0u, 0u));
  for (uint j = 0u; j < k; ++j) {
    uint s = floatBitsToUint(texelFetch(layers, ivec3(crop.xy + c, int(2u * j)), 0).r);
    uint e = 2u * j + 1u < n ? floatBitsToUint(texelFetch(layers, ivec3(crop.xy + c, int(2u * j + 1u)), 0).r) : 0x7F800000u;
    imageStore(compressed, at(first + j), uvec4(s, e, 0u, 0u));
  }
}

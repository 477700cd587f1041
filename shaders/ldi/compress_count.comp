// Compression, step 1 (traces/capture/ldi/build.cpp, model/ldi/compression.h): per cropped texel
// (index i = cy * w_crop + cx), its layer count n (layers before the first +inf, at most d) and its
// range count k = ceil(n / 2).
#version 450 core
layout(local_size_x = 8, local_size_y = 8) in;
uniform sampler2DArray layers;  // the full LDI
uniform ivec4 crop;             // x, y, w, h
uniform int depth_complexity;   // d
layout(std430, binding = 0) writeonly buffer Counts { uint layer_count[]; };
layout(std430, binding = 1) writeonly buffer Ranges { uint range_count[]; };
void main() {
  ivec2 c = ivec2(gl_GlobalInvocationID.xy);
  if (c.x >= crop.z || c.y >= crop.w) return;
  uint n = 0u;
  for (int k = 0; k < depth_complexity; ++k) {
    if (isinf(texelFetch(layers, ivec3(crop.xy + c, k), 0).r)) break;
    ++n;
  }
  uint i = uint(c.y * crop.z + c.x);
  layer_count[i] = n;
  range_count[i] = (n + 1u) / 2u;
}

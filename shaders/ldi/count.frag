// Viewpoint selection (traces/capture/ldi/build.cpp): every rasterized fragment of the shape adds 1
// at its texel of an R32UI image (no depth test, no culling, no colour attachment), so a texel ends
// with the number of surfaces its centre line crosses. The vertex stage is peel.vert.
#version 450 core
layout(r32ui, binding = 0) uniform uimage2D counts;
void main() { imageAtomicAdd(counts, ivec2(gl_FragCoord.xy), 1u); }

// Depth peeling: one pass keeps, per texel, the nearest fragment strictly behind the previous
// layer. Counts every rasterized fragment first (no early fragment tests: the count is taken
// before the discard and the depth test), then discards unless gl_FragCoord.z > previous layer at
// this texel (texelFetch of a separate 2D texture, never the one this pass renders to), then writes
// gl_FragCoord.z as the colour. No gl_FragDepth write: the depth test (LEQUAL against a buffer
// cleared to 1.0 each pass) sees the same z, so colour and depth buffer order fragments alike.
#version 450 core
layout(std430, binding = 0) buffer Fragments { uint fragments[]; };
uniform uint draw_slot;
uniform bool first_pass;
uniform sampler2D previous_layer;
layout(location = 0) out float layer_depth;
void main() {
  atomicAdd(fragments[draw_slot], 1u);
  float d = gl_FragCoord.z;
  if (!first_pass && !(d > texelFetch(previous_layer, ivec2(gl_FragCoord.xy), 0).r)) discard;
  layer_depth = d;
}

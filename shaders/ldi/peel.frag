// Depth peeling: one pass keeps, per texel, the nearest fragment strictly behind the previous
// layer. Counts every rasterized fragment first (no early fragment tests: the count is taken
// before the discard and the depth test), then discards unless depth > previous layer at this
// texel (texelFetch of a separate 2D texture, never the one this pass renders to), then writes the
// linear depth as the colour and as the fragment depth (depth test LEQUAL against a buffer cleared
// to 1.0 each pass), so the depth test and the colour order fragments by the same float.
#version 450 core
layout(std430, binding = 0) buffer Fragments { uint fragments[]; };
uniform uint pass_slot;
uniform bool first_pass;
uniform sampler2D previous_layer;
noperspective in float linear_depth;
layout(location = 0) out float layer_depth;
void main() {
  atomicAdd(fragments[pass_slot], 1u);
  float d = clamp(linear_depth, 0.0, 1.0);
  if (!first_pass && !(d > texelFetch(previous_layer, ivec2(gl_FragCoord.xy), 0).r)) discard;
  layer_depth = d;
  gl_FragDepth = d;
}

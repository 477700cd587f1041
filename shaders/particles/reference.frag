// The particles' reference pass: every particle drawn with the frame's depth test and early
// fragment tests, so each fragment that reaches this shader passed the depth test; a counter per
// particle gives its passed samples, the ground truth of popping.
#version 450 core
layout(early_fragment_tests) in;
layout(std430, binding = 4) buffer Reference { uint samples[]; };
flat in uint particle_id;
void main() { atomicAdd(samples[particle_id], 1u); }

// A heightfield baked from a mesh (traces/capture/relief/bake.cpp): depth only, the vertex stage is
// ldi/peel.vert (xy in NDC and 1 - height as the window depth, clip control ZERO_TO_ONE, w = 1).
#version 450 core
void main() {}

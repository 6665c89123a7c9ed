#version 450
#extension GL_GOOGLE_include_directive : require
// Every covered voxel centre flips the draw's bits (logic op XOR): the presence buffer
// of §5.3.1, one bit per slice.
#include "slice_params.glsl"
layout(location = 0) out uint bits;
void main() {
    bits = pc.bits;
}

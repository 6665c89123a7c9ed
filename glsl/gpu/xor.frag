#version 450
#extension GL_GOOGLE_include_directive : require
// Every covered texel receives `value`; the logic op XOR flips those bits, so a texel
// covered an even number of times ends where it started.
#include "xor_params.glsl"
layout(location = 0) out uint bits;
void main() {
    bits = pc.value;
}

#version 450
#extension GL_GOOGLE_include_directive : require
// Fixed-function style (§5.3.3, Fang & Chen): the CPU computed the triangles of the
// slice; the vertex shader only maps grid units to clip coordinates.
#include "slice_params.glsl"
layout(location = 0) in vec2 position;   // (x, z) in grid units
void main() {
    gl_Position = vec4(position * pc.clip_scale + pc.clip_offset, 0.0, 1.0);
}

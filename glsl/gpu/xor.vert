#version 450
#extension GL_GOOGLE_include_directive : require
// Triangles given in texel units, rasterized with Vulkan's top-left rule.
#include "texel.glsl"
#include "xor_params.glsl"
layout(location = 0) in vec2 position;
void main() {
    gl_Position = pixel_to_clip(position, pc.size);
}

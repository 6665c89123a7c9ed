#version 450
#extension GL_GOOGLE_include_directive : require
// The point-list pass: one point per datum (gl_PointSize = 1), placed on its own texel
// of a `width`-wide target, carrying a value for the fragment shader to write.
#include "texel.glsl"
layout(push_constant) uniform Params {
    vec2 size;
} pc;
layout(location = 0) in uint texel;
layout(location = 1) in vec4 value;
layout(location = 0) flat out vec4 v;
void main() {
    gl_Position = texel_centre(texel_of(texel, uint(pc.size.x)), pc.size);
    gl_PointSize = 1.0;
    v = value;
}

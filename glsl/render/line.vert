#version 450
#extension GL_GOOGLE_include_directive : require
// Thick line segments and points, one instance per segment: six vertices make a
// screen-aligned quad `width` pixels wide around the projected segment, with square caps
// (a point is a segment of length zero: a square). Endpoints move a small fraction of
// their eye distance towards the eye so that edges drawn over their own surface win the
// depth test.
#include "view.glsl"
layout(location = 0) in vec3 a;
layout(location = 1) in vec3 b;
layout(location = 2) in uint colour;
layout(location = 3) in float width;
layout(location = 0) out vec4 tint;

const int ENDS[6] = int[6](0, 1, 1, 0, 1, 0);
const float SIDES[6] = float[6](-1.0, -1.0, 1.0, -1.0, 1.0, 1.0);

vec4 clip(vec3 p) {
    vec4 eye = u.view * vec4(p, 1.0);
    eye.xyz *= 1.0 - u.viewport.z;
    return u.proj * eye;
}

void main() {
    vec4 ca = clip(a);
    vec4 cb = clip(b);
    // Clip the segment to the near plane (z >= 0 in Vulkan clip space), so a segment that
    // passes behind the eye never turns into a quad flipped across the picture.
    if (ca.z < 0.0 && cb.z < 0.0) {
        gl_Position = vec4(0.0, 0.0, -1.0, 1.0);  // wholly behind: outside the view volume
        tint = vec4(0.0);
        return;
    }
    if (ca.z < 0.0) {
        ca = mix(ca, cb, ca.z / (ca.z - cb.z));
    } else if (cb.z < 0.0) {
        cb = mix(cb, ca, cb.z / (cb.z - ca.z));
    }
    vec2 half_size = 0.5 * u.viewport.xy;
    vec2 d = (cb.xy / cb.w - ca.xy / ca.w) * half_size;
    float len = length(d);
    vec2 dir = len > 1e-6 ? d / len : vec2(1.0, 0.0);
    vec2 across = vec2(-dir.y, dir.x);
    int end = ENDS[gl_VertexIndex];
    vec4 c = end == 0 ? ca : cb;
    vec2 offset = (across * SIDES[gl_VertexIndex] + dir * (end == 0 ? -1.0 : 1.0)) * (0.5 * width);
    c.xy += offset / half_size * c.w;
    gl_Position = c;
    tint = unpackUnorm4x8(colour);
}

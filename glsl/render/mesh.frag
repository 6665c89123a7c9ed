#version 450
// Shading of a rendered mesh: a headlight from the eye, two-sided (open or inverted
// meshes look the same from both sides); flat shading takes the triangle's normal from
// the screen-space derivatives of the eye position.
layout(location = 0) in vec3 eye_pos;
layout(location = 1) in vec3 eye_normal;
layout(location = 2) in vec4 base;
layout(push_constant) uniform Style {
    uint shading;   // 0 flat, 1 smooth, 2 unlit
} pc;
layout(location = 0) out vec4 colour;

void main() {
    if (pc.shading == 2u) {
        colour = vec4(base.rgb, 1.0);
        return;
    }
    vec3 n = pc.shading == 0u ? cross(dFdx(eye_pos), dFdy(eye_pos)) : eye_normal;
    float len = length(n);
    float facing = len > 0.0 ? abs(dot(n / len, normalize(-eye_pos))) : 1.0;
    colour = vec4(base.rgb * (0.3 + 0.7 * facing), 1.0);
}

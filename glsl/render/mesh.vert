#version 450
#extension GL_GOOGLE_include_directive : require
// A mesh of a rendered picture: positions, smooth normals and RGBA8 colours per vertex.
#include "view.glsl"
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in uint colour;
layout(location = 0) out vec3 eye_pos;
layout(location = 1) out vec3 eye_normal;
layout(location = 2) out vec4 base;

void main() {
    vec4 eye = u.view * vec4(position, 1.0);
    gl_Position = u.proj * eye;
    eye_pos = eye.xyz;
    eye_normal = mat3(u.view) * normal;
    base = unpackUnorm4x8(colour);
}

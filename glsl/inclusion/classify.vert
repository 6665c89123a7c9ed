#version 450
#extension GL_GOOGLE_include_directive : require
// Alg. 4-2, phase 1: one point-vertex per covering tetrahedron, placed on its own texel.
// The vertex classifies a group of query points against its tetrahedron (four per
// attachment, one per RGBA channel, eight attachments) using the tetrahedron's four
// face planes, precomputed on the host (inward unit normals, apex at the origin).
// A point clearly inside gets 2s, clearly outside 0; a point within `eps` of a face
// (on a face, an edge through the apex, the base; or a flat tetrahedron) gets FLAG,
// which the host detects in the sum and answers with the exact CPU test.
#include "texel.glsl"
#include "classify_params.glsl"

layout(location = 0) in vec4 plane0;
layout(location = 1) in vec4 plane1;
layout(location = 2) in vec4 plane2;
layout(location = 3) in vec4 plane3;
// x: 2s (the inclusion value of a point strictly inside); y: kind (0 regular,
// 1 flat: plane0 holds its plane, 2 degenerate: plane0 holds a bounding sphere).
layout(location = 4) in vec2 info;

layout(set = 0, binding = 0) uniform Points {
    vec4 p[GROUP_POINTS * MAX_GROUPS];
} points;

layout(location = 0) flat out vec4 v[8];

float classify(vec3 q) {
    if (info.y == 0.0) {
        float d = min(min(dot(plane0.xyz, q) + plane0.w, dot(plane1.xyz, q) + plane1.w),
                      min(dot(plane2.xyz, q) + plane2.w, dot(plane3.xyz, q) + plane3.w));
        return d >= pc.eps ? info.x : (d <= -pc.eps ? 0.0 : FLAG);
    }
    if (info.y == 1.0) {
        return abs(dot(plane0.xyz, q) + plane0.w) < pc.eps ? FLAG : 0.0;
    }
    return distance(plane0.xyz, q) <= plane0.w + pc.eps ? FLAG : 0.0;
}

void main() {
    ivec2 t = texel_of(uint(gl_VertexIndex), uint(pc.size.x));
    // Instance i handles point group first_group + i and renders into tile i (a
    // column of tiles below each other).
    t.y += gl_InstanceIndex * int(pc.tile_rows);
    gl_Position = texel_centre(t, pc.size);
    gl_PointSize = 1.0;
    int base = (pc.first_group + gl_InstanceIndex) * GROUP_POINTS;
    for (int a = 0; a < 8; ++a) {
        v[a] = vec4(classify(points.p[base + 4 * a].xyz),
                    classify(points.p[base + 4 * a + 1].xyz),
                    classify(points.p[base + 4 * a + 2].xyz),
                    classify(points.p[base + 4 * a + 3].xyz));
    }
}

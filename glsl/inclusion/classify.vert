#version 450
#extension GL_GOOGLE_include_directive : require
// Alg. 4-2, phase 1 over every covering tetrahedron: vertex i sums tetrahedra
// [i*batch, (i+1)*batch) for point group `instance` and lands in that group's tile.
#include "texel.glsl"
#include "classify_common.glsl"

void main() {
    uint vertex = uint(gl_VertexIndex);
    uint group = uint(gl_InstanceIndex);
    ivec2 t = texel_of(vertex, uint(pc.size.x));
    t.y += int(group * pc.tile_rows);
    gl_Position = texel_centre(t, pc.size);
    gl_PointSize = 1.0;
    vec3 q[GROUP_POINTS];
    float acc[GROUP_POINTS];
    for (int k = 0; k < GROUP_POINTS; ++k) {
        q[k] = points.p[group * GROUP_POINTS + k].xyz;
        acc[k] = 0.0;
    }
    uint first = vertex * pc.batch;
    uint last = min(first + pc.batch, pc.tetra_count);
    for (uint id = first; id < last; ++id) {
        Tetra T = fetch_tetra(id);
        for (int k = 0; k < GROUP_POINTS; ++k) {
            acc[k] += classify(T, q[k]);
        }
    }
    emit(acc);
}

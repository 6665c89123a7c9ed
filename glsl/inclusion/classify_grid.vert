#version 450
#extension GL_GOOGLE_include_directive : require
// Alg. 4-2, phase 1 with the TetraGrid: each instance is a job, the query points of
// one grid cell (up to 32) against that cell's tetrahedra only. Vertex i sums batch i
// of the cell's list; vertices past the end of a shorter list are sent off target.
#include "texel.glsl"
#include "classify_common.glsl"

layout(set = 0, binding = 2) uniform usampler2D cell_lists;
// x: first entry of the cell's list, y: list length, z: first point, w: point count.
layout(location = 0) in uvec4 job;

void main() {
    uint vertex = uint(gl_VertexIndex);
    uint first = vertex * pc.batch;
    if (first >= job.y) {
        gl_Position = vec4(2.0, 2.0, 0.0, 1.0); // outside the view volume: no fragment
        gl_PointSize = 1.0;
        return;
    }
    place(vertex, uint(gl_InstanceIndex));
    vec3 q[GROUP_POINTS];
    float acc[GROUP_POINTS];
    for (int k = 0; k < GROUP_POINTS; ++k) {
        q[k] = points.p[job.z + uint(k)].xyz;
        acc[k] = 0.0;
    }
    uint last = min(first + pc.batch, job.y);
    for (uint e = first; e < last; ++e) {
        uint at = job.x + e;
        uint id = texelFetch(cell_lists, ivec2(int(at % pc.index_width), int(at / pc.index_width)), 0).x;
        Tetra T = fetch_tetra(id);
        for (uint k = 0u; k < job.w; ++k) {
            acc[k] += classify(T, q[k]);
        }
    }
    emit(acc);
}

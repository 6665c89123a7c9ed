#version 450
#extension GL_GOOGLE_include_directive : require
// Alg. 4-2, phase 1 with the TetraGrid: the query points of one grid cell (up to 32,
// a job) against that cell's tetrahedra only. Each point-vertex is one batch of one
// job's list and carries where it goes: the vertices of a job fill 4x4 tiles of the
// target, which the 2x2 reduction sums to one texel each.
#include "texel.glsl"
#include "classify_common.glsl"

layout(set = 0, binding = 2) uniform usampler2D cell_lists;
// Per job: x = first entry of the cell's list, y = list length, z = first point,
// w = point count.
layout(set = 0, binding = 3) uniform Jobs {
    uvec4 jobs[MAX_POINTS];
} jobs;

// x: job, y: batch of the job's list, zw: target texel.
layout(location = 0) in uvec4 item;

void main() {
    uvec4 job = jobs.jobs[item.x];
    gl_Position = texel_centre(ivec2(item.zw), pc.size);
    gl_PointSize = 1.0;
    vec3 q[GROUP_POINTS];
    float acc[GROUP_POINTS];
    for (int k = 0; k < GROUP_POINTS; ++k) {
        q[k] = points.p[job.z + uint(k)].xyz;
        acc[k] = 0.0;
    }
    uint first = item.y * pc.batch;
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

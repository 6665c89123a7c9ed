#version 450
#extension GL_GOOGLE_include_directive : require
// Alg. 5-2, §5.3.4: a static buffer with two triangles (six vertices) per tetra; every
// vertex carries the tetra's vertices sorted by y (A highest) and which cross-section
// point it is. The vertex shader moves it to that point of the slice (SPEC §4.2 table)
// or, when the slice misses the tetra, to the culled corner.
#include "slice_params.glsl"
layout(location = 0) in uint point;   // a, b, c = 0, 1, 2; second triangle c, b, d = 6, 5, 3
layout(location = 1) in vec3 A;
layout(location = 2) in vec3 B;
layout(location = 3) in vec3 C;
layout(location = 4) in vec3 D;

void main() {
    float s = pc.slice;
    // Half-open in y: a vertex is above iff y > s; the slice cuts the tetra iff 1..3 are.
    int above = int(A.y > s) + int(B.y > s) + int(C.y > s) + int(D.y > s);
    if (above == 0 || above == 4) {
        gl_Position = CULLED;
        return;
    }
    // The second triangle (c, b, d) exists only in the middle interval.
    if (point >= 3u && above != 2) {
        gl_Position = CULLED;
        return;
    }
    uint p = point & 3u;
    vec3 U = A, L = D;                                                 // a: AD
    if (p == 1u) { U = above == 1 ? A : B; L = above == 1 ? B : D; }   // b: AB | BD
    if (p == 2u) { U = above == 3 ? C : A; L = above == 3 ? D : C; }   // c: AC | CD
    if (p == 3u) { U = B; L = C; }                                     // d: BC
    // One formula for every edge (upper end first), as slicing::edge_point: tetras that
    // share an edge compute bit-identical points, so their shared edges cancel.
    precise float t = (s - U.y) / (L.y - U.y);
    precise vec2 q = U.xz + (L.xz - U.xz) * t;
    gl_Position = vec4(q * pc.clip_scale + pc.clip_offset, 0.0, 1.0);
}

// Alg. 4-2, phase 1, shared by classify.vert (all tetrahedra) and classify_grid.vert
// (a TetraGrid cell's tetrahedra). Each point-vertex lands on its own texel and sums the
// inclusion values of a batch of tetrahedra (batch = 1 is the thesis' layout: one
// point per tetrahedron) for a group of 32 query points: four per attachment, one per
// RGBA channel, eight attachments.
//
// A tetrahedron is four face planes with inward unit normals, in coordinates
// normalized to the solid's bounding cube (host side: gpu.rs). A query point clearly
// inside (every plane >= eps) gets 2s, clearly outside (some plane <= -eps) gets 0:
// both are exact, since f32 errors stay far below eps. Anything else (on a face, an edge
// through the apex, the base, or a flat tetrahedron) gets FLAG; the host sees it in the
// sum and answers that point with the exact CPU test.

#define GROUP_POINTS 32
#define MAX_POINTS 2048
// Non-flagged terms are exact and a valid solid's total is 0 or 2, so any other sum
// (a flagged term adds 8) sends the point to the exact CPU test.
#define FLAG 8.0

layout(push_constant) uniform Params {
    vec2 size;          // target size in texels
    float eps;          // plane-distance margin, normalized units
    uint tile_rows;     // rows of one tile; instance i renders into tile i
    uint first_group;   // first point group of this draw (classify.vert)
    uint batch;         // tetrahedra per point-vertex
    uint tetra_count;
    uint tetra_width;   // width of the tetrahedra texture
    uint index_width;   // width of the cell-list texture (classify_grid.vert)
} pc;

// Layers 0-3: the face planes (xyz normal, w offset); layer 4: x = 2s, y = kind
// (0 regular; 1 flat: layer 0 is its plane; 2 degenerate: layer 0 is a bounding sphere).
layout(set = 0, binding = 0) uniform sampler2DArray tetras;
layout(set = 0, binding = 1) uniform Points {
    vec4 p[MAX_POINTS];
} points;

layout(location = 0) flat out vec4 v[8];

struct Tetra {
    vec4 plane[4];
    vec2 info;
};

Tetra fetch_tetra(uint id) {
    ivec2 t = ivec2(int(id % pc.tetra_width), int(id / pc.tetra_width));
    Tetra T;
    for (int k = 0; k < 4; ++k) {
        T.plane[k] = texelFetch(tetras, ivec3(t, k), 0);
    }
    T.info = texelFetch(tetras, ivec3(t, 4), 0).xy;
    return T;
}

float classify(Tetra T, vec3 q) {
    if (T.info.y == 0.0) {
        float d = min(min(dot(T.plane[0].xyz, q) + T.plane[0].w, dot(T.plane[1].xyz, q) + T.plane[1].w),
                      min(dot(T.plane[2].xyz, q) + T.plane[2].w, dot(T.plane[3].xyz, q) + T.plane[3].w));
        return d >= pc.eps ? T.info.x : (d <= -pc.eps ? 0.0 : FLAG);
    }
    if (T.info.y == 1.0) {
        return abs(dot(T.plane[0].xyz, q) + T.plane[0].w) < pc.eps ? FLAG : 0.0;
    }
    return distance(T.plane[0].xyz, q) <= T.plane[0].w + pc.eps ? FLAG : 0.0;
}

// Puts this point-vertex on texel `i` of tile `tile` (tiles stacked vertically).
void place(uint i, uint tile) {
    ivec2 t = texel_of(i, uint(pc.size.x));
    t.y += int(tile * pc.tile_rows);
    gl_Position = texel_centre(t, pc.size);
    gl_PointSize = 1.0;
}

void emit(float acc[GROUP_POINTS]) {
    for (int a = 0; a < 8; ++a) {
        v[a] = vec4(acc[4 * a], acc[4 * a + 1], acc[4 * a + 2], acc[4 * a + 3]);
    }
}

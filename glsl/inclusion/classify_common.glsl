// Alg. 4-2, phase 1, shared by classify.vert (all tetrahedra) and classify_grid.vert
// (a TetraGrid cell's tetrahedra). Each point-vertex lands on its own texel and sums the
// inclusion values of a batch of tetrahedra (batch = 1 is the thesis' layout: one
// point per tetrahedron) for a group of 32 query points: four per attachment, one per
// RGBA channel, eight attachments.
//
// Coordinates are normalized to the solid's bounding cube and taken relative to the
// apex (host side: gpu.rs), so the three faces through the apex are planes through the
// origin. A query point clearly inside (every plane >= eps) gets 2s, clearly outside
// (some plane <= -eps) gets 0: both exact, since f32 errors stay far below eps.
// Anything in between (on a face, an edge through the apex, the base) gets FLAG; the
// host sees it in the sum and answers that point with the exact CPU test.

#define GROUP_POINTS 32
#define MAX_POINTS 2048
// Trusted terms sum to 0 or 2 for a valid solid, so any other sum (a flagged term adds
// 8) sends the point to the exact CPU test.
#define FLAG 8.0

layout(push_constant) uniform Params {
    vec2 size;          // render area in texels
    float eps;          // plane-distance margin, normalized units
    uint tile_rows;     // rows of one tile; instance i renders into tile i (classify.vert)
    uint batch;         // tetrahedra per point-vertex
    uint tetra_count;
    uint tetra_width;   // width of the tetrahedra texture
    uint index_width;   // width of the cell-list texture (classify_grid.vert)
} pc;

// Layers 0-2: the faces through the apex (xyz: unit inward normal; layer 0's w: 2s);
// layer 3: the base plane (xyz: unit inward normal, w: offset).
layout(set = 0, binding = 0) uniform sampler2DArray tetras;
layout(set = 0, binding = 1) uniform Points {
    vec4 p[MAX_POINTS];
} points;

layout(location = 0) flat out vec4 v[8];

struct Tetra {
    vec4 f0;
    vec3 f1;
    vec3 f2;
    vec4 base;
};

Tetra fetch_tetra(uint id) {
    ivec2 t = ivec2(int(id % pc.tetra_width), int(id / pc.tetra_width));
    Tetra T;
    T.f0 = texelFetch(tetras, ivec3(t, 0), 0);
    T.f1 = texelFetch(tetras, ivec3(t, 1), 0).xyz;
    T.f2 = texelFetch(tetras, ivec3(t, 2), 0).xyz;
    T.base = texelFetch(tetras, ivec3(t, 3), 0);
    return T;
}

float classify(Tetra T, vec3 q) {
    float d = min(min(dot(T.f0.xyz, q), dot(T.f1, q)), min(dot(T.f2, q), dot(T.base.xyz, q) + T.base.w));
    return d >= pc.eps ? T.f0.w : (d <= -pc.eps ? 0.0 : FLAG);
}

void emit(float acc[GROUP_POINTS]) {
    for (int a = 0; a < 8; ++a) {
        v[a] = vec4(acc[4 * a], acc[4 * a + 1], acc[4 * a + 2], acc[4 * a + 3]);
    }
}

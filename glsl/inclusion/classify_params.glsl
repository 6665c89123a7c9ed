// Shared by classify.vert and classify.frag.
#define GROUP_POINTS 32
#define MAX_GROUPS 64
// Added to a point's sum by every tetrahedron that cannot classify it safely in f32.
// Non-flagged terms are exact and the true total is 0, 1 or 2, so a sum >= 3 means
// "flagged" however the flagged tetrahedra would have counted (see gpu.rs).
#define FLAG 8.0
layout(push_constant) uniform Params {
    vec2 size;        // target size in texels
    float eps;        // plane-distance margin (units of the normalized coordinates)
    uint tile_rows;   // rows per tile (one tile per instance)
    int first_group;  // first point group of this draw
} pc;

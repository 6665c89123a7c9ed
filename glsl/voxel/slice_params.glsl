// Push constants of the slicing passes: grid units (x, z) -> clip coordinates, the
// slice plane, and the bits this draw XORs into its R32UI texels (32 slices per texel).
layout(push_constant) uniform Params {
    vec2 clip_scale;   // clip = p * clip_scale + clip_offset
    vec2 clip_offset;
    float slice;       // y of the slice plane in grid units (j + 0.5)
    uint bits;         // 1 << (j mod 32) for a slice; a mask for a Fang slab
} pc;

// Where culled vertices go: the corner of the viewport, in the margin around the voxels
// and on no texel centre, so a culled triangle has no area and never needs clipping.
const vec4 CULLED = vec4(-1.0, -1.0, 0.0, 1.0);

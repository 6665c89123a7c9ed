// Placing data on texels: the texture era's addressing.

// Clip-space position of the centre of texel `t` of a `size` target, for point draws
// (one point per datum, gl_PointSize = 1, lands on exactly that texel).
vec4 texel_centre(ivec2 t, vec2 size) {
    return vec4((vec2(t) + 0.5) / size * 2.0 - 1.0, 0.0, 1.0);
}

// Texel of datum `i` in a row-major layout `width` texels wide.
ivec2 texel_of(uint i, uint width) {
    return ivec2(int(i % width), int(i / width));
}

// Clip-space position of a point given in texel units (x right, y down, texel (i, j)
// has its centre at (i + 0.5, j + 0.5)).
vec4 pixel_to_clip(vec2 p, vec2 size) {
    return vec4(p / size * 2.0 - 1.0, 0.0, 1.0);
}

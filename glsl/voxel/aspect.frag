#version 450
#extension GL_GOOGLE_include_directive : require
// The aspect function of §5.3.4 (Fig. 5-9): every occupied voxel of the slice gets the
// colour of a material given by 3D Perlin noise at its centre; empty voxels stay
// transparent. One fragment per voxel of the slice (a full-target quad).
layout(set = 0, binding = 0) uniform usampler2DArray occupancy;  // 32 slices per texel
layout(set = 0, binding = 1) uniform usampler2D perm;
layout(push_constant) uniform Params {
    uint slice;       // j
    uint n;           // resolution
    uint material;    // 0 marble, 1 wood, 2 granite
    float frequency;  // noise periods across the grid
} pc;
layout(location = 0) out vec4 colour;
#include "perlin.glsl"

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);   // (i, k)
    uint bits = texelFetch(occupancy, ivec3(t, int(pc.slice / 32u)), 0).r;
    if (((bits >> (pc.slice % 32u)) & 1u) == 0u) {
        colour = vec4(0.0);
        return;
    }
    vec3 p = vec3(t.x, pc.slice, t.y) + 0.5;
    vec3 q = p / float(pc.n) * pc.frequency;
    vec3 c;
    if (pc.material == 0u) {
        // Marble: bands along x bent by turbulence.
        float v = 0.5 + 0.5 * sin(6.2831853 * q.x + 6.0 * turbulence(q, 5));
        c = mix(vec3(0.32, 0.30, 0.36), vec3(0.95, 0.93, 0.88), v);
    } else if (pc.material == 1u) {
        // Wood: rings around the y axis, wobbled.
        float r = length(q.xz - 0.5 * pc.frequency) * 4.0 + 0.6 * turbulence(q * 2.0, 3);
        float v = fract(r);
        c = mix(vec3(0.55, 0.33, 0.14), vec3(0.85, 0.62, 0.35), smoothstep(0.0, 0.7, v) * (1.0 - smoothstep(0.7, 1.0, v)));
    } else {
        // Granite: speckles.
        float v = clamp(0.5 + 0.8 * noise(q * 8.0) + 0.3 * noise(q * 32.0), 0.0, 1.0);
        c = mix(vec3(0.15, 0.14, 0.16), vec3(0.80, 0.72, 0.70), v);
    }
    colour = vec4(c, 1.0);
}

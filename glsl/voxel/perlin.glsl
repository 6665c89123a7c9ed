// Improved 3D Perlin noise (Perlin 2002) with the permutation table in a 256x1 texture,
// the texture-era way of getting it onto the GPU ([Green05]).
// Needs `perm` (usampler2D, binding given by the includer).

uint perm_at(int i) {
    return texelFetch(perm, ivec2(i & 255, 0), 0).r;
}

// Gradient dot product: 12 edge directions of the cube picked by the hash's low bits.
float grad(uint h, vec3 p) {
    h &= 15u;
    float u = h < 8u ? p.x : p.y;
    float v = h < 4u ? p.y : ((h == 12u || h == 14u) ? p.x : p.z);
    return ((h & 1u) == 0u ? u : -u) + ((h & 2u) == 0u ? v : -v);
}

vec3 fade(vec3 t) {
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
}

// Noise in about [-1, 1], zero at integer lattice points.
float noise(vec3 p) {
    vec3 cell = floor(p);
    ivec3 i = ivec3(cell) & 255;
    vec3 f = p - cell;
    vec3 w = fade(f);
    int a = int(perm_at(i.x)) + i.y;
    int b = int(perm_at(i.x + 1)) + i.y;
    int aa = int(perm_at(a)) + i.z, ab = int(perm_at(a + 1)) + i.z;
    int ba = int(perm_at(b)) + i.z, bb = int(perm_at(b + 1)) + i.z;
    float x00 = mix(grad(perm_at(aa), f), grad(perm_at(ba), f - vec3(1, 0, 0)), w.x);
    float x10 = mix(grad(perm_at(ab), f - vec3(0, 1, 0)), grad(perm_at(bb), f - vec3(1, 1, 0)), w.x);
    float x01 = mix(grad(perm_at(aa + 1), f - vec3(0, 0, 1)), grad(perm_at(ba + 1), f - vec3(1, 0, 1)), w.x);
    float x11 = mix(grad(perm_at(ab + 1), f - vec3(0, 1, 1)), grad(perm_at(bb + 1), f - vec3(1, 1, 1)), w.x);
    return mix(mix(x00, x10, w.y), mix(x01, x11, w.y), w.z);
}

// Sum of |noise| over octaves: the "turbulence" that veins marble and roughens wood.
float turbulence(vec3 p, int octaves) {
    float sum = 0.0, scale = 1.0;
    for (int o = 0; o < octaves; ++o) {
        sum += abs(noise(p * scale)) / scale;
        scale *= 2.0;
    }
    return sum;
}

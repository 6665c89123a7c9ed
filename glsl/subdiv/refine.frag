#version 450
// One Catmull-Clark level of every fragment mesh at once (2010 thesis §3.3.2, SPEC §5.3):
// a full-target pass over the output stream, one invocation per new vertex, reading the
// previous level (ping-pong). Fragments lie back to back in the thesis' storage order
// (centre, then ring by ring, sector by sector), a 1D stream wrapped into rows of 2^n
// texels, grouped in runs of one class (valence, half-fan). Each invocation finds its
// run, fragment and (sector, a, b), then applies the stencil: both coordinates even →
// vertex point, one odd → edge point, both odd → face point. Stencils are derived here
// (regular masks, the valence-k centre, border rules on half-fans), the same as
// `stencil` in src/subdiv/fragment.rs.
//
// No integer division: like the GPUs of the era (and llvmpipe's SIMD code, which has no
// vector integer divide), quotients come from float division plus an exact correction.

// Entries of `runs` (the Rust side uploads exactly this many; see src/subdiv/gpu.rs).
#define MAX_RUNS 256

layout(set = 0, binding = 0) uniform sampler2D src;
// Per class run: (valence, half-fan 0/1, first input texel, first output texel).
layout(set = 0, binding = 1, std140) uniform Runs {
    ivec4 runs[MAX_RUNS];
} tab;
layout(push_constant) uniform Params {
    int r_in;       // ring radius of the input fragments
    int r_out;      // ring radius written by this pass
    int run_count;  // entries of tab.runs in use
    int total_out;  // texels of the output stream
    int log2_width; // rows are 2^log2_width texels wide
} pc;
layout(location = 0) out vec4 result;

// The current fragment: valence, half-fan flag, first input texel.
int K;
int E;
int BASE;

// floor(n / d) for 0 <= n < 2^30, 1 <= d < 2^24, exact.
int divide(int n, int d) {
    float fd = float(d);
    int q = int(float(n) / fd);
    int r = n - q * d;
    q += int(floor(float(r) / fd));
    r = n - q * d;
    if (r < 0) {
        q -= 1;
    } else if (r >= d) {
        q += 1;
    }
    return q;
}

// Entries before ring r (r >= 1), centre excluded.
int ring_offset(int r) {
    return K * r * (r - 1) + E * (r - 1);
}

// Input texel of vertex (a, b) of sector s, after moving (a, -1) and (0, b) to the
// neighbouring sector. Written with selects, not branches: SIMD lanes diverge here.
vec3 at(int s, int a, int b) {
    bool below = b < 0;
    int s1 = below ? ((s == 0) ? K - 1 : s - 1) : s;
    int a1 = below ? 1 : a;
    int b1 = below ? a : b;
    bool on_next = a1 == 0;
    int s2 = on_next ? ((s1 + 1 == K && E == 0) ? 0 : s1 + 1) : s1;
    int a2 = on_next ? b1 : a1;
    int b2 = on_next ? 0 : b1;
    int r = max(a2, b2);
    int t = (a2 == r) ? b2 : 2 * r - a2;
    int i = BASE + ((a2 == 0) ? 0 : 1 + ring_offset(r) + s2 * 2 * r + t);
    return texelFetch(src, ivec2(i & ((1 << pc.log2_width) - 1), i >> pc.log2_width), 0).xyz;
}

vec3 centre_point() {
    vec3 c = at(0, 0, 0);
    if (E == 1) {
        return 0.75 * c + 0.125 * (at(0, 1, 0) + at(K, 1, 0));
    }
    vec3 edges = vec3(0.0);
    vec3 diagonals = vec3(0.0);
    for (int s = 0; s < K; ++s) {
        edges += at(s, 1, 0);
        diagonals += at(s, 1, 1);
    }
    float n = float(K);
    return c * (1.0 - 7.0 / (4.0 * n)) + edges * (1.5 / (n * n)) + diagonals * (0.25 / (n * n));
}

void main() {
    int lin = (int(gl_FragCoord.y) << pc.log2_width) + int(gl_FragCoord.x);
    if (lin >= pc.total_out) {
        result = vec4(0.0);
        return;
    }
    // The class run holding this texel: the last one starting at or before it.
    int lo = 0;
    int hi = pc.run_count - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) >> 1;
        if (tab.runs[mid].w <= lin) {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    ivec4 run = tab.runs[lo];
    K = run.x;
    E = run.y;
    int len_out = 1 + K * (pc.r_out + 1) * pc.r_out + E * pc.r_out;
    int len_in = 1 + K * (pc.r_in + 1) * pc.r_in + E * pc.r_in;
    int u = lin - run.w;
    int frag = divide(u, len_out);
    int i = u - frag * len_out;
    BASE = run.z + frag * len_in;

    vec3 p;
    if (i == 0) {
        p = centre_point();
    } else {
        // Ring r: the largest r with ring_offset(r) <= q (quadratic, then corrected).
        int q = i - 1;
        float k = float(K);
        float d = float(K - E);
        int r = max(1, int((d + sqrt(d * d + 4.0 * k * float(E + q))) / (2.0 * k)));
        if (ring_offset(r + 1) <= q) {
            r += 1;
        }
        if (ring_offset(r) > q) {
            r -= 1;
        }
        int w = q - ring_offset(r);
        int s = divide(w, 2 * r);
        int t = w - s * 2 * r;
        int a = (s == K || t <= r) ? r : 2 * r - t;
        int b = (s == K) ? 0 : min(t, r);
        bool border = E == 1 && b == 0 && (s == 0 || s == K);
        // The masks are tensor products of 1D ones (B-spline subdivision): per axis, an
        // even output coordinate takes (1/8, 3/4, 1/8) of the input at c/2 - 1, c/2,
        // c/2 + 1, an odd one (1/2, 1/2) of c/2 and c/2 + 1, and a half-fan's border
        // spoke takes only b = 0 (the boundary rules). Taps of weight 0 read the centre
        // tap again, so every address stays valid.
        int a0 = a >> 1;
        int b0 = b >> 1;
        bool a_even = (a & 1) == 0;
        bool b_even = (b & 1) == 0;
        ivec3 ta = ivec3(a_even ? a0 - 1 : a0, a0, a0 + 1);
        vec3 wa = a_even ? vec3(0.125, 0.75, 0.125) : vec3(0.0, 0.5, 0.5);
        ivec3 tb = border ? ivec3(0) : ivec3(b_even ? b0 - 1 : b0, b0, b0 + 1);
        vec3 wb = border ? vec3(0.0, 1.0, 0.0) : (b_even ? vec3(0.125, 0.75, 0.125) : vec3(0.0, 0.5, 0.5));
        p = vec3(0.0);
        for (int y = 0; y < 3; ++y) {
            vec3 row = wa.x * at(s, ta.x, tb[y]) + wa.y * at(s, ta.y, tb[y]) + wa.z * at(s, ta.z, tb[y]);
            p += wb[y] * row;
        }
    }
    result = vec4(p, 1.0);
}

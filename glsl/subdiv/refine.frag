#version 450
// One Catmull-Clark level of every fragment mesh at once (2010 thesis §3.3.2, SPEC §5.3,
// issue 14): a full-target pass over the output stream, one invocation per new texel,
// reading the previous level (ping-pong). Fragments lie back to back in the thesis'
// storage order (centre, then ring by ring, sector by sector), a 1D stream wrapped into
// rows of 2^n texels, grouped in runs of one class (valence, half-fan, sharpness horizon).
// Each invocation finds its run, fragment and (sector, a, b), then applies the stencil:
// both coordinates even -> vertex point, one odd -> edge point, both odd -> face point.
//
// Smooth fragments take the tensor-product masks (and the valence-k centre). In a sharp
// fragment every vertex entry is followed by a data texel — centre: (vertex sharpness,
// 0, 0, 0); entry (a, b): (semi-sharp count, sharpness of edge (a-1,b)-(a,b), of edge
// (a,b-1)-(a,b), semi-sharp sum) — and the invocation applies OpenSubdiv's rules
// (Sdc::Crease: dart, crease and corner masks, their fractional blends, uniform or
// Chaikin decay). An invocation on a data texel writes the decayed data of its vertex for
// the next level. The same rules as `sharp_stencil` / `sharp_data` in
// src/subdiv/fragment.rs (there in f64, here in f32).
//
// No integer division: like the GPUs of the era (and llvmpipe's SIMD code, which has no
// vector integer divide), quotients come from float division plus an exact correction.

// Entries of `runs` (the Rust side uploads exactly this many; see src/subdiv/gpu.rs).
#define MAX_RUNS 256
#define INFINITE 10.0

layout(set = 0, binding = 0) uniform sampler2D src;
// Per class run: (valence, flags, first input texel, first output texel); flags: 1
// half-fan, 2 data texels in the input, 4 data texels in the output.
layout(set = 0, binding = 1, std140) uniform Runs {
    ivec4 runs[MAX_RUNS];
} tab;
layout(push_constant) uniform Params {
    int r_in;       // ring radius of the input fragments
    int r_out;      // ring radius written by this pass
    int run_count;  // entries of tab.runs in use
    int total_out;  // texels of the output stream
    int log2_width; // rows are 2^log2_width texels wide
    int chaikin;    // 1: Chaikin creasing, 0: uniform
} pc;
layout(location = 0) out vec4 result;

// The current fragment: valence, half-fan flag, first input texel, texels per input entry.
int K;
int E;
int BASE;
int STRIDE;

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

// Storage index of vertex (a, b) of sector s, after moving (a, -1) and (0, b) to the
// neighbouring sector. Written with selects, not branches: SIMD lanes diverge here.
int entry(int s, int a, int b) {
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
    return (a2 == 0) ? 0 : 1 + ring_offset(r) + s2 * 2 * r + t;
}

vec4 fetch(int i) {
    return texelFetch(src, ivec2(i & ((1 << pc.log2_width) - 1), i >> pc.log2_width), 0);
}

vec3 at(int s, int a, int b) {
    return fetch(BASE + entry(s, a, b) * STRIDE).xyz;
}

// The data texel of entry (s, a, b) (sharp fragments only).
vec4 dat(int s, int a, int b) {
    return fetch(BASE + entry(s, a, b) * 2 + 1);
}

vec3 centre_point() {
    vec3 c = at(0, 0, 0);
    if (E == 1) {
        return c; // never used: a half-fan's centre has two infinitely sharp edges
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

// The 3 x 3 taps of the last smooth_point call (row y, column x at T[3 * y + x]): every
// position the sharp rules need is among them.
vec3 T[9];

// The smooth stencil of entry (s, a, b) (a >= 1): the masks are tensor products of 1D
// ones (B-spline subdivision): per axis, an even output coordinate takes (1/8, 3/4, 1/8)
// of the input at c/2 - 1, c/2, c/2 + 1, an odd one (1/2, 1/2) of c/2 and c/2 + 1. On a
// half-fan's border only b = 0 is read (its value is never used there: border edges are
// infinitely sharp). Taps of weight 0 read the centre tap again, so every address stays
// valid.
vec3 smooth_point(int s, int a, int b) {
    bool border = E == 1 && b == 0 && (s == 0 || s == K);
    int a0 = a >> 1;
    int b0 = b >> 1;
    bool a_even = (a & 1) == 0;
    bool b_even = (b & 1) == 0;
    ivec3 ta = ivec3(a_even ? a0 - 1 : a0, a0, a0 + 1);
    vec3 wa = a_even ? vec3(0.125, 0.75, 0.125) : vec3(0.0, 0.5, 0.5);
    ivec3 tb = border ? ivec3(0) : ivec3(b_even ? b0 - 1 : b0, b0, b0 + 1);
    vec3 wb = border ? vec3(0.0, 1.0, 0.0) : (b_even ? vec3(0.125, 0.75, 0.125) : vec3(0.0, 0.5, 0.5));
    vec3 p = vec3(0.0);
    for (int y = 0; y < 3; ++y) {
        T[3 * y] = at(s, ta.x, tb[y]);
        T[3 * y + 1] = at(s, ta.y, tb[y]);
        T[3 * y + 2] = at(s, ta.z, tb[y]);
        p += wb[y] * (wa.x * T[3 * y] + wa.y * T[3 * y + 1] + wa.z * T[3 * y + 2]);
    }
    return p;
}

// ---- Sharpness (OpenSubdiv's Sdc::Crease), four values at a time ----

vec4 decrement4(vec4 s) {
    vec4 d = mix(s - 1.0, vec4(0.0), lessThanEqual(s, vec4(1.0)));
    return mix(d, vec4(INFINITE), greaterThanEqual(s, vec4(INFINITE)));
}

// Child sharpness of edges of sharpness s at a vertex with semi-sharp (count, sum).
vec4 child4(vec4 s, vec2 semi) {
    if (pc.chaikin == 0) {
        return decrement4(s);
    }
    vec4 others = (vec4(semi.y) - s) / max(semi.x - 1.0, 1.0);
    vec4 c = (semi.x > 1.0) ? 0.75 * s + 0.25 * others : s;
    c = max(c - 1.0, vec4(0.0));
    c = mix(c, vec4(0.0), lessThanEqual(s, vec4(0.0)));
    return mix(c, vec4(INFINITE), greaterThanEqual(s, vec4(INFINITE)));
}

float child1(float s, vec2 semi) {
    return child4(vec4(s), semi).x;
}

// 0 smooth, 1 dart, 2 crease, 3 corner.
int rule(float vertex, float sharp_edges) {
    return vertex > 0.0 ? 3 : min(int(sharp_edges), 3);
}

// 1 where an edge's sharpness decays to 0 this level.
vec4 decays4(vec4 parent, vec4 child) {
    bvec4 gone = (pc.chaikin == 0) ? lessThanEqual(parent, vec4(1.0)) : lessThanEqual(child, vec4(0.0));
    return vec4(greaterThan(parent, vec4(0.0))) * vec4(gone);
}

// Semi-sharp (count, sum) of four edges (absent ones are 0).
vec2 semi4(vec4 e) {
    vec4 semi = vec4(greaterThan(e, vec4(0.0))) * vec4(lessThan(e, vec4(INFINITE)));
    return vec2(dot(semi, vec4(1.0)), dot(semi, e));
}

// The centre's semi-sharp (count, sum) over its spokes (Chaikin only; set in main).
vec2 CENTRE_SEMI;

// Semi-sharp (count, sum) of vertex (x, y) of sector s, any x, y >= 0 (Chaikin only).
vec2 semi_at(int s, int x, int y) {
    if (pc.chaikin == 0) {
        return vec2(0.0);
    }
    if (x == 0 && y == 0) {
        return CENTRE_SEMI;
    }
    vec4 d = (x == 0) ? dat((s + 1 == K && E == 0) ? 0 : s + 1, y, 0) : dat(s, x, y);
    return d.xw;
}

// The edges of vertex (s, x, y) (x >= 1, y >= 0) in the order -a, +a, -b, +b: their
// sharpness (0 where absent: a half-fan's borders).
vec4 vertex_edges(int s, int x, int y) {
    bool minus_b = y >= 1 || E == 0 || s > 0;
    float e_minus_b = (y >= 1) ? dat(s, x, y).z : (minus_b ? dat((s == 0) ? K - 1 : s - 1, 1, x).y : 0.0);
    return vec4(dat(s, x, y).y, dat(s, x + 1, y).y, e_minus_b, (s < K) ? dat(s, x, y + 1).z : 0.0);
}

// OpenSubdiv's vertex-vertex mask at a vertex p of sharpness vs: the parent's rule, and
// where it changes the child's, blended by the fractional weight. `sharp` and `csharp`
// count the sharp edges of parent and child, `ends` and `cends` sum their neighbours,
// `count` and `sum` the sharpness that decays (incl. the vertex's); sm is the smooth point.
vec3 vertex_mask(vec3 p, float vs, float sharp, float csharp, vec3 ends, vec3 cends, float count, float sum, vec3 sm) {
    int pr = rule(vs, sharp);
    if (pr <= 1) {
        return sm;
    }
    float cvs = decrement4(vec4(vs)).x;
    int cr = rule(cvs, csharp);
    vec3 pm = (pr == 2) ? 0.75 * p + 0.125 * ends : p;
    if (cr == pr) {
        return pm;
    }
    vec3 cm = (cr <= 1) ? sm : ((cr == 2) ? 0.75 * p + 0.125 * cends : p);
    if (vs > 0.0 && cvs <= 0.0) {
        count += 1.0;
        sum += vs;
    }
    float w = count > 0.0 ? min(sum / count, 1.0) : 0.0;
    return w * pm + (1.0 - w) * cm;
}

// The centre of a sharp fragment: the vertex mask over its K (+ E) spokes.
vec3 sharp_centre() {
    vec3 sm = centre_point();
    float sharp = 0.0;
    float csharp = 0.0;
    float count = 0.0;
    float sum = 0.0;
    vec3 ends = vec3(0.0);
    vec3 cends = vec3(0.0);
    for (int s = 0; s < K + E; ++s) {
        float e = dat(s, 1, 0).y;
        float c = child1(e, CENTRE_SEMI);
        vec3 q = at(s, 1, 0);
        float d = decays4(vec4(e), vec4(c)).x;
        sharp += float(e > 0.0);
        csharp += float(c > 0.0);
        ends += float(e > 0.0) * q;
        cends += float(c > 0.0) * q;
        count += d;
        sum += d * e;
    }
    return vertex_mask(at(0, 0, 0), dat(0, 0, 0).x, sharp, csharp, ends, cends, count, sum, sm);
}

// Position of output entry (s, a, b) of a sharp fragment, from its smooth point sm and
// the taps T of smooth_point(s, a, b).
vec3 sharpen(vec3 sm, int s, int a, int b) {
    int x = a >> 1;
    int y = b >> 1;
    bool a_even = (a & 1) == 0;
    bool b_even = (b & 1) == 0;
    if (!a_even && !b_even) {
        return sm; // face point
    }
    if (a_even && b_even) {
        // Vertex point of (x, y): neighbours -a, +a, -b, +b are taps 3, 5, 1, 7.
        vec4 e = vertex_edges(s, x, y);
        vec4 c = child4(e, semi_at(s, x, y));
        vec4 sharp = vec4(greaterThan(e, vec4(0.0)));
        vec4 csharp = vec4(greaterThan(c, vec4(0.0)));
        vec3 ends = sharp.x * T[3] + sharp.y * T[5] + sharp.z * T[1] + sharp.w * T[7];
        vec3 cends = csharp.x * T[3] + csharp.y * T[5] + csharp.z * T[1] + csharp.w * T[7];
        vec4 d = decays4(e, c);
        return vertex_mask(T[4], 0.0, dot(sharp, vec4(1.0)), dot(csharp, vec4(1.0)), ends, cends,
                           dot(d, vec4(1.0)), dot(d, e), sm);
    }
    // Edge point of the parent edge (x, y)-(x1, y1): along a (taps 4, 5) or b (taps 4, 7).
    int x1 = a_even ? x : x + 1;
    int y1 = a_even ? y + 1 : y;
    float e = a_even ? dat(s, x, y1).z : dat(s, x1, y).y;
    if (e <= 0.0) {
        return sm;
    }
    vec3 mid = 0.5 * (T[4] + (a_even ? T[7] : T[5]));
    bool crease = child1(e, semi_at(s, x, y)) > 0.0 && child1(e, semi_at(s, x1, y1)) > 0.0;
    return crease ? mid : e * mid + (1.0 - e) * sm;
}

// Data texel of output entry (s, a, b) (see the header).
vec4 sharp_data(int s, int a, int b) {
    bool a_even = (a & 1) == 0;
    bool b_even = (b & 1) == 0;
    int x = a >> 1;
    int y = b >> 1;
    vec2 semi_here = semi_at(s, x, y);
    // Edge (a-1, b)-(a, b): half of the parent edge along a at row y when b is even; its
    // end vertex is (x, y) either way. Edge (a, b-1)-(a, b): half of the parent edge along
    // b at column x when a is even, end (x, y).
    float ea = b_even ? child1(dat(s, a_even ? x : x + 1, y).y, semi_here) : 0.0;
    float eb = (b >= 1 && a_even) ? child1(dat(s, x, b_even ? y : y + 1).z, semi_here) : 0.0;
    if (pc.chaikin == 0) {
        return vec4(0.0, ea, eb, 0.0);
    }
    // The semi-sharp edges of the new vertex: halves of its parent's edges.
    vec2 semi = vec2(0.0);
    if (a_even && b_even) {
        semi = semi4(child4(vertex_edges(s, x, y), semi_here));
    } else if (a_even != b_even) {
        int x1 = a_even ? x : x + 1;
        int y1 = a_even ? y + 1 : y;
        float e = a_even ? dat(s, x, y1).z : dat(s, x1, y).y;
        semi = semi4(vec4(child1(e, semi_here), child1(e, semi_at(s, x1, y1)), 0.0, 0.0));
    }
    return vec4(semi.x, ea, eb, semi.y);
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
    E = run.y & 1;
    bool data_in = (run.y & 2) != 0;
    int data_out = (run.y >> 2) & 1;
    STRIDE = data_in ? 2 : 1;
    int len_out = 1 + K * (pc.r_out + 1) * pc.r_out + E * pc.r_out;
    int len_in = 1 + K * (pc.r_in + 1) * pc.r_in + E * pc.r_in;
    int u = lin - run.w;
    int frag = divide(u, len_out << data_out);
    int rem = u - frag * (len_out << data_out);
    int i = rem >> data_out;
    bool is_data = (rem & data_out) != 0;
    BASE = run.z + frag * len_in * STRIDE;

    int s = 0;
    int a = 0;
    int b = 0;
    if (i > 0) {
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
        s = divide(w, 2 * r);
        int t = w - s * 2 * r;
        a = (s == K || t <= r) ? r : 2 * r - t;
        b = (s == K) ? 0 : min(t, r);
    }
    CENTRE_SEMI = vec2(0.0);
    if (data_in && pc.chaikin != 0) {
        for (int k = 0; k < K + E; ++k) {
            CENTRE_SEMI += semi4(vec4(dat(k, 1, 0).y, 0.0, 0.0, 0.0));
        }
    }
    if (is_data) {
        result = (i == 0) ? vec4(decrement4(vec4(dat(0, 0, 0).x)).x, 0.0, 0.0, 0.0) : sharp_data(s, a, b);
        return;
    }
    vec3 p;
    if (i == 0) {
        p = data_in ? sharp_centre() : centre_point();
    } else {
        p = smooth_point(s, a, b);
        if (data_in) {
            p = sharpen(p, s, a, b);
        }
    }
    result = vec4(p, 1.0);
}

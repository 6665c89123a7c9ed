// One Catmull-Clark level of every fragment mesh at once (2010 thesis §3.3.2, SPEC §5.3,
// issue 14): a full-target pass over the output stream, one invocation per new texel,
// reading the previous level (ping-pong). Fragments lie back to back in the thesis'
// storage order (centre, then ring by ring, sector by sector), a 1D stream wrapped into
// rows of 2^n texels, grouped in runs of one class (valence, half-fan, sharpness horizon).
// Each invocation finds its run, fragment and (sector, a, b), then applies the stencil:
// both coordinates even -> vertex point, one odd -> edge point, both odd -> face point.
//
// Smooth fragments take the tensor-product masks (and the valence-k centre). Inside the
// part of a fragment a pass evaluates, only spoke edges can be sharp and only the centre
// can have a vertex sharpness (src/subdiv/fragment.rs explains why), so a sharp
// fragment's data lives on its spokes: a data block after all positions holds the
// centre, (vertex sharpness, 0, 0, 0), then for each spoke s and each vertex a = 1..R
// along it, (sharpness of segment (a-1)-a, semi-sharp count, semi-sharp sum, 0) at
// 1 + s·R + a - 1. From it the pass applies OpenSubdiv's rules (Sdc::Crease: dart, crease
// and corner masks, their fractional blends, uniform or Chaikin decay) at the centre and
// along the spokes, and writes the next level's data block. The same rules as
// `sharp_stencil` / `sharp_data` in src/subdiv/fragment.rs (there in f64, here in f32).
//
// Variants compiled from this file: refine_smooth.frag (positions, smooth masks only),
// refine.frag and refine_chaikin.frag (SHARP: positions with the sharp rules, uniform or
// Chaikin creasing) and refine_data.frag, refine_data_chaikin.frag (DATA: the data
// block). lavapipe runs every branch of a shader on every texel (SIMD lanes under masks),
// so code a texel does not need still costs it; each pass therefore draws three row
// ranges of its output, in one render pass: the runs without input data with the smooth
// variant, the others with a sharp one, and the data block (which starts on a row of its
// own) with a data one. A sharp variant computes smooth texels the same way.
//
// No integer division: like the GPUs of the era (and llvmpipe's SIMD code, which has no
// vector integer divide), quotients come from float division plus an exact correction.

// Entries of `runs` (the Rust side uploads exactly this many; see src/subdiv/gpu.rs).
#define MAX_RUNS 256
#define INFINITE 10.0

layout(set = 0, binding = 0) uniform sampler2D src;
// Per class run: (valence, flags, first input position texel, first output position
// texel); flags: 1 half-fan, 2 data in the input, 4 data in the output. And (first input
// data texel, first output data texel or -1, 0, 0).
layout(set = 0, binding = 1, std140) uniform Runs {
    ivec4 runs[MAX_RUNS];
    ivec4 data[MAX_RUNS];
} tab;
layout(push_constant) uniform Params {
    int r_in;         // ring radius of the input fragments
    int r_out;        // ring radius written by this pass
    int run_count;    // entries of tab.runs in use
    int positions_out; // position texels of the output stream
    int total_out;    // texels of the output stream (positions, padding, data)
    int log2_width;   // rows are 2^log2_width texels wide
} pc;
layout(location = 0) out vec4 result;

// The current fragment: valence, half-fan flag, first input position and data texels.
int K;
int E;
int BASE;
int DBASE;

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
    return fetch(BASE + entry(s, a, b)).xyz;
}

#if SHARP
// The data of vertex (a, 0) of spoke s, a >= 1 (sharp fragments only): segment
// (a-1)-a, semi-sharp count and sum.
vec4 spoke(int s, int a) {
    return fetch(DBASE + 1 + s * pc.r_in + a - 1);
}
#endif

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

// The 3 x 3 taps of smooth_point, T<3·row + column>: every position the sharp rules need
// is among them.
vec3 T0, T1, T2, T3, T4, T5, T6, T7, T8;

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
    T0 = at(s, ta.x, tb.x);
    T1 = at(s, ta.y, tb.x);
    T2 = at(s, ta.z, tb.x);
    T3 = at(s, ta.x, tb.y);
    T4 = at(s, ta.y, tb.y);
    T5 = at(s, ta.z, tb.y);
    T6 = at(s, ta.x, tb.z);
    T7 = at(s, ta.y, tb.z);
    T8 = at(s, ta.z, tb.z);
    return wb.x * (wa.x * T0 + wa.y * T1 + wa.z * T2) + wb.y * (wa.x * T3 + wa.y * T4 + wa.z * T5) +
           wb.z * (wa.x * T6 + wa.y * T7 + wa.z * T8);
}

#if SHARP
// ---- Sharpness (OpenSubdiv's Sdc::Crease), four values at a time ----

vec4 decrement4(vec4 s) {
    vec4 d = mix(s - 1.0, vec4(0.0), lessThanEqual(s, vec4(1.0)));
    return mix(d, vec4(INFINITE), greaterThanEqual(s, vec4(INFINITE)));
}

// Child sharpness of edges of sharpness s at a vertex whose semi-sharp edges count
// semi.x and sum semi.y (Chaikin: 3/4 of its own, 1/4 of the others' mean, minus 1).
vec4 child4(vec4 s, vec2 semi) {
#if CHAIKIN
    vec4 others = (vec4(semi.y) - s) / max(semi.x - 1.0, 1.0);
    vec4 c = (semi.x > 1.0) ? 0.75 * s + 0.25 * others : s;
    c = max(c - 1.0, vec4(0.0));
    c = mix(c, vec4(0.0), lessThanEqual(s, vec4(0.0)));
    return mix(c, vec4(INFINITE), greaterThanEqual(s, vec4(INFINITE)));
#else
    return decrement4(s);
#endif
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
#if CHAIKIN
    bvec4 gone = lessThanEqual(child, vec4(0.0));
#else
    bvec4 gone = lessThanEqual(parent, vec4(1.0));
#endif
    return vec4(greaterThan(parent, vec4(0.0))) * vec4(gone);
}

// Semi-sharp (count, sum) of four edges (absent ones are 0).
vec2 semi4(vec4 e) {
    vec4 semi = vec4(greaterThan(e, vec4(0.0))) * vec4(lessThan(e, vec4(INFINITE)));
    return vec2(dot(semi, vec4(1.0)), dot(semi, e));
}

// The centre's semi-sharp (count, sum): its spokes' first segments (Chaikin; set in main).
vec2 CENTRE_SEMI;

// Semi-sharp (count, sum) at vertex (a, 0) of spoke s, the centre for a = 0 (Chaikin).
vec2 semi_at(int s, int a) {
    return (a == 0) ? CENTRE_SEMI : spoke(s, a).yz;
}

// OpenSubdiv's vertex-vertex mask at a vertex p of sharpness vs: the parent's rule, and
// where it changes the child's, blended by the fractional weight. `sharp` and `csharp`
// count the sharp edges of parent and child, `ends` and `cends` sum their neighbours,
// `count` and `sum` the sharpness that decays (the vertex's added here); sm is the
// smooth point.
vec3 vertex_mask(vec3 p, float vs, float sharp, float csharp, vec3 ends, vec3 cends, float count, float sum, vec3 sm) {
    int pr = rule(vs, sharp);
    float cvs = decrement4(vec4(vs)).x;
    int cr = rule(cvs, csharp);
    vec3 pm = (pr == 2) ? 0.75 * p + 0.125 * ends : p;
    vec3 cm = (cr <= 1) ? sm : ((cr == 2) ? 0.75 * p + 0.125 * cends : p);
    if (vs > 0.0 && cvs <= 0.0) {
        count += 1.0;
        sum += vs;
    }
    float w = count > 0.0 ? min(sum / count, 1.0) : 0.0;
    return (pr <= 1) ? sm : ((cr == pr) ? pm : w * pm + (1.0 - w) * cm);
}

// The centre of a sharp fragment: the vertex mask over its spokes.
vec3 sharp_centre(vec3 sm) {
    float sharp = 0.0;
    float csharp = 0.0;
    float count = 0.0;
    float sum = 0.0;
    vec3 ends = vec3(0.0);
    vec3 cends = vec3(0.0);
    for (int s = 0; s < K + E; ++s) {
        float e = spoke(s, 1).x;
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
    return vertex_mask(at(0, 0, 0), fetch(DBASE).x, sharp, csharp, ends, cends, count, sum, sm);
}
#endif // SHARP

void main() {
    int lin = (int(gl_FragCoord.y) << pc.log2_width) + int(gl_FragCoord.x);
#if DATA
    bool valid = lin < pc.total_out;
#else
    bool valid = lin < pc.positions_out;
#endif
    if (!valid) {
        result = vec4(0.0);
        return;
    }
    // The class run holding this texel: the last one starting at or before it (position
    // starts, or data starts where runs without output data have -1).
    int lo = 0;
    int hi = pc.run_count - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) >> 1;
#if DATA
        int start = tab.data[mid].y;
#else
        int start = tab.runs[mid].w;
#endif
        if (start <= lin) {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    ivec4 run = tab.runs[lo];
    K = run.x;
    E = run.y & 1;
#if SHARP
    CENTRE_SEMI = vec2(0.0);
#if CHAIKIN
    // (Computed below once DBASE is known.)
#endif
#endif
#if DATA
    // A data texel: the centre's, or vertex a of spoke s.
    int dlen_out = 1 + (K + E) * pc.r_out;
    int u = lin - tab.data[lo].y;
    int frag = divide(u, dlen_out);
    int e = u - frag * dlen_out;
    DBASE = tab.data[lo].x + frag * (1 + (K + E) * pc.r_in);
#if CHAIKIN
    for (int k = 0; k < K + E; ++k) {
        CENTRE_SEMI += semi4(vec4(spoke(k, 1).x, 0.0, 0.0, 0.0));
    }
#endif
    int s = divide(max(e - 1, 0), pc.r_out);
    int a = e - s * pc.r_out;
    // Segment (a-1)-a: half of the parent segment (a+1)/2 at the parent vertex a/2 (a
    // even) or (a-1)/2 (a odd); the next segment a-(a+1) likewise.
    int end = a >> 1;
    float segment = child1(spoke(s, (a + 1) >> 1).x, semi_at(s, end));
    vec2 semi = vec2(0.0);
#if CHAIKIN
    int next_end = ((a & 1) == 0) ? end : end + 1;
    float next = child1(spoke(s, end + 1).x, semi_at(s, next_end));
    semi = semi4(vec4(segment, next, 0.0, 0.0));
#endif
    result = (e == 0) ? vec4(decrement4(vec4(fetch(DBASE).x)).x, 0.0, 0.0, 0.0) : vec4(segment, semi, 0.0);
#else
    int len_out = 1 + K * (pc.r_out + 1) * pc.r_out + E * pc.r_out;
    int len_in = 1 + K * (pc.r_in + 1) * pc.r_in + E * pc.r_in;
    int u = lin - run.w;
    int frag = divide(u, len_out);
    int i = u - frag * len_out;
    BASE = run.z + frag * len_in;
    DBASE = tab.data[lo].x + frag * (1 + (K + E) * pc.r_in);

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
    vec3 p = (i == 0) ? centre_point() : smooth_point(s, a, b);
#if SHARP
    if ((run.y & 2) != 0) {
#if CHAIKIN
        for (int k = 0; k < K + E; ++k) {
            CENTRE_SEMI += semi4(vec4(spoke(k, 1).x, 0.0, 0.0, 0.0));
        }
#endif
        // Along spoke s (b = 0): the vertex point of (x, 0), or the edge point of segment
        // (x, 0)-(x + 1, 0); taps 3, 4, 5 are (x - 1, 0), (x, 0), (x + 1, 0) for the
        // first, 4 and 5 are (x, 0), (x + 1, 0) for the second. Elsewhere every edge is
        // smooth.
        int x = a >> 1;
        vec4 d0 = spoke(s, max(x, 1));
        vec4 d1 = spoke(s, x + 1);
        vec2 semi0 = (x == 0) ? CENTRE_SEMI : d0.yz;
        vec3 q;
        if (i == 0) {
            q = sharp_centre(p);
        } else if ((a & 1) == 0) {
            // Segments x and x + 1 (none at x = 0: not a spoke vertex).
            vec4 e = vec4(d0.x, d1.x, 0.0, 0.0);
            vec4 c = child4(e, semi0);
            vec4 sharp = vec4(greaterThan(e, vec4(0.0)));
            vec4 csharp = vec4(greaterThan(c, vec4(0.0)));
            vec3 ends = sharp.x * T3 + sharp.y * T5;
            vec3 cends = csharp.x * T3 + csharp.y * T5;
            vec4 g = decays4(e, c);
            q = vertex_mask(T4, 0.0, dot(sharp, vec4(1.0)), dot(csharp, vec4(1.0)), ends, cends, dot(g, vec4(1.0)),
                            dot(g, e), p);
        } else {
            float pe = d1.x;
            vec3 mid = 0.5 * (T4 + T5);
            bool crease = child1(pe, semi0) > 0.0 && child1(pe, d1.yz) > 0.0;
            q = (pe <= 0.0) ? p : (crease ? mid : pe * mid + (1.0 - pe) * p);
        }
        p = (b == 0) ? q : p;
    }
#endif
    result = vec4(p, 1.0);
#endif
}

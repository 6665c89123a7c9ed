//! The CPU scanline rasterizer of a slice (§5.3.2 step 3) with the half-open rule of
//! `exact` (top-left, as Vulkan rasterizes): row k (z = k + ½) meets an edge iff
//! z_low ≤ z < z_high, and a centre x = i + ½ is covered iff x_left ≤ x < x_right. Each
//! edge's crossing is computed from the edge alone (ends ordered by z, then x), so a
//! centre on an edge shared by two triangles is flipped exactly once.

use super::volume::Volume;

/// The x where the edge p–q (ordered so that p.z < q.z) crosses z.
fn edge_x(p: [f64; 2], q: [f64; 2], z: f64) -> f64 {
    p[0] + (q[0] - p[0]) * ((z - p[1]) / (q[1] - p[1]))
}

/// First index i ≥ 0 with i + ½ ≥ v (i + ½ > v when `strict`), clamped to 0..=n.
fn first_centre(v: f64, n: usize) -> usize {
    (v - 0.5).ceil().clamp(0.0, n as f64) as usize
}

/// Flips every voxel centre of slice `j` that the triangle (grid units (x, z)) covers.
pub fn xor_triangle(volume: &mut Volume, j: usize, tri: [[f64; 2]; 3]) {
    let n = volume.n();
    triangle_spans(tri, n, |k, first, end| volume.xor_span(j, k, first, end));
}

/// The texel centres of an n×n grid that the triangle covers, row by row with the
/// half-open rule: `span(row, first, end)` for the centres `first..end` of each row.
pub fn triangle_spans(tri: [[f64; 2]; 3], n: usize, mut span: impl FnMut(usize, usize, usize)) {
    let mut v = tri;
    v.sort_by(|p, q| p[1].total_cmp(&q[1]).then(p[0].total_cmp(&q[0])));
    let [p0, p1, p2] = v;
    let (k0, k2) = (first_centre(p0[1], n), first_centre(p2[1], n));
    let k1 = first_centre(p1[1], n);
    for k in k0..k2 {
        let z = k as f64 + 0.5;
        let long = edge_x(p0, p2, z);
        let short = if k < k1 { edge_x(p0, p1, z) } else { edge_x(p1, p2, z) };
        let (lo, hi) = if long < short { (long, short) } else { (short, long) };
        span(k, first_centre(lo, n), first_centre(hi, n));
    }
}

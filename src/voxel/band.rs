//! The exact fallback (SPEC §0): a method that rasterizes in floating point (f64 on the
//! CPU, f32 and fixed-point snapping on the GPU) can misjudge a voxel centre only if the
//! centre lies within the method's error bound τ of the surface; those centres are found
//! conservatively and get the exact answer of the scanline classifier.
//!
//! Why only near the surface: the per-slice cross-sections of all tetras form a planar
//! arrangement in which every edge shared by two tetras (an apex face O–Q–R, or the
//! split diagonal of a quad) is computed by both from the same tetra edge with the same
//! formula, so the two copies are bit-identical and the rasterizer's shared-edge rule
//! covers each centre on them consistently; their flips cancel in pairs whatever the
//! rounding. Only the cross-sections of the covering triangles (the surface) are
//! unpaired, and the computed ones lie within τ of the exact ones. A centre farther than τ
//! (3D) from every covering triangle therefore gets the parity of the exact covering.
//!
//! The bound τ, in grid units (voxel side = 1), for coordinates up to M = 2N:
//! - f64 CPU rasterizers: τ = 2⁻³²·(N + 1) (rounding is ~2⁻⁵³·M per operation);
//! - GPU rasterizers: τ = 2·(√2·2⁻ˢ + 64·2⁻²⁴·M), with s the device's
//!   `subPixelPrecisionBits` (vertices snap to 2⁻ˢ pixels: √2·2⁻ˢ in 2D), and 64 f32
//!   roundings of magnitude M for the vertex coordinates, the interpolation along the
//!   tetra edge and the clip/viewport transforms; the factor 2 is margin.

use glam::DVec3;

use super::error::Result;
use super::grid::Grid;
use super::scanline;
use super::solid::Solid;
use super::volume::Volume;

/// τ for the f64 CPU rasterizers at resolution n.
pub fn tolerance_f64(n: usize) -> f64 {
    (n as f64 + 1.0) * 2f64.powi(-32)
}

/// τ for the GPU rasterizers at resolution n on a device snapping to `sub_pixel_bits`.
pub fn tolerance_gpu(n: usize, sub_pixel_bits: u32) -> f64 {
    let m = 2.0 * n as f64;
    2.0 * (std::f64::consts::SQRT_2 * 2f64.powi(-(sub_pixel_bits as i32)) + 64.0 * 2f64.powi(-24) * m)
}

/// What the fallback did.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct BandReport {
    /// τ in voxels.
    pub tolerance: f64,
    /// Voxel centres within τ of the surface (decided exactly).
    pub candidates: usize,
    /// Of those, how many the method had wrong.
    pub changed: usize,
}

/// Voxel centres within `tau` (grid units) of a covering triangle, as sorted unique keys
/// (row j·N + k) << 32 | i. Conservative: a few farther centres may be included.
pub fn near_surface(solid: &Solid, grid: &Grid, tau: f64) -> Vec<u64> {
    let n = grid.n;
    let tau = tau * (1.0 + 1e-6) + 1e-12 * n as f64;
    let mut keys = Vec::new();
    let index = |lo: f64, hi: f64| -> std::ops::Range<usize> {
        let first = (lo - 0.5).ceil().max(0.0);
        let last = (hi - 0.5).floor().min(n as f64 - 1.0);
        if first > last { 0..0 } else { first as usize..last as usize + 1 }
    };
    for tri in solid.grid_triangles(grid) {
        let (ylo, yhi) = (
            tri.iter().map(|p| p.y).fold(f64::INFINITY, f64::min),
            tri.iter().map(|p| p.y).fold(f64::NEG_INFINITY, f64::max),
        );
        for j in index(ylo - tau, yhi + tau) {
            let y = j as f64 + 0.5;
            let slab = clip(&tri, 1, y - tau, y + tau);
            let Some((zlo, zhi)) = extent(&slab, 2) else { continue };
            for k in index(zlo - tau, zhi + tau) {
                let z = k as f64 + 0.5;
                let strip = clip(&slab, 2, z - tau, z + tau);
                let Some((xlo, xhi)) = extent(&strip, 0) else { continue };
                for i in index(xlo - tau, xhi + tau) {
                    let p = DVec3::new(i as f64 + 0.5, y, z);
                    if distance_to_triangle(p, &tri) <= tau {
                        keys.push(((j * n + k) as u64) << 32 | i as u64);
                    }
                }
            }
        }
    }
    keys.sort_unstable();
    keys.dedup();
    keys
}

/// Replaces every voxel within `tau` of the surface by its exact value.
pub fn fix(volume: &mut Volume, solid: &Solid, grid: &Grid, tau: f64) -> Result<BandReport> {
    let keys = near_surface(solid, grid, tau);
    let mut report = BandReport { tolerance: tau, candidates: keys.len(), changed: 0 };
    if keys.is_empty() {
        return Ok(report);
    }
    let n = grid.n;
    let mut rows = vec![0u64; (n * n).div_ceil(64)];
    for &key in &keys {
        let row = (key >> 32) as usize;
        rows[row / 64] |= 1 << (row % 64);
    }
    let crossings = scanline::row_crossings(solid, grid, Some(&rows));
    let mut exact_row = vec![0u64; n.div_ceil(64)];
    let mut buf = Vec::new();
    let mut c = 0;
    for group in keys.chunk_by(|a, b| a >> 32 == b >> 32) {
        let row = (group[0] >> 32) as usize;
        while c < crossings.len() && (crossings[c].0 as usize) < row {
            c += 1;
        }
        buf.clear();
        while c < crossings.len() && crossings[c].0 as usize == row {
            buf.push(crossings[c].1);
            c += 1;
        }
        let (j, k) = (row / n, row % n);
        scanline::classify_row(solid, grid, j, k, &buf, &mut exact_row);
        for &key in group {
            let i = (key & 0xffff_ffff) as usize;
            let exact = exact_row[i / 64] >> (i % 64) & 1 == 1;
            if volume.get(i, j, k) != exact {
                volume.set(i, j, k, exact);
                report.changed += 1;
            }
        }
    }
    Ok(report)
}

/// The part of convex polygon `poly` with `lo ≤ p[axis] ≤ hi`.
fn clip(poly: &[DVec3], axis: usize, lo: f64, hi: f64) -> Vec<DVec3> {
    let half = |poly: &[DVec3], keep: &dyn Fn(f64) -> f64| -> Vec<DVec3> {
        // keep(v) ≥ 0 on the kept side.
        let mut out = Vec::with_capacity(poly.len() + 2);
        for (i, &p) in poly.iter().enumerate() {
            let q = poly[(i + 1) % poly.len()];
            let (dp, dq) = (keep(p[axis]), keep(q[axis]));
            if dp >= 0.0 {
                out.push(p);
            }
            if (dp >= 0.0) != (dq >= 0.0) {
                out.push(p + (q - p) * (dp / (dp - dq)));
            }
        }
        out
    };
    if poly.is_empty() {
        return Vec::new();
    }
    let above = half(poly, &|v| v - lo);
    if above.is_empty() {
        return above;
    }
    half(&above, &|v| hi - v)
}

fn extent(poly: &[DVec3], axis: usize) -> Option<(f64, f64)> {
    let lo = poly.iter().map(|p| p[axis]).fold(f64::INFINITY, f64::min);
    let hi = poly.iter().map(|p| p[axis]).fold(f64::NEG_INFINITY, f64::max);
    (lo <= hi).then_some((lo, hi))
}

/// Euclidean distance from p to a (possibly degenerate) triangle.
pub fn distance_to_triangle(p: DVec3, t: &[DVec3; 3]) -> f64 {
    let [a, b, c] = *t;
    let n = (b - a).cross(c - a);
    let nn = n.length_squared();
    let scale = (b - a).length_squared().max((c - a).length_squared());
    if nn > 1e-24 * scale * scale {
        let d = n.dot(p - a);
        let q = p - n * (d / nn);
        let inside = (b - a).cross(q - a).dot(n) >= 0.0
            && (c - b).cross(q - b).dot(n) >= 0.0
            && (a - c).cross(q - c).dot(n) >= 0.0;
        if inside {
            return d.abs() / nn.sqrt();
        }
    }
    segment_distance(p, a, b).min(segment_distance(p, b, c)).min(segment_distance(p, c, a))
}

fn segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let len = ab.length_squared();
    let t = if len > 0.0 { ((p - a).dot(ab) / len).clamp(0.0, 1.0) } else { 0.0 };
    (a + ab * t - p).length()
}

//! §5.2.1, scanline voxelization: a ray along +x through each row of voxel centres
//! (y_j, z_k); the parity of its crossings with the surface ahead of a centre says
//! inside or outside. Here it is exact: which triangles a row meets is decided with
//! exact predicates under the tie rule (`exact`), the crossing abscissae are computed in
//! f64 with a forward error bound, and a centre within that bound of a crossing is
//! settled by the exact predicate. It is also how every other method's doubtful voxels
//! get their exact answer (`band`).

use glam::DVec3;

use super::error::Result;
use super::exact::{self, Sign};
use super::grid::Grid;
use super::solid::Solid;
use super::volume::{Volume, slab_height, slab_lists, xor_bits};

/// A row of voxel centres, id j·N + k.
pub type RowId = u32;

/// One crossing of a row's line with a covering triangle.
#[derive(Clone, Copy, Debug)]
pub struct Crossing {
    /// Abscissa of the crossing (world units), accurate to `err`.
    pub x: f64,
    pub err: f64,
    pub triangle: u32,
    /// Orientation of the triangle seen along x (sign of its normal's x), never 0.
    pub nx: Sign,
}

/// The crossings of every row (or of the rows `filter` accepts), grouped by row and
/// sorted by x within a row.
pub fn row_crossings(solid: &Solid, grid: &Grid, filter: Option<&[u64]>) -> Vec<(RowId, Crossing)> {
    let mut out = Vec::new();
    crossings_into(solid, grid, 0..solid.triangles.len() as u32, 0..grid.n, filter, &mut out);
    out
}

/// The crossings of `triangles` with the rows of slices `slices` (and `filter`), sorted
/// by row, then x, then triangle (a total order: the same list whatever the order the
/// triangles come in).
fn crossings_into(
    solid: &Solid,
    grid: &Grid,
    triangles: impl Iterator<Item = u32>,
    slices: std::ops::Range<usize>,
    filter: Option<&[u64]>,
    out: &mut Vec<(RowId, Crossing)>,
) {
    let n = grid.n;
    let h = grid.h();
    let wanted = |row: usize| filter.is_none_or(|bits| bits[row / 64] >> (row % 64) & 1 == 1);
    for t in triangles {
        let tri = &solid.triangles[t as usize];
        let [a, b, c] = *tri;
        let nx = exact::orient2d([a.y, a.z], [b.y, b.z], [c.y, c.z]);
        if nx == 0 {
            continue;
        }
        let (ylo, yhi) = (a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y));
        let js = index_range(grid.min.y, h, n, ylo, yhi);
        for j in js.start.max(slices.start)..js.end.min(slices.end) {
            let y = grid.centre_coord(grid.min.y, j);
            if y < ylo || y > yhi {
                continue;
            }
            let Some((zlo, zhi)) = z_extent_at(tri, y) else { continue };
            let margin = 1e-9 * (zlo.abs() + zhi.abs() + h);
            for k in index_range(grid.min.z, h, n, zlo - margin, zhi + margin) {
                let row = j * n + k;
                if !wanted(row) {
                    continue;
                }
                let p = DVec3::new(0.0, y, grid.centre_coord(grid.min.z, k));
                if exact::inside_yz(a, b, c, p, nx) {
                    let (x, err) = x_crossing(a, b, c, y, p.z);
                    out.push((row as RowId, Crossing { x, err, triangle: t, nx }));
                }
            }
        }
    }
    out.sort_unstable_by(|(r0, c0), (r1, c1)| {
        r0.cmp(r1).then(c0.x.total_cmp(&c1.x)).then(c0.triangle.cmp(&c1.triangle))
    });
}

/// Indices i (clamped to 0..n) whose centres may lie in [lo, hi], with one index of
/// margin on each side; callers decide each one exactly.
fn index_range(min: f64, h: f64, n: usize, lo: f64, hi: f64) -> std::ops::Range<usize> {
    let first = ((lo - min) / h - 0.5).ceil() - 1.0;
    let last = ((hi - min) / h - 0.5).floor() + 1.0;
    if last.is_nan() || first.is_nan() || last < 0.0 || first >= n as f64 || first > last {
        return 0..0;
    }
    (first.max(0.0) as usize)..((last + 1.0).min(n as f64) as usize)
}

/// The z extent of the triangle's (y, z) projection on the line y = `y` (approximate).
fn z_extent_at(tri: &[DVec3; 3], y: f64) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (p, q) in [(tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])] {
        let (ylo, yhi) = (p.y.min(q.y), p.y.max(q.y));
        if y < ylo || y > yhi {
            continue;
        }
        if p.y == q.y {
            lo = lo.min(p.z.min(q.z));
            hi = hi.max(p.z.max(q.z));
        } else {
            let z = p.z + (q.z - p.z) * ((y - p.y) / (q.y - p.y));
            lo = lo.min(z);
            hi = hi.max(z);
        }
    }
    (lo <= hi).then_some((lo, hi))
}

/// Abscissa where the line (y, z) along x meets the plane of abc, with a bound on its
/// rounding error (infinite when the plane is too close to parallel to x to tell).
pub fn x_crossing(a: DVec3, b: DVec3, c: DVec3, y: f64, z: f64) -> (f64, f64) {
    const EPS: f64 = f64::EPSILON * 0.5;
    let (u, v) = (b - a, c - a);
    let nx = u.y * v.z - u.z * v.y;
    let ny = u.z * v.x - u.x * v.z;
    let nz = u.x * v.y - u.y * v.x;
    let (px, py, pz) = (
        (u.y * v.z).abs() + (u.z * v.y).abs(),
        (u.z * v.x).abs() + (u.x * v.z).abs(),
        (u.x * v.y).abs() + (u.y * v.x).abs(),
    );
    let (dy, dz) = (y - a.y, z - a.z);
    let num = ny * dy + nz * dz;
    let q = num / nx;
    let x = a.x - q;
    // Each product of rounded differences is within 4ε of its permanent; the sums,
    // quotient and final difference add a few ε more. Doubled for margin.
    let e_nx = 4.0 * EPS * px;
    let e_num = 8.0 * EPS * (py * dy.abs() + pz * dz.abs());
    if nx.abs() <= 2.0 * e_nx || nx.is_nan() || !x.is_finite() {
        return (x, f64::INFINITY);
    }
    let err = (e_num + q.abs() * e_nx) / (nx.abs() - e_nx) + 4.0 * EPS * (q.abs() + x.abs() + a.x.abs());
    (x, 2.0 * err)
}

/// Smallest i in 0..=n whose centre x satisfies `pred` (`pred` monotone: false…true).
fn first_index(grid: &Grid, pred: impl Fn(f64) -> bool) -> usize {
    let (mut lo, mut hi) = (0usize, grid.n);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if pred(grid.centre_coord(grid.min.x, mid)) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    lo
}

/// Writes the exact occupancy of row (j, k) into `row` (its words, cleared first), from
/// the row's crossings.
pub fn classify_row(solid: &Solid, grid: &Grid, j: usize, k: usize, crossings: &[Crossing], row: &mut [u64]) {
    row.fill(0);
    let (y, z) = (grid.centre_coord(grid.min.y, j), grid.centre_coord(grid.min.z, k));
    for c in crossings {
        // Centres certainly before the crossing see it ahead: flip them all at once.
        let certain_end = first_index(grid, |x| x >= c.x - c.err);
        if certain_end > 0 {
            xor_bits(row, 0, certain_end);
        }
        let doubt_end = if c.err.is_finite() { first_index(grid, |x| x > c.x + c.err) } else { grid.n };
        let [a, b, t] = solid.triangles[c.triangle as usize];
        for i in certain_end..doubt_end {
            let p = DVec3::new(grid.centre_coord(grid.min.x, i), y, z);
            if exact::crossing_ahead(a, b, t, p, c.nx) {
                row[i / 64] ^= 1 << (i % 64);
            }
        }
    }
}

/// The scanline method: every row classified exactly. Slabs of slices run in parallel
/// (rayon's global pool), each from the triangles that reach it; a row's crossings and
/// its words belong to one slab, so the volume is the same for any number of threads.
pub fn voxelize(solid: &Solid, grid: &Grid) -> Result<Volume> {
    let n = grid.n;
    let mut volume = Volume::new(n)?;
    let h = grid.h();
    let slab = slab_height(n);
    let lists = slab_lists(
        n,
        slab,
        solid
            .triangles
            .iter()
            .map(|[a, b, c]| index_range(grid.min.y, h, n, a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y))),
    );
    volume.par_slabs(slab, |mut s| {
        let slices = s.slices();
        let mut crossings = Vec::new();
        crossings_into(solid, grid, lists[s.j0 / slab].iter().copied(), slices, None, &mut crossings);
        let mut buf: Vec<Crossing> = Vec::new();
        for group in crossings.chunk_by(|a, b| a.0 == b.0) {
            let row = group[0].0 as usize;
            buf.clear();
            buf.extend(group.iter().map(|(_, c)| *c));
            let (j, k) = (row / n, row % n);
            classify_row(solid, grid, j, k, &buf, s.row_mut(j, k));
        }
    });
    Ok(volume)
}

//! §5.2.1, scanline voxelization: a ray along +x through each row of voxel centres
//! (y_j, z_k); the parity of its crossings with the surface ahead of a centre says
//! inside or outside. Here it is exact: which triangles a row meets is decided with
//! exact predicates under the tie rule (`exact`), the crossing abscissae are computed in
//! f64 with a forward error bound, and a centre within that bound of a crossing is
//! settled by the exact predicate. It is also how every other method's doubtful voxels
//! get their exact answer (`band`).

use glam::DVec3;

use super::error::Result;
use super::exact;
use super::grid::Grid;
use super::solid::Solid;
use super::volume::{Volume, slab_height, slab_lists, xor_bits};
use crate::exact::{Sign, orient2d};

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
    let wanted = |j: usize, k: usize| {
        let row = j * n + k;
        filter.is_none_or(|bits| bits[row / 64] >> (row % 64) & 1 == 1)
    };
    for t in triangles {
        let all = (f64::NEG_INFINITY, f64::INFINITY);
        triangle_crossings(solid, grid, t, slices.clone(), 0..n, all, wanted, |j, k, c| {
            out.push(((j * n + k) as RowId, c))
        });
    }
    out.sort_unstable_by(|(r0, c0), (r1, c1)| {
        r0.cmp(r1).then(c0.x.total_cmp(&c1.x)).then(c0.triangle.cmp(&c1.triangle))
    });
}

/// The signed steps of the winding number of `solid`'s triangles along the rows of slices
/// `slices`, for a *closed chain* (every directed edge used as often as its reverse; the
/// triangles may cross each other): `(row, f, s)`, sorted by row then f, says that centres
/// f.. of the row see one more crossing behind them, whose sign is s (f = N: behind no
/// centre). Entering a triangle's back side along +x raises the winding number by one, so
/// s = −nx; with the tie rule the winding number at centre i, exactly, is the sum of the
/// row's s over f ≤ i, and a row's s sum to 0.
pub fn winding_steps(
    solid: &Solid,
    grid: &Grid,
    triangles: impl Iterator<Item = u32>,
    slices: std::ops::Range<usize>,
    out: &mut Vec<(RowId, u32, Sign)>,
) {
    let n = grid.n;
    let all = (f64::NEG_INFINITY, f64::INFINITY);
    for t in triangles {
        triangle_crossings(
            solid,
            grid,
            t,
            slices.clone(),
            0..n,
            all,
            |_, _| true,
            |j, k, c| {
                let f = first_behind(solid, grid, j, k, &c, doubt(grid, &c));
                out.push(((j * n + k) as RowId, f as u32, -c.nx));
            },
        );
    }
    out.sort_unstable_by_key(|&(row, f, _)| (row, f));
}

/// Calls `each(j, k, crossing)` for every row (j, k) with j in `slices`, k in `columns`
/// and `wanted(j, k)` whose line meets covering triangle `t` (decided exactly, under the
/// tie rule) at an abscissa that may lie in `window` (rows whose crossing is certainly
/// outside it may be left out).
#[allow(clippy::too_many_arguments)]
fn triangle_crossings(
    solid: &Solid,
    grid: &Grid,
    t: u32,
    slices: std::ops::Range<usize>,
    columns: std::ops::Range<usize>,
    window: (f64, f64),
    wanted: impl Fn(usize, usize) -> bool,
    mut each: impl FnMut(usize, usize, Crossing),
) {
    let (n, h) = (grid.n, grid.h());
    let tri = &solid.triangles[t as usize];
    let [a, b, c] = *tri;
    let (ylo, yhi) = (a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y));
    let js = index_range(grid.min.y, h, n, ylo, yhi);
    let (js, ks) = (js.start.max(slices.start)..js.end.min(slices.end), columns);
    let (zlo, zhi) = (a.z.min(b.z).min(c.z), a.z.max(b.z).max(c.z));
    let all_ks = index_range(grid.min.z, h, n, zlo, zhi);
    if js.is_empty() || all_ks.end <= ks.start || all_ks.start >= ks.end {
        return;
    }
    let nx = orient2d([a.y, a.z], [b.y, b.z], [c.y, c.z]);
    if nx == 0 {
        return;
    }
    // With a window, a triangle that is not too steep along x is only visited on the
    // strip of rows where its plane's abscissa, x = a.x − (ny·(y − a.y) + nz·(z − a.z))/nx,
    // is within the window grown by two voxels: far more than the f64 error of that
    // formula (|n.x| ≥ 10⁻³·|n|₁) or of any crossing's own bound. A steep triangle has
    // few rows anyway: its (y, z) projection is small.
    let normal = (b - a).cross(c - a);
    let strip =
        (window.0.is_finite() || window.1.is_finite()) && normal.x.abs() >= 1e-3 * normal.abs().element_sum();
    let grown = 2.0 * h + 1e-9 * (grid.min.x.abs() + grid.side);
    let (wlo, whi) = (window.0 - grown, window.1 + grown);
    for j in js {
        let y = grid.centre_coord(grid.min.y, j);
        if y < ylo || y > yhi {
            continue;
        }
        let Some((mut zlo, mut zhi)) = z_extent_at(tri, y) else { continue };
        if strip {
            let u = normal.y * (y - a.y);
            if normal.z.abs() <= 1e-12 * normal.abs().element_sum() {
                // x does not depend on z along this row.
                let x = a.x - u / normal.x;
                if x < wlo || x > whi {
                    continue;
                }
            } else {
                let z_at = |x: f64| a.z + ((a.x - x) * normal.x - u) / normal.z;
                let (z0, z1) = (z_at(wlo), z_at(whi));
                zlo = zlo.max(z0.min(z1));
                zhi = zhi.min(z0.max(z1));
                if zlo > zhi {
                    continue;
                }
            }
        }
        let margin = 1e-9 * (zlo.abs() + zhi.abs() + h);
        let row_ks = index_range(grid.min.z, h, n, zlo - margin, zhi + margin);
        for k in row_ks.start.max(ks.start)..row_ks.end.min(ks.end) {
            if !wanted(j, k) {
                continue;
            }
            let p = DVec3::new(0.0, y, grid.centre_coord(grid.min.z, k));
            if exact::inside_yz(a, b, c, p, nx) {
                let (x, err) = x_crossing(a, b, c, y, p.z);
                each(j, k, Crossing { x, err, triangle: t, nx });
            }
        }
    }
}

/// Indices i (clamped to 0..n) whose centres may lie in [lo, hi], with one index of
/// margin on each side; callers decide each one exactly.
pub(crate) fn index_range(min: f64, h: f64, n: usize, lo: f64, hi: f64) -> std::ops::Range<usize> {
    let (first, last) = index_bounds(min, h, lo, hi);
    if last.is_nan() || first.is_nan() || last < 0.0 || first >= n as f64 || first > last {
        return 0..0;
    }
    (first.max(0.0) as usize)..((last + 1.0).min(n as f64) as usize)
}

/// The unclamped first and last indices of [`index_range`]: the centre of `first` is
/// certainly below `lo`, that of `last` certainly above `hi`.
fn index_bounds(min: f64, h: f64, lo: f64, hi: f64) -> (f64, f64) {
    (((lo - min) / h - 0.5).ceil() - 1.0, ((hi - min) / h - 0.5).floor() + 1.0)
}

/// The z extent of the triangle's (y, z) projection on the line y = `y` (approximate).
pub(crate) fn z_extent_at(tri: &[DVec3; 3], y: f64) -> Option<(f64, f64)> {
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

/// The centres (indices along x) a crossing's f64 abscissa cannot place: those before
/// the range certainly see it ahead, those after certainly behind.
fn doubt(grid: &Grid, c: &Crossing) -> std::ops::Range<usize> {
    let certain_end = first_index(grid, |x| x >= c.x - c.err);
    let doubt_end = if c.err.is_finite() { first_index(grid, |x| x > c.x + c.err) } else { grid.n };
    certain_end..doubt_end.max(certain_end)
}

/// The first centre of row (j, k) that crossing `c` is not ahead of, searched in
/// `doubt` (from [`doubt`]) with the exact predicate: the crossing flips the parity of
/// centres 0..f and no other. (Seen from a centre moving along +x, a crossing is ahead
/// until it is passed, so the predicate is monotone and a bisection finds the change.)
fn first_behind(
    solid: &Solid,
    grid: &Grid,
    j: usize,
    k: usize,
    c: &Crossing,
    doubt: std::ops::Range<usize>,
) -> usize {
    let (y, z) = (grid.centre_coord(grid.min.y, j), grid.centre_coord(grid.min.z, k));
    let [a, b, t] = solid.triangles[c.triangle as usize];
    let (mut lo, mut hi) = (doubt.start, doubt.end);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if exact::crossing_ahead(a, b, t, DVec3::new(grid.centre_coord(grid.min.x, mid), y, z), c.nx) {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Writes the exact occupancy of row (j, k) into `row` (its words, cleared first), from
/// the row's crossings.
pub fn classify_row(solid: &Solid, grid: &Grid, j: usize, k: usize, crossings: &[Crossing], row: &mut [u64]) {
    row.fill(0);
    for c in crossings {
        let f = first_behind(solid, grid, j, k, c, doubt(grid, c));
        if f > 0 {
            xor_bits(row, 0, f);
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

/// x planes per batch of [`x_planes`]: 16 planes of 1024² bits are 2 MiB, and a
/// triangle only spans a second batch when it is wider than a few voxels.
const BATCH: usize = 16;

/// Planes of the scanline volume handed out by [`x_planes`]: plane p is the voxels with
/// x = x0 + p, row k of a plane holds z = k, bit j of the row y = j.
pub struct Planes<'a> {
    n: usize,
    wpr: usize,
    planes: usize,
    /// Planes stored per row: `planes` and room for more.
    stride: usize,
    /// Words by row k, then plane, then word: one task owns a band of rows in every plane.
    words: &'a [u64],
}

impl Planes<'_> {
    /// Number of planes.
    pub fn len(&self) -> usize {
        self.planes
    }

    pub fn is_empty(&self) -> bool {
        self.planes == 0
    }

    /// Row k of plane p: the voxels (x0 + p, j, k) as bits j.
    pub fn row(&self, p: usize, k: usize) -> &[u64] {
        let s = (k * self.stride + p) * self.wpr;
        &self.words[s..s + self.wpr]
    }

    /// Voxels per row (N).
    pub fn n(&self) -> usize {
        self.n
    }
}

/// The scanline volume in binvox's order, x plane by x plane, without the whole volume
/// in memory: `emit` gets the planes in order, a batch at a time, and the count of
/// occupied voxels is returned.
///
/// Here a centre's parity counts the crossings *behind* it (those it is not ahead of), so
/// x planes can be finished in increasing x: each row carries its parity from batch to
/// batch, and a crossing only flips the row at the first centre it is behind. For a
/// closed, consistently oriented covering every row line meets the surface an even
/// number of times (the tie rule perturbs lines off edges and vertices), so that parity is
/// the one [`voxelize`] computes from the crossings ahead. The last batch checks it: a
/// row whose crossings are odd in number makes this return [`OddRow`] (as the error's
/// inner error), so the caller can fall back to [`voxelize`].
///
/// Each batch is computed by tasks that own bands of rows (rayon's global pool) and whose
/// flips commute, so the planes do not depend on the number of threads.
pub fn x_planes(
    solid: &Solid,
    grid: &Grid,
    mut emit: impl FnMut(&Planes<'_>) -> std::io::Result<()>,
) -> std::io::Result<u64> {
    use rayon::prelude::*;
    let (n, h) = (grid.n, grid.h());
    let wpr = n.div_ceil(64);
    // The centres a triangle's crossings can first be behind: its x range with the margin
    // of `index_range` (the centre before it is ahead of any crossing, the one after
    // behind); crossings beyond the last centre are counted at N.
    let behind = |t: u32| {
        let [a, b, c] = solid.triangles[t as usize];
        let (first, last) = index_bounds(grid.min.x, h, a.x.min(b.x).min(c.x), a.x.max(b.x).max(c.x));
        (first.clamp(0.0, n as f64) as usize, last.clamp(0.0, n as f64) as usize)
    };
    // Triangles in order of their first centre (ties in index order).
    let mut order: Vec<u32> = (0..solid.triangles.len() as u32).collect();
    order.sort_by_cached_key(|&t| behind(t).0);
    let mut next = 0;
    let mut active: Vec<u32> = Vec::new();
    let stride = BATCH + 1;
    let mut words = vec![0u64; n * stride * wpr];
    let mut carry = vec![0u64; n * wpr];
    // Bands of rows: enough for every thread to stay busy when bands differ in work.
    let band = n.div_ceil(8 * rayon::current_num_threads()).max(1);
    let mut occupied = 0;
    for x0 in (0..n).step_by(BATCH) {
        let x1 = (x0 + BATCH).min(n);
        // Crossings first behind a centre in x0..=last belong to this batch; in the last
        // batch, those behind no centre (f = N) go to plane x1 - x0, for the parity check.
        let last = if x1 == n { n } else { x1 - 1 };
        while next < order.len() && behind(order[next]).0 <= last {
            active.push(order[next]);
            next += 1;
        }
        active.retain(|&t| behind(t).1 >= x0);
        // Which band of rows each active triangle reaches (its z range).
        let lists = slab_lists(
            n,
            band,
            active.iter().map(|&t| {
                let [a, b, c] = solid.triangles[t as usize];
                index_range(grid.min.z, h, n, a.z.min(b.z).min(c.z), a.z.max(b.z).max(c.z))
            }),
        );
        let planes = x1 - x0;
        // Crossings this batch takes lie between the centre before x0 and centre `last`.
        let window = (
            if x0 == 0 { f64::NEG_INFINITY } else { grid.centre_coord(grid.min.x, x0 - 1) },
            if last == n { f64::INFINITY } else { grid.centre_coord(grid.min.x, last) },
        );
        let (odd, count) = words
            .par_chunks_mut(band * stride * wpr)
            .zip(carry.par_chunks_mut(band * wpr))
            .enumerate()
            .map(|(b, (rows, carry))| {
                rows.fill(0);
                let ks = b * band..(b * band + band).min(n);
                for &t in lists[b].iter().map(|&i| &active[i as usize]) {
                    triangle_crossings(
                        solid,
                        grid,
                        t,
                        0..n,
                        ks.clone(),
                        window,
                        |_, _| true,
                        |j, k, c| {
                            let d = doubt(grid, &c);
                            if d.end < x0 || d.start > last {
                                return;
                            }
                            let f = first_behind(solid, grid, j, k, &c, d);
                            if (x0..=last).contains(&f) {
                                rows[((k - ks.start) * stride + f - x0) * wpr + j / 64] ^= 1 << (j % 64);
                            }
                        },
                    );
                }
                let mut odd = false;
                let mut count = 0u64;
                for (row, carry) in rows.chunks_exact_mut(stride * wpr).zip(carry.chunks_exact_mut(wpr)) {
                    for p in 0..planes {
                        for (w, c) in row[p * wpr..(p + 1) * wpr].iter_mut().zip(carry.iter_mut()) {
                            *c ^= *w;
                            *w = *c;
                            count += c.count_ones() as u64;
                        }
                    }
                    if x1 == n {
                        odd |= row[planes * wpr..(planes + 1) * wpr] != *carry;
                    }
                }
                (odd, count)
            })
            .reduce(|| (false, 0), |a, b| (a.0 | b.0, a.1 + b.1));
        if odd {
            return Err(std::io::Error::other(OddRow));
        }
        occupied += count;
        emit(&Planes { n, wpr, planes, stride, words: &words })?;
    }
    Ok(occupied)
}

/// A row line met the covering an odd number of times: [`x_planes`] cannot finish its
/// volume (the covering is not closed where the tie rule looks).
#[derive(Debug, thiserror::Error)]
#[error("a row of voxel centres meets the surface an odd number of times")]
pub struct OddRow;

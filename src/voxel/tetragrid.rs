//! Conservative rasterization (§5.5.1, SPEC §4.4) and the TetraGrid it builds (SPEC §3.2
//! item 4): for the point-in-solid optimizer every grid cell must list every tetra that
//! intersects it. Standard rasterization does not guarantee that, so each tetra is
//! enlarged — its four face planes moved outward by an offset, its vertices recomputed as
//! intersections of the moved planes — and the enlarged tetra is rasterized with
//! "append id" instead of XOR: slice by slice and row by row, a cell is appended when its
//! centre lies inside all four moved planes (and inside the tetra's bounding box grown by
//! the offset, which keeps slivers' far-flung recomputed vertices in check).
//!
//! Why it is conservative: a tetra that meets a cell has a point within half a cell
//! diagonal (h√3/2) of the cell's centre, so the centre lies in the tetra grown by that
//! distance, which the moved planes contain. The thesis (and SPEC §4.4) move the planes
//! by twice the voxel diagonal ([`SPEC_OFFSET`]); half a diagonal ([`MIN_OFFSET`]) is
//! already enough when cells are sampled at their centres. Tighter still,
//! [`Growth::CellBox`] moves each plane by the cell's half extent along that plane's
//! normal (h/2·(|nx|+|ny|+|nz|)): a cell meets a half-space exactly when its centre is
//! inside the half-space moved that much, so no touched cell is lost and cells beside
//! axis-aligned faces are not added.
//!
//! Cells are numbered like the voxel volume: (j·N + k)·N + i.

use glam::DVec3;

use super::error::{Result, VoxelError};
use super::grid::{Grid, check_memory};

/// The plane offset SPEC §4.4 asks for, in voxel diagonals.
pub const SPEC_OFFSET: f64 = 2.0;

/// The smallest offset that is conservative for centre sampling, in voxel diagonals.
pub const MIN_OFFSET: f64 = 0.5;

/// How far the rasterized tetra is grown beyond the real one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Growth {
    /// Every plane (and the bounding box) moved by this many cell diagonals (§5.5.1).
    Diagonals(f64),
    /// Every plane moved by the cell's half extent along its normal, plus `extra` (world
    /// units); the box by half a cell plus `extra`.
    CellBox { extra: f64 },
}

impl Growth {
    /// (offset of a plane with unit normal `n`, growth of the box), world units.
    fn amounts(self, cell: f64, n: DVec3) -> (f64, f64) {
        match self {
            Growth::Diagonals(d) => (d * cell * 3f64.sqrt(), d * cell * 3f64.sqrt()),
            Growth::CellBox { extra } => (0.5 * cell * n.abs().element_sum() + extra, 0.5 * cell + extra),
        }
    }
}

/// The index of cell (i, j, k).
pub fn cell_index(n: usize, i: usize, j: usize, k: usize) -> usize {
    (j * n + k) * n + i
}

/// The cell that contains `p` (cells are closed on their low side; the cube's high faces
/// belong to the last cells), or `None` outside the cube.
pub fn cell_of(grid: &Grid, p: DVec3) -> Option<usize> {
    let u = grid.to_grid(p);
    let n = grid.n as f64;
    if !(u.cmpge(DVec3::ZERO).all() && u.cmple(DVec3::splat(n)).all()) {
        return None;
    }
    let c = |x: f64| (x.floor() as usize).min(grid.n - 1);
    Some(cell_index(grid.n, c(u.x), c(u.y), c(u.z)))
}

/// The face planes of tetra `t` as (outward unit normal, offset d): inside is n·x ≤ d.
/// `None` for a (nearly) flat tetra.
pub fn face_planes(t: &[DVec3; 4]) -> Option<[(DVec3, f64); 4]> {
    let scale = (0..4)
        .flat_map(|a| (a + 1..4).map(move |b| (a, b)))
        .map(|(a, b)| t[a].distance(t[b]))
        .fold(0.0, f64::max);
    let volume6 = (t[1] - t[0]).dot((t[2] - t[0]).cross(t[3] - t[0]));
    if volume6.is_nan() || volume6.abs() <= 1e-9 * scale * scale * scale {
        return None;
    }
    let mut planes = [(DVec3::ZERO, 0.0); 4];
    for (v, plane) in planes.iter_mut().enumerate() {
        let [a, b, c] = [t[(v + 1) % 4], t[(v + 2) % 4], t[(v + 3) % 4]];
        let mut n = (b - a).cross(c - a).normalize();
        if n.dot(t[v] - a) > 0.0 {
            n = -n; // point away from the opposite vertex
        }
        *plane = (n, n.dot(a));
    }
    Some(planes)
}

/// The enlarged tetra of §5.5.1: every face plane moved outward by `offset`, the vertices
/// recomputed as intersections of three moved planes. `None` for a flat tetra.
pub fn enlarge(t: &[DVec3; 4], offset: f64) -> Option<[DVec3; 4]> {
    let planes = face_planes(t)?;
    let moved = planes.map(|(n, d)| (n, d + offset));
    let mut out = [DVec3::ZERO; 4];
    for (v, vertex) in out.iter_mut().enumerate() {
        // Vertex v is where the three planes not opposite to it meet.
        let [(n0, d0), (n1, d1), (n2, d2)] = [moved[(v + 1) % 4], moved[(v + 2) % 4], moved[(v + 3) % 4]];
        let det = n0.dot(n1.cross(n2));
        if det.abs() < 1e-12 {
            return None;
        }
        *vertex = (n1.cross(n2) * d0 + n2.cross(n0) * d1 + n0.cross(n1) * d2) / det;
    }
    Some(out)
}

/// Appends to `out` every cell the tetra `t` (world coordinates) may touch: the cells
/// whose centres the enlarged tetra covers. A flat tetra gets the cells of its grown
/// bounding box.
pub fn cells(grid: &Grid, t: &[DVec3; 4], growth: Growth, out: &mut Vec<u32>) {
    let n = grid.n;
    for_each_cell(grid.min, grid.h(), n, t, growth, |i, j, k| out.push(cell_index(n, i, j, k) as u32));
}

/// The conservative rasterizer itself, for any n³ grid of cubic cells of side `cell`
/// whose minimum corner is `origin` (so other grids, like the inclusion TetraGrid's, can
/// use it): calls `f(i, j, k)` for every cell whose centre lies inside the tetra `t` grown
/// by `growth` (its face planes moved outward) and inside its grown bounding box. With
/// [`Growth::CellBox`] or at least [`MIN_OFFSET`] diagonals every cell `t` touches is
/// visited.
pub fn for_each_cell(
    origin: DVec3,
    cell: f64,
    n: usize,
    t: &[DVec3; 4],
    growth: Growth,
    f: impl FnMut(usize, usize, usize),
) {
    let lo = t.iter().fold(DVec3::INFINITY, |m, &p| m.min(p));
    let hi = t.iter().fold(DVec3::NEG_INFINITY, |m, &p| m.max(p));
    for_each_cell_planes(origin, cell, n, face_planes(t).as_ref(), (lo, hi), growth, f);
}

/// The same rasterizer for a tetra given by its four face planes — (outward unit normal,
/// d), inside n·x ≤ d, `None` for a flat tetra — and its bounding box: the form other
/// modules keep their tetras in.
pub fn for_each_cell_planes(
    origin: DVec3,
    cell: f64,
    n: usize,
    planes: Option<&[(DVec3, f64); 4]>,
    (lo, hi): (DVec3, DVec3),
    growth: Growth,
    mut f: impl FnMut(usize, usize, usize),
) {
    let grow = growth.amounts(cell, DVec3::ZERO).1;
    let lo = lo - DVec3::splat(grow);
    let hi = hi + DVec3::splat(grow);
    // Rounding slack, far below any cell size.
    let slack = 1e-9 * (hi - lo).max_element().max(cell);
    let planes = planes.map(|p| p.map(|(nrm, d)| (nrm, d + growth.amounts(cell, nrm).0 + slack)));
    let range = |min: f64, a: f64, b: f64| -> std::ops::Range<usize> {
        let first = ((a - slack - min) / cell - 0.5).ceil().max(0.0);
        let last = ((b + slack - min) / cell - 0.5).floor().min(n as f64 - 1.0);
        if first > last { 0..0 } else { first as usize..last as usize + 1 }
    };
    let centre = |min: f64, i: usize| min + (i as f64 + 0.5) * cell;
    for j in range(origin.y, lo.y, hi.y) {
        let y = centre(origin.y, j);
        for k in range(origin.z, lo.z, hi.z) {
            let z = centre(origin.z, k);
            // The x interval of the row inside all four moved planes.
            let (mut xa, mut xb) = (lo.x, hi.x);
            if let Some(planes) = &planes {
                for &(nrm, d) in planes {
                    let rhs = d - nrm.y * y - nrm.z * z;
                    if nrm.x.abs() > 1e-12 {
                        let x = rhs / nrm.x;
                        if nrm.x > 0.0 { xb = xb.min(x) } else { xa = xa.max(x) }
                    } else if rhs < 0.0 {
                        xb = f64::NEG_INFINITY;
                    }
                }
            }
            if xa <= xb {
                for i in range(origin.x, xa, xb) {
                    f(i, j, k);
                }
            }
        }
    }
}

/// The cell → tetras lists (CSR) of a grid.
#[derive(Clone, Debug)]
pub struct TetraGrid {
    pub grid: Grid,
    /// Cell c lists `tetras[offsets[c]..offsets[c + 1]]`, ascending.
    pub offsets: Vec<u32>,
    pub tetras: Vec<u32>,
}

impl TetraGrid {
    /// Conservatively rasterizes every tetra (world coordinates) into `grid`'s cells
    /// (`Growth::Diagonals(SPEC_OFFSET)` is SPEC §4.4's choice).
    pub fn build(grid: &Grid, tetras: &[[DVec3; 4]], growth: Growth) -> Result<TetraGrid> {
        let cells_total = grid.voxels();
        check_memory("the TetraGrid cell offsets", grid.n, (cells_total + 1) * 4)?;
        let mut counts = vec![0u32; cells_total as usize + 1];
        let mut buf = Vec::new();
        let mut total = 0u64;
        for t in tetras {
            buf.clear();
            cells(grid, t, growth, &mut buf);
            total += buf.len() as u64;
            for &c in &buf {
                counts[c as usize + 1] += 1;
            }
        }
        if total > u32::MAX as u64 {
            return Err(VoxelError::Usage(format!(
                "the TetraGrid would hold {total} entries (more than 2^32)"
            )));
        }
        check_memory("the TetraGrid lists", grid.n, total * 4)?;
        for c in 1..counts.len() {
            counts[c] += counts[c - 1];
        }
        let offsets = counts.clone();
        let mut lists = vec![0u32; total as usize];
        for (id, t) in tetras.iter().enumerate() {
            buf.clear();
            cells(grid, t, growth, &mut buf);
            for &c in &buf {
                lists[counts[c as usize] as usize] = id as u32;
                counts[c as usize] += 1;
            }
        }
        Ok(TetraGrid { grid: *grid, offsets, tetras: lists })
    }

    /// The tetras listed in cell `c`.
    pub fn cell(&self, c: usize) -> &[u32] {
        &self.tetras[self.offsets[c] as usize..self.offsets[c + 1] as usize]
    }

    /// The tetras of the cell that contains `p` (empty outside the cube).
    pub fn tetras_at(&self, p: DVec3) -> &[u32] {
        cell_of(&self.grid, p).map_or(&[], |c| self.cell(c))
    }

    /// Bytes the lists take (offsets and ids).
    pub fn memory_bytes(&self) -> usize {
        4 * (self.offsets.len() + self.tetras.len())
    }
}

/// Whether tetra `t` and the closed box [lo, hi] intersect, by the separating axis
/// theorem (box normals, tetra face normals, and every box edge × tetra edge), in f64:
/// the independent check the conservative rasterizer is tested against.
pub fn tetra_box_overlap(t: &[DVec3; 4], lo: DVec3, hi: DVec3) -> bool {
    let centre = (lo + hi) * 0.5;
    let half = (hi - lo) * 0.5;
    let separated = |axis: DVec3| -> bool {
        if axis.length_squared() < 1e-300 {
            return false;
        }
        let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in t {
            let d = axis.dot(*p - centre);
            a = a.min(d);
            b = b.max(d);
        }
        let r = half.dot(axis.abs());
        a > r || b < -r
    };
    let box_axes = [DVec3::X, DVec3::Y, DVec3::Z];
    let edges = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)].map(|(a, b)| t[b] - t[a]);
    let faces =
        [(1, 2, 3), (0, 2, 3), (0, 1, 3), (0, 1, 2)].map(|(a, b, c)| (t[b] - t[a]).cross(t[c] - t[a]));
    if box_axes.iter().any(|&a| separated(a)) || faces.iter().any(|&a| separated(a)) {
        return false;
    }
    !box_axes.iter().any(|&b| edges.iter().any(|&e| separated(b.cross(e))))
}

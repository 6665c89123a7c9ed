//! The TetraGrid (SPEC §3.2 item 4, §4.4; thesis §4.3.2.4, §5.5.1): an n³ grid of cubic
//! cells, each listing every tetra that may touch it, filled by conservative
//! rasterization of the tetras. The inclusion optimizer tests a point only against its
//! cell's list ([`super::tetragrid`], on the CPU and the GPU); the voxelizer's
//! slicing is where the rasterization comes from. This module depends on neither.
//!
//! ## Conservative rasterization
//!
//! Standard rasterization does not list every cell a tetra touches, so each tetra is
//! enlarged — its four face planes moved outward, its vertices recomputed as
//! intersections of the moved planes — and rasterized with "append id" instead of XOR:
//! slice by slice and row by row, a cell is appended when its centre lies inside all four
//! moved planes (and inside the tetra's bounding box grown by the same amount, which keeps
//! slivers' far-flung recomputed vertices in check).
//!
//! Why it is conservative: a tetra that meets a cell has a point within half a cell
//! diagonal (h√3/2) of the cell's centre, so the centre lies in the tetra grown by that
//! distance, which the moved planes contain. The thesis (and SPEC §4.4) move the planes by
//! twice the voxel diagonal ([`SPEC_OFFSET`]); half a diagonal ([`MIN_OFFSET`]) is already
//! enough when cells are sampled at their centres. Tighter still, [`Growth::CellBox`] moves
//! each plane by the cell's half extent along that plane's normal (h/2·(|nx|+|ny|+|nz|)):
//! a cell meets a half-space exactly when its centre is inside the half-space moved that
//! much, so no touched cell is lost and cells beside axis-aligned faces are not added.
//!
//! Cells are numbered x fastest, then y, then z: (k·n + j)·n + i.

use std::ops::Range;

use glam::DVec3;
use rayon::prelude::*;

/// The plane offset SPEC §4.4 asks for, in cell diagonals.
pub const SPEC_OFFSET: f64 = 2.0;

/// The smallest offset that is conservative for centre sampling, in cell diagonals.
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

/// An n³ grid of cubic cells of side `cell` whose minimum corner is `lo`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cells {
    pub n: usize,
    pub lo: DVec3,
    pub cell: f64,
}

impl Cells {
    pub fn new(lo: DVec3, cell: f64, n: usize) -> Cells {
        Cells { n, lo, cell }
    }

    /// The cube of side (largest extent of [lo, hi]) + 2·`pad`, centred on the box, cut into
    /// n³ cells (a box without extent gets a unit cube).
    pub fn around(lo: DVec3, hi: DVec3, pad: f64, n: usize) -> Cells {
        let side = (hi - lo).max_element() + 2.0 * pad;
        let side = if side > 0.0 { side } else { 1.0 };
        Cells { n, lo: (lo + hi) * 0.5 - DVec3::splat(side * 0.5), cell: side / n as f64 }
    }

    pub fn num_cells(&self) -> usize {
        self.n * self.n * self.n
    }

    /// Cell index of integer coordinates (x fastest, then y, then z).
    #[inline]
    pub fn index(&self, c: [usize; 3]) -> usize {
        c[0] + self.n * (c[1] + self.n * c[2])
    }

    /// Integer coordinate along one axis, unclamped.
    #[inline]
    fn coord(&self, x: f64, axis: usize) -> f64 {
        ((x - self.lo[axis]) / self.cell).floor()
    }

    /// Integer coordinates of the cell holding `q`; `None` outside the cube (and for NaN).
    /// Cells are closed on their low side.
    #[inline]
    pub fn coords(&self, q: DVec3) -> Option<[usize; 3]> {
        let n = self.n as f64;
        let mut c = [0usize; 3];
        for (axis, ci) in c.iter_mut().enumerate() {
            let x = self.coord(q[axis], axis);
            if !(x >= 0.0 && x < n) {
                return None;
            }
            *ci = x as usize;
        }
        Some(c)
    }

    /// The integer coordinate along `axis` of a coordinate value `x`, `None` outside the
    /// cube (the arithmetic of [`Self::coords`]).
    #[inline]
    pub fn coords_axis(&self, x: f64, axis: usize) -> Option<usize> {
        let c = self.coord(x, axis);
        (c >= 0.0 && c < self.n as f64).then_some(c as usize)
    }

    /// The index of the cell holding `q`, `None` outside the cube.
    #[inline]
    pub fn cell_of(&self, q: DVec3) -> Option<usize> {
        self.coords(q).map(|c| self.index(c))
    }

    /// Cell coordinate ranges covering the box [lo, hi], clamped to the grid. Uses the
    /// same arithmetic as [`Self::coords`], so a point in the box always falls in them.
    pub fn ranges(&self, lo: DVec3, hi: DVec3) -> [Range<usize>; 3] {
        let last = (self.n - 1) as f64;
        std::array::from_fn(|axis| {
            let a = self.coord(lo[axis], axis).clamp(0.0, last) as usize;
            let b = self.coord(hi[axis], axis).clamp(0.0, last) as usize;
            a..b + 1
        })
    }

    /// Corners of cell `c`.
    pub fn cell_box(&self, c: [usize; 3]) -> (DVec3, DVec3) {
        let lo = self.lo + DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) * self.cell;
        (lo, lo + DVec3::splat(self.cell))
    }

    /// Calls `f(index)` for every cell whose centre the tetra `t` grown by `growth` covers
    /// (see the module docs): with [`Growth::CellBox`] or at least [`MIN_OFFSET`] diagonals,
    /// every cell `t` touches.
    pub fn rasterize(&self, t: &[DVec3; 4], growth: Growth, mut f: impl FnMut(usize)) {
        let lo = t.iter().fold(DVec3::INFINITY, |m, &p| m.min(p));
        let hi = t.iter().fold(DVec3::NEG_INFINITY, |m, &p| m.max(p));
        self.rasterize_planes(face_planes(t).as_ref(), (lo, hi), growth, |c| f(self.index(c)));
    }

    /// The rasterizer for a tetra given by its four face planes — (outward unit normal, d),
    /// inside n·x ≤ d, `None` for a flat tetra, which gets its grown box — and its bounding
    /// box: the form other modules keep their tetras in. Calls `f([i, j, k])`.
    pub fn rasterize_planes(
        &self,
        planes: Option<&[(DVec3, f64); 4]>,
        (lo, hi): (DVec3, DVec3),
        growth: Growth,
        mut f: impl FnMut([usize; 3]),
    ) {
        let (origin, cell, n) = (self.lo, self.cell, self.n);
        let grow = growth.amounts(cell, DVec3::ZERO).1;
        let lo = lo - DVec3::splat(grow);
        let hi = hi + DVec3::splat(grow);
        // Rounding slack, far below any cell size.
        let slack = 1e-9 * (hi - lo).max_element().max(cell);
        let planes = planes.map(|p| p.map(|(nrm, d)| (nrm, d + growth.amounts(cell, nrm).0 + slack)));
        let range = |min: f64, a: f64, b: f64| -> Range<usize> {
            let first = ((a - slack - min) / cell - 0.5).ceil().max(0.0);
            let last = ((b + slack - min) / cell - 0.5).floor().min(n as f64 - 1.0);
            if first > last { 0..0 } else { first as usize..last as usize + 1 }
        };
        let centre = |min: f64, i: usize| min + (i as f64 + 0.5) * cell;
        for k in range(origin.z, lo.z, hi.z) {
            let z = centre(origin.z, k);
            for j in range(origin.y, lo.y, hi.y) {
                let y = centre(origin.y, j);
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
                        f([i, j, k]);
                    }
                }
            }
        }
    }
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

/// A TetraGrid that would not fit: too many entries for 32-bit lists, or more memory than
/// is available.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the TetraGrid's {what} need {need_mib} MiB, but only {have_mib} MiB are available")]
pub struct TooLarge {
    pub what: &'static str,
    pub need_mib: crate::host::Mib,
    pub have_mib: u64,
}

/// The cell → tetras lists of a grid (CSR): cell c lists `ids[start[c]..start[c + 1]]`, in
/// increasing tetra order.
#[derive(Clone, Debug)]
pub struct TetraGrid {
    cells: Cells,
    start: Vec<u32>,
    ids: Vec<u32>,
}

impl TetraGrid {
    /// Lists `count` tetras (or any items): `cover(t, out)` appends the indices of the
    /// cells item `t` touches (no duplicates). A cover may list extra cells, never miss
    /// one. Covers run in parallel; the lists are the same for any number of threads.
    pub fn build(
        cells: Cells,
        count: usize,
        cover: impl Fn(usize, &mut Vec<u32>) + Sync,
    ) -> Result<TetraGrid, TooLarge> {
        let check = |what: &'static str, bytes: u64| {
            crate::host::check_available(bytes).map_err(|(need_mib, have_mib)| TooLarge {
                what,
                need_mib,
                have_mib,
            })
        };
        let num_cells = cells.num_cells();
        check("cell offsets", (num_cells as u64 + 1) * 4)?;
        // Cells of every item (in parallel chunks, in order), then a counting sort into
        // per-cell lists.
        const CHUNK: usize = 4096;
        let parts: Vec<(Vec<u32>, Vec<u32>)> = (0..count.div_ceil(CHUNK))
            .into_par_iter()
            .map(|k| {
                let (mut entries, mut ends) = (Vec::new(), Vec::with_capacity(CHUNK));
                for t in k * CHUNK..((k + 1) * CHUNK).min(count) {
                    cover(t, &mut entries);
                    ends.push(entries.len() as u32);
                }
                // Held with the lists until they are filled: no spare capacity.
                entries.shrink_to_fit();
                (entries, ends)
            })
            .collect();
        let total: usize = parts.iter().map(|p| p.0.len()).sum();
        if total >= u32::MAX as usize {
            return Err(TooLarge {
                what: "lists (more than 2^32 entries)",
                need_mib: crate::host::Mib::of(total as u64 * 4),
                have_mib: 0,
            });
        }
        check("lists", total as u64 * 4)?;
        // `start[c + 1]` first counts cell c's entries, then (summed) is where its list
        // ends; items placed last to first, each one slot down, leave `start[c]` at the
        // list's beginning and the lists in increasing order, with no second array.
        let mut start = vec![0u32; num_cells + 1];
        for &c in parts.iter().flat_map(|p| &p.0) {
            start[c as usize + 1] += 1;
        }
        for c in 0..num_cells {
            start[c + 1] += start[c];
        }
        let mut ids = vec![0u32; total];
        for (k, (entries, ends)) in parts.iter().enumerate().rev() {
            for i in (0..ends.len()).rev() {
                let from = if i == 0 { 0 } else { ends[i - 1] as usize };
                for &c in &entries[from..ends[i] as usize] {
                    let slot = &mut start[c as usize + 1];
                    *slot -= 1;
                    ids[*slot as usize] = (k * CHUNK + i) as u32;
                }
            }
        }
        // Each list now begins at `start[c + 1]`: shift by one to make it `start[c]`.
        start.copy_within(1.., 0);
        start[num_cells] = total as u32;
        Ok(TetraGrid { cells, start, ids })
    }

    /// Conservatively rasterizes every tetra (four corners, the coordinates of `cells`)
    /// into its cells (`Growth::Diagonals(SPEC_OFFSET)` is SPEC §4.4's choice).
    pub fn of_tetras(cells: Cells, tetras: &[[DVec3; 4]], growth: Growth) -> Result<TetraGrid, TooLarge> {
        TetraGrid::build(cells, tetras.len(), |t, out| {
            cells.rasterize(&tetras[t], growth, |c| out.push(c as u32))
        })
    }

    pub fn cells(&self) -> &Cells {
        &self.cells
    }

    /// The tetras listed in cell `c`, in increasing order.
    #[inline]
    pub fn cell(&self, c: usize) -> &[u32] {
        &self.ids[self.start[c] as usize..self.start[c + 1] as usize]
    }

    /// The tetras of the cell holding `p` (empty outside the cube).
    pub fn tetras_at(&self, p: DVec3) -> &[u32] {
        self.cells.cell_of(p).map_or(&[], |c| self.cell(c))
    }

    /// CSR arrays of the lists: `(start, ids)` with `start.len() == n³ + 1`.
    pub fn lists(&self) -> (&[u32], &[u32]) {
        (&self.start, &self.ids)
    }

    /// Heap bytes of the lists.
    pub fn memory_bytes(&self) -> usize {
        4 * (self.start.capacity() + self.ids.capacity())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Rng;

    #[test]
    fn lists_hold_every_item_of_their_cells_in_increasing_order() {
        // More items than one parallel chunk, random covers of 0–5 distinct cells.
        let cells = Cells::new(DVec3::ZERO, 1.0, 6);
        let mut rng = Rng::new(5);
        let covers: Vec<Vec<u32>> = (0..10_000)
            .map(|_| {
                let mut c: Vec<u32> = (0..rng.below(6)).map(|_| rng.below(216) as u32).collect();
                c.sort_unstable();
                c.dedup();
                c
            })
            .collect();
        let grid = TetraGrid::build(cells, covers.len(), |t, out| out.extend(&covers[t])).unwrap();
        for c in 0..216 {
            let expected: Vec<u32> =
                (0..covers.len() as u32).filter(|&t| covers[t as usize].contains(&(c as u32))).collect();
            assert_eq!(grid.cell(c), &expected[..], "cell {c}");
        }
        let (start, ids) = grid.lists();
        assert_eq!((start.len(), start[216] as usize), (217, ids.len()));
    }
}

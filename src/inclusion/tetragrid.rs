//! TetraGrid (§4.3.2.4, Tables 4-4, 4-5): an n³ grid over the bounding cube, each cell
//! listing every tetra that may touch it; a point is tested only against its cell's list,
//! and a point outside the cube is Outside at once.
//!
//! Two separate parts: [`GridGeometry`] + CSR cell lists (the storage a GPU pass groups
//! points by), and a *cover* function saying which cells a tetra touches. The default is
//! [`conservative_cover`], the conservative tetra rasterization of §4.4/§5.5.1; the first
//! cover, [`box_cover`] (the tetra's grown box, minus cells clearly beyond one of its
//! planes), stays available through [`TetraGrid::with_cover`]. A cover may list extra
//! cells, never miss one: it must list every cell holding a point for which the tetra's
//! verdict is not `Outside`.

use std::ops::Range;
use std::time::Instant;

use glam::DVec3;

use super::cpu::FeitoTorres;
use super::tetra::{CompactPlanes, Kind, TetraPlanes};
use super::classifier::{BuildStats, Class, Classifier, vec_bytes};
use super::error::{InclusionError, Result};

pub const DEFAULT_RESOLUTION: usize = 32;
pub const RESOLUTIONS: Range<usize> = 2..65;

/// Placement of an n³ grid of cubic cells, in coordinates relative to the apex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridGeometry {
    pub n: usize,
    /// Minimum corner of the grid cube (relative to the apex).
    pub lo: DVec3,
    /// Edge length of a cell.
    pub cell: f64,
}

impl GridGeometry {
    /// The bounding cube of `ft`'s surface (side = largest extent, centred), grown by 4ε so
    /// every grown tetra box fits inside, cut into n³ cells.
    pub fn around(ft: &FeitoTorres, n: usize) -> GridGeometry {
        let (lo, hi) = ft.surface().bounds();
        let side = (hi - lo).max_element() + 8.0 * ft.surface().eps();
        let side = if side > 0.0 { side } else { 1.0 };
        let lo = (lo + hi) * 0.5 - DVec3::splat(side * 0.5) - ft.apex();
        GridGeometry { n, lo, cell: side / n as f64 }
    }

    pub fn num_cells(&self) -> usize {
        self.n * self.n * self.n
    }

    /// Cell index of integer coordinates (x fastest, then y, then z).
    #[inline]
    pub fn index(&self, c: [usize; 3]) -> usize {
        c[0] + self.n * (c[1] + self.n * c[2])
    }

    /// Integer coordinate along one axis of a relative coordinate, unclamped.
    #[inline]
    fn coord(&self, x: f64, axis: usize) -> f64 {
        ((x - self.lo[axis]) / self.cell).floor()
    }

    /// Integer coordinates of the cell holding `q` (relative to the apex); `None` outside
    /// the cube (and for NaN).
    #[inline]
    pub fn cell_coords(&self, q: DVec3) -> Option<[usize; 3]> {
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

    /// Cell coordinate ranges covering the box [lo, hi] (relative), clamped to the grid.
    /// Uses the same arithmetic as [`Self::cell_coords`], so a point in the box always
    /// falls in the ranges.
    pub fn ranges(&self, lo: DVec3, hi: DVec3) -> [Range<usize>; 3] {
        let last = (self.n - 1) as f64;
        std::array::from_fn(|axis| {
            let a = self.coord(lo[axis], axis).clamp(0.0, last) as usize;
            let b = self.coord(hi[axis], axis).clamp(0.0, last) as usize;
            a..b + 1
        })
    }

    /// Corners of cell `c` (relative).
    pub fn cell_box(&self, c: [usize; 3]) -> (DVec3, DVec3) {
        let lo = self.lo + DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) * self.cell;
        (lo, lo + DVec3::splat(self.cell))
    }
}

/// Conservative cover from the tetra's grown box: every cell of the box, except cells lying
/// more than 2ε beyond one of a regular tetra's four planes (there its verdict is `Outside`
/// for every point; 2ε absorbs the rounding between cell corners and point coordinates).
pub fn box_cover(grid: &GridGeometry, t: &TetraPlanes, eps: f64, out: &mut Vec<u32>) {
    let [rx, ry, rz] = grid.ranges(t.lo, t.hi);
    let half = DVec3::splat(grid.cell * 0.5);
    let planes = [(t.side[0], 0.0), (t.side[1], 0.0), (t.side[2], 0.0), (t.base, t.base_offset)];
    for k in rz {
        for j in ry.clone() {
            for i in rx.clone() {
                let c = [i, j, k];
                if t.kind == Kind::Regular {
                    let (lo, _) = grid.cell_box(c);
                    let centre = lo + half;
                    // Largest inward distance over the cell: at the corner along the normal.
                    if planes.iter().any(|&(n, off)| n.dot(centre) + n.abs().dot(half) - off < -2.0 * eps) {
                        continue;
                    }
                }
                out.push(grid.index(c) as u32);
            }
        }
    }
}

/// The default cover: conservative rasterization of the tetra (§5.5.1, SPEC §4.4, the
/// voxelization module's rasterizer): its planes moved out by the cell's half extent along
/// each normal plus 2ε, so every cell holding a point whose verdict for this tetra is not
/// Outside (within ε) is listed. Flat and degenerate tetras get their grown box, as with
/// [`box_cover`].
pub fn conservative_cover(grid: &GridGeometry, t: &TetraPlanes, eps: f64, out: &mut Vec<u32>) {
    use crate::voxel::tetragrid::{Growth, for_each_cell_planes};
    // The rasterizer takes outward planes (inside n·x ≤ d); these are inward, with the
    // side faces through the apex (the origin of `grid`'s coordinates).
    let planes = (t.kind == Kind::Regular)
        .then(|| [(-t.side[0], 0.0), (-t.side[1], 0.0), (-t.side[2], 0.0), (-t.base, -t.base_offset)]);
    let growth = Growth::CellBox { extra: 2.0 * eps };
    for_each_cell_planes(grid.lo, grid.cell, grid.n, planes.as_ref(), (t.lo, t.hi), growth, |i, j, k| {
        out.push(grid.index([i, j, k]) as u32)
    });
}

/// Feito-Torres over the tetras of the point's grid cell.
#[derive(Clone, Debug)]
pub struct TetraGrid {
    ft: FeitoTorres,
    grid: GridGeometry,
    /// Tetras of cell c are `ids[start[c]..start[c + 1]]`, in increasing order.
    start: Vec<u32>,
    ids: Vec<u32>,
    /// f32 planes of every tetra: a one-cache-line prefilter for the scattered reads.
    compact: Vec<CompactPlanes>,
    index_stats: BuildStats,
}

impl TetraGrid {
    /// An n³ grid (n in 2..=64) filled by conservative rasterization ([`conservative_cover`]).
    pub fn new(ft: FeitoTorres, n: usize) -> Result<TetraGrid> {
        TetraGrid::with_cover(ft, n, conservative_cover)
    }

    /// An n³ grid filled by `cover(grid, tetra, ε, out)`, which appends the indices of the
    /// cells the tetra touches (see the module docs for what it must include).
    pub fn with_cover(
        ft: FeitoTorres,
        n: usize,
        cover: impl Fn(&GridGeometry, &TetraPlanes, f64, &mut Vec<u32>),
    ) -> Result<TetraGrid> {
        if !RESOLUTIONS.contains(&n) {
            return Err(InclusionError::Resolution(n));
        }
        let start_time = Instant::now();
        let grid = GridGeometry::around(&ft, n);
        let eps = ft.surface().eps();
        // Cells of every tetra, then a counting sort into per-cell lists.
        let mut cells = Vec::new();
        let mut offsets = Vec::with_capacity(ft.tetras().len() + 1);
        offsets.push(0usize);
        for t in ft.tetras() {
            cover(&grid, t, eps, &mut cells);
            offsets.push(cells.len());
        }
        let mut start = vec![0u32; grid.num_cells() + 1];
        for &c in &cells {
            start[c as usize + 1] += 1;
        }
        for c in 0..grid.num_cells() {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut ids = vec![0u32; cells.len()];
        for (t, w) in offsets.windows(2).enumerate() {
            for &c in &cells[w[0]..w[1]] {
                ids[fill[c as usize] as usize] = t as u32;
                fill[c as usize] += 1;
            }
        }
        let compact = ft.compact_planes();
        let bytes = vec_bytes(&start) + vec_bytes(&ids) + vec_bytes(&compact);
        let index_stats = BuildStats { build_time: start_time.elapsed(), bytes };
        Ok(TetraGrid { ft, grid, start, ids, compact, index_stats })
    }

    pub fn base(&self) -> &FeitoTorres {
        &self.ft
    }

    pub fn geometry(&self) -> &GridGeometry {
        &self.grid
    }

    pub fn resolution(&self) -> usize {
        self.grid.n
    }

    /// Time and memory of the grid alone (Table 4-4).
    pub fn index_stats(&self) -> BuildStats {
        self.index_stats
    }

    /// The cell holding `p`, `None` outside the grid's cube (such points are Outside).
    #[inline]
    pub fn cell_of(&self, p: DVec3) -> Option<usize> {
        self.grid.cell_coords(p - self.ft.apex()).map(|c| self.grid.index(c))
    }

    /// The tetras listed in `cell`, in increasing order.
    #[inline]
    pub fn cell_tetras(&self, cell: usize) -> &[u32] {
        &self.ids[self.start[cell] as usize..self.start[cell + 1] as usize]
    }

    /// CSR arrays of the cell lists: `(start, ids)` with `start.len() == n³ + 1`.
    pub fn cell_lists(&self) -> (&[u32], &[u32]) {
        (&self.start, &self.ids)
    }
}

impl Classifier for TetraGrid {
    fn name(&self) -> &str {
        "tetragrid"
    }

    fn classify(&self, p: DVec3) -> Class {
        match self.cell_of(p) {
            Some(cell) => {
                self.ft.classify_among_compact(p, self.cell_tetras(cell).iter().copied(), &self.compact)
            }
            None => Class::Outside,
        }
    }

    fn build_stats(&self) -> BuildStats {
        let base = self.ft.build_stats();
        BuildStats {
            build_time: base.build_time + self.index_stats.build_time,
            bytes: base.bytes + self.index_stats.bytes,
        }
    }
}

//! TetraGrid search (§4.3.2.4, Tables 4-4, 4-5): Feito-Torres over the tetras of the
//! point's cell of a [`TetraGrid`] (an n³ grid over the bounding cube, each cell listing
//! every tetra that may touch it); a point outside the cube is Outside at once.
//!
//! Which cells a tetra touches is a *cover* function. The default is
//! [`conservative_cover`], the conservative tetra rasterization of §4.4/§5.5.1
//! ([`super::cells`]); the first cover, [`box_cover`] (the tetra's grown box, minus
//! cells clearly beyond one of its planes), stays available through
//! [`GridClassifier::with_cover`]. A cover may list extra cells, never miss one: it must
//! list every cell holding a point for which the tetra's verdict is not `Outside`.

use std::ops::Range;
use std::time::Instant;

use glam::DVec3;

use super::cells::{Cells, Growth, TetraGrid};
use super::classifier::{BuildStats, Class, Classifier, vec_bytes};
use super::cpu::FeitoTorres;
use super::error::{InclusionError, Result};
use super::tetra::{CompactPlanes, Kind, TetraPlanes};

pub const DEFAULT_RESOLUTION: usize = 32;
pub const RESOLUTIONS: Range<usize> = 2..65;

/// The grid of a classifier: the bounding cube of `ft`'s surface (side = largest extent,
/// centred), grown by 4ε so every grown tetra box fits inside, in coordinates relative to
/// the apex, cut into n³ cells.
pub fn cells_around(ft: &FeitoTorres, n: usize) -> Cells {
    let (lo, hi) = ft.surface().bounds();
    Cells::around(lo - ft.apex(), hi - ft.apex(), 4.0 * ft.surface().eps(), n)
}

/// Conservative cover from the tetra's grown box: every cell of the box, except cells lying
/// more than 2ε beyond one of a regular tetra's four planes (there its verdict is `Outside`
/// for every point; 2ε absorbs the rounding between cell corners and point coordinates).
pub fn box_cover(grid: &Cells, t: &TetraPlanes, eps: f64, out: &mut Vec<u32>) {
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
pub fn conservative_cover(grid: &Cells, t: &TetraPlanes, eps: f64, out: &mut Vec<u32>) {
    // The rasterizer takes outward planes (inside n·x ≤ d); these are inward, with the
    // side faces through the apex (the origin of `grid`'s coordinates).
    let planes = (t.kind == Kind::Regular)
        .then(|| [(-t.side[0], 0.0), (-t.side[1], 0.0), (-t.side[2], 0.0), (-t.base, -t.base_offset)]);
    let growth = Growth::CellBox { extra: 2.0 * eps };
    grid.rasterize_planes(planes.as_ref(), (t.lo, t.hi), growth, |c| out.push(grid.index(c) as u32));
}

/// Feito-Torres over the tetras of the point's grid cell.
#[derive(Clone, Debug)]
pub struct GridClassifier {
    ft: FeitoTorres,
    /// The cell lists, in coordinates relative to the apex.
    grid: TetraGrid,
    /// f32 planes of every tetra: a one-cache-line prefilter for the scattered reads.
    compact: Vec<CompactPlanes>,
    index_stats: BuildStats,
}

impl GridClassifier {
    /// An n³ grid (n in 2..=64) filled by conservative rasterization ([`conservative_cover`]).
    pub fn new(ft: FeitoTorres, n: usize) -> Result<GridClassifier> {
        GridClassifier::with_cover(ft, n, conservative_cover)
    }

    /// An n³ grid filled by `cover(grid, tetra, ε, out)`, which appends the indices of the
    /// cells the tetra touches (see the module docs for what it must include).
    pub fn with_cover(
        ft: FeitoTorres,
        n: usize,
        cover: impl Fn(&Cells, &TetraPlanes, f64, &mut Vec<u32>) + Sync,
    ) -> Result<GridClassifier> {
        if !RESOLUTIONS.contains(&n) {
            return Err(InclusionError::Resolution(n));
        }
        let start_time = Instant::now();
        let cells = cells_around(&ft, n);
        let eps = ft.surface().eps();
        let tetras = ft.tetras();
        let grid = TetraGrid::build(cells, tetras.len(), |t, out| cover(&cells, &tetras[t], eps, out))
            .map_err(|e| InclusionError::TooLarge(e.to_string()))?;
        let compact = ft.compact_planes();
        let bytes = grid.memory_bytes() + vec_bytes(&compact);
        let index_stats = BuildStats { build_time: start_time.elapsed(), bytes };
        Ok(GridClassifier { ft, grid, compact, index_stats })
    }

    pub fn base(&self) -> &FeitoTorres {
        &self.ft
    }

    /// The grid's cells (coordinates relative to the apex).
    pub fn geometry(&self) -> &Cells {
        self.grid.cells()
    }

    pub fn resolution(&self) -> usize {
        self.grid.cells().n
    }

    /// Time and memory of the grid alone (Table 4-4).
    pub fn index_stats(&self) -> BuildStats {
        self.index_stats
    }

    /// The cell holding `p`, `None` outside the grid's cube (such points are Outside).
    #[inline]
    pub fn cell_of(&self, p: DVec3) -> Option<usize> {
        self.grid.cells().cell_of(p - self.ft.apex())
    }

    /// The tetras listed in `cell`, in increasing order.
    #[inline]
    pub fn cell_tetras(&self, cell: usize) -> &[u32] {
        self.grid.cell(cell)
    }

    /// CSR arrays of the cell lists: `(start, ids)` with `start.len() == n³ + 1`.
    pub fn cell_lists(&self) -> (&[u32], &[u32]) {
        self.grid.lists()
    }
}

impl Classifier for GridClassifier {
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

//! Inclusion by voxel space (§4.2.1.1, "algoritmo de inclusión basado en espacio de
//! voxels", made exact): a uniform grid over the solid's bounding cube whose cells are
//! labelled once — *surface* where some face may come within ε of the cell, else *inside*
//! or *outside* — so a point in a labelled cell is answered in O(1), and only points in
//! surface cells run an exact test on their cell's list of covering triangles. The thesis
//! lists the method among the inexact ones because the labels of "partially included"
//! cells are approximate; here no partial cell gets a label, so every answer is exact.
//!
//! ## Building
//!
//! 1. **Surface cells** by conservative rasterization of the covering triangles (in
//!    parallel): a cell lists triangle t when t's box grown by ε + slack reaches it and t's
//!    plane passes within (the cell's half extent along the normal) + ε + slack of its
//!    centre. Every cell holding a point within ε of a face lists that face's triangles.
//! 2. **Labels** of the other cells: the class of the cell's centre. No face comes within
//!    ε of such a cell, so all its points share its centre's class. Each row is labelled
//!    from its far end (outside beyond the grid) towards −x, each centre by the same parity
//!    walk as a query point (below) to the labelled cell on its right: the crossings tested
//!    are those of the surface cells in between, so the whole labelling reads each list
//!    about once per row. A cell whose computed centre rounds out of the cell (coordinates
//!    so far from the origin that the cell is a few ulps wide) stays a surface cell.
//!
//! ## A point in a surface cell
//!
//! First the boundary: the exact "within ε of a face" predicate ([`Surface::on_face`]) for
//! the faces of the cell's triangles (the same predicate, so the same OnBoundary answers,
//! as every other method). Otherwise P is off the surface (in the plane of a non-convex
//! face it is first moved ε/2 off that plane, as [`Surface::off_polygon_planes`] says
//! why), and its class is the parity of
//! the crossings of a ray from P along +x (the exact predicates and tie rule of
//! [`crate::voxel::exact`]): the ray walks along P's row of cells to the first labelled
//! cell (or out of the grid); with R the point of that cell's centre abscissa on P's line,
//! class(P) = class(R) (its label; outside beyond the grid) XOR the parity of the crossings
//! between P and R. Those crossings lie in the surface cells walked, so only their lists
//! are tested, each triangle once.
//! This is Feito-Torres' sum with the apex at infinity along −x (its tetras become prisms
//! along x) taken between P and R.

use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;

use super::cells::{Cells, TetraGrid};
use super::classifier::{BuildStats, Class, Classifier, vec_bytes};
use super::error::{InclusionError, Result};
use super::surface::Surface;
use crate::exact::orient2d;
use crate::mesh::Mesh;
use crate::voxel::exact::{crossing_ahead, inside_yz};

/// Resolutions the method accepts (n³ cells).
pub const RESOLUTIONS: std::ops::RangeInclusive<usize> = 2..=512;

/// Cell labels: outside, inside, surface (a list to test), and not labelled yet (while
/// building).
const OUTSIDE: u8 = 0;
const INSIDE: u8 = 1;
const SURFACE: u8 = 2;
const UNLABELLED: u8 = 3;

/// The grid size for `triangles` covering triangles and about `points` query points: the
/// cost model of [`super::auto`] (see there for the measurements behind it).
pub fn resolution_for(triangles: usize, points: usize) -> usize {
    super::auto::voxel_space_resolution(triangles, points)
}

/// The exact voxel-space classifier.
#[derive(Clone, Debug)]
pub struct VoxelSpace {
    surface: Surface,
    /// Per cell, the covering triangles that may come within ε of it (increasing ids;
    /// empty for a labelled cell).
    lists: TetraGrid,
    /// Per cell: [`OUTSIDE`], [`INSIDE`] or [`SURFACE`] — what most points read, one byte
    /// a cell so it stays in cache.
    labels: Vec<u8>,
    /// Box of every covering triangle: x, y, z ranges (`[xlo, xhi, ylo, yhi, zlo, zhi]`),
    /// rounded outwards to f32 (half the memory; only ever a filter before exact tests).
    boxes: Vec<[f32; 6]>,
    /// Per column i: the abscissa of its centre, when it rounds into the column.
    column_x: Vec<Option<f64>>,
    stats: BuildStats,
}

impl VoxelSpace {
    /// Labels an n³ grid over `mesh`, closed and consistently oriented. `unchecked` skips
    /// checking that (under `allow_open` the factory sends open surfaces to the winding
    /// number instead; the command line has checked it already).
    pub fn new(mesh: &Mesh, n: usize, unchecked: bool) -> Result<VoxelSpace> {
        let start_time = Instant::now();
        let surface = Surface::with_policy(mesh, unchecked)?;
        VoxelSpace::with_surface(surface, n, start_time)
    }

    fn with_surface(surface: Surface, n: usize, start_time: Instant) -> Result<VoxelSpace> {
        if !RESOLUTIONS.contains(&n) {
            return Err(InclusionError::Options(format!(
                "voxel-space resolution {n} is outside {}..={}",
                RESOLUTIONS.start(),
                RESOLUTIONS.end()
            )));
        }
        let num_cells = n * n * n;
        crate::host::check_available(num_cells as u64 * 5).map_err(|(need, have)| {
            InclusionError::TooLarge(format!(
                "a {n}³ voxel space needs {need} MiB, only {have} MiB are available"
            ))
        })?;
        let (lo, hi) = surface.bounds();
        let eps = surface.eps();
        let cells = Cells::around(lo, hi, 4.0 * eps, n);
        let covering = surface.covering();
        // 1. Surface cells: every cell a covering triangle may come within ε of lists it.
        let h = cells.cell;
        let slack = 1e-9 * h + 8.0 * f64::EPSILON * (cells.lo.abs().max_element() + h * n as f64);
        let grow = eps + slack;
        let lists = TetraGrid::build(cells, covering.triangles.len(), |t, out| {
            let [a, b, c] = covering.triangle(t);
            let (tlo, thi) = (a.min(b).min(c) - grow, a.max(b).max(c) + grow);
            let normal = (b - a).cross(c - a).normalize_or_zero();
            let reach = 0.5 * h * normal.abs().element_sum() + grow;
            let base = cells.lo - a;
            let [rx, ry, rz] = cells.ranges(tlo, thi);
            for k in rz {
                for j in ry.clone() {
                    for i in rx.clone() {
                        let centre = base + DVec3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5) * h;
                        if normal != DVec3::ZERO && normal.dot(centre).abs() > reach {
                            continue;
                        }
                        out.push(cells.index([i, j, k]) as u32);
                    }
                }
            }
        })
        .map_err(|e| InclusionError::TooLarge(format!("voxel space: {e}")))?;
        let labels = (0..num_cells)
            .into_par_iter()
            .with_min_len(1 << 16)
            .map(|c| if lists.cell(c).is_empty() { UNLABELLED } else { SURFACE })
            .collect();
        let boxes = (0..covering.triangles.len())
            .into_par_iter()
            .with_min_len(4096)
            .map(|t| {
                let [a, b, c] = covering.triangle(t);
                let (l, h) = (a.min(b).min(c), a.max(b).max(c));
                [down(l.x), up(h.x), down(l.y), up(h.y), down(l.z), up(h.z)]
            })
            .collect();
        let column_x = (0..n)
            .map(|i| {
                let x = cells.lo.x + (i as f64 + 0.5) * cells.cell;
                (cells.coords_axis(x, 0) == Some(i)).then_some(x)
            })
            .collect();
        let mut vs =
            VoxelSpace { surface, lists, labels: Vec::new(), boxes, column_x, stats: BuildStats::default() };
        // 2. Labels: every other cell gets its centre's class, row by row from the far end
        // (outside beyond the grid), each centre by the parity walk of a query point to the
        // labelled cell on its right. A cell whose centre rounds out of the cell becomes a
        // surface cell with an empty list (its points walk to a labelled cell).
        let mut labels: Vec<u8> = labels;
        let centre = |axis: usize, j: usize| {
            let y = cells.lo[axis] + (j as f64 + 0.5) * cells.cell;
            (cells.coords_axis(y, axis) == Some(j)).then_some(y)
        };
        labels.par_chunks_mut(n).enumerate().for_each(|(row, lab)| {
            let (j, k) = (row % n, row / n);
            let yz = centre(1, j).zip(centre(2, k));
            let mut scratch = Vec::new();
            for i in (0..n).rev() {
                if lab[i] == SURFACE {
                    continue;
                }
                lab[i] = match (yz, vs.column_x[i]) {
                    (Some((y, z)), Some(x)) => {
                        if vs.parity_in_row(lab, row * n, DVec3::new(x, y, z), i, &mut scratch) {
                            INSIDE
                        } else {
                            OUTSIDE
                        }
                    }
                    _ => SURFACE,
                };
            }
        });
        vs.labels = labels;
        vs.stats = BuildStats {
            build_time: start_time.elapsed(),
            bytes: vs.surface.bytes()
                + vs.lists.memory_bytes()
                + vec_bytes(&vs.labels)
                + vec_bytes(&vs.boxes),
        };
        Ok(vs)
    }

    pub fn resolution(&self) -> usize {
        self.lists.cells().n
    }

    /// Cells that are surface cells (hold a list, perhaps empty) out of n³.
    pub fn surface_cells(&self) -> usize {
        self.labels.par_iter().with_min_len(1 << 16).filter(|&&l| l == SURFACE).count()
    }

    /// Total entries of the lists.
    pub fn entries(&self) -> usize {
        self.lists.lists().1.len()
    }

    pub fn surface(&self) -> &Surface {
        &self.surface
    }

    /// The label of cell `c` if it has one, `None` for a surface cell.
    pub fn label(&self, c: usize) -> Option<Class> {
        match self.labels[c] {
            OUTSIDE => Some(Class::Outside),
            INSIDE => Some(Class::Inside),
            _ => None,
        }
    }

    /// The exact test for a point in surface cell `c` (see the module docs).
    fn classify_near(&self, p: DVec3, c: usize, scratch: &mut Vec<u32>) -> Class {
        let list = self.lists.cell(c);
        let eps = self.surface.eps();
        let covering = self.surface.covering();
        let near = |b: &[f32; 6]| {
            let b = |k: usize| f64::from(b[k]);
            p.x >= b(0) - eps
                && p.x <= b(1) + eps
                && p.y >= b(2) - eps
                && p.y <= b(3) + eps
                && p.z >= b(4) - eps
                && p.z <= b(5) + eps
        };
        if list.iter().any(|&t| {
            near(&self.boxes[t as usize]) && self.surface.on_face(covering.face_of[t as usize] as usize, p)
        }) {
            return Class::OnBoundary;
        }
        // In the plane of a non-convex face over its cancelled part, the overlapping fan
        // triangles would see P on sides decided by rounding: classify P moved ε/2 off
        // that plane (same class, P being > ε from every face), from the moved point's cell.
        let moved = self.surface.off_polygon_planes(p, list.iter().map(|&t| t as usize));
        if moved != p {
            return match self.lookup(moved) {
                (_, OUTSIDE) => Class::Outside,
                (_, INSIDE) => Class::Inside,
                (c, _) => self.parity(moved, c, scratch),
            };
        }
        self.parity(p, c, scratch)
    }

    /// The class of a point `p` in surface cell `c`, off the boundary: the parity walk of
    /// the module docs.
    fn parity(&self, p: DVec3, c: usize, scratch: &mut Vec<u32>) -> Class {
        let n = self.lists.cells().n;
        let row = c - c % n;
        let inside = self.parity_in_row(&self.labels[row..row + n], row, p, c % n, scratch);
        if inside { Class::Inside } else { Class::Outside }
    }

    /// Whether `p`, off the boundary in cell `i` of the row whose first cell is `row` and
    /// whose labels are `labels`, is inside: the first labelled cell along +x whose centre
    /// abscissa lies in it gives R, and the crossings between P and R flip R's class.
    /// Only that cell and the surface cells before it are read (so the labelling can use
    /// it while it fills the row from the far end). `scratch` is reused between calls.
    fn parity_in_row(&self, labels: &[u8], row: usize, p: DVec3, i: usize, scratch: &mut Vec<u32>) -> bool {
        let covering = self.surface.covering();
        let n = labels.len();
        let mut end = i + 1;
        let mut reference: Option<(f64, bool)> = None;
        while end < n {
            if labels[end] <= INSIDE {
                if let Some(x) = self.column_x[end] {
                    reference = Some((x, labels[end] == INSIDE));
                    break;
                }
            }
            end += 1;
        }
        let r = reference.map(|(x, _)| DVec3::new(x, p.y, p.z));
        let r_x = r.map_or(f64::INFINITY, |r| r.x);
        let mut parity = reference.is_some_and(|(_, inside)| inside);
        // The triangles that may cross P's line between P and R, each once: a triangle is
        // listed in several cells of the row (sorted and deduplicated here rather than
        // trusting its cells to be consecutive, which rounding need not keep).
        scratch.clear();
        for (m, _) in labels.iter().enumerate().take(end).skip(i).filter(|&(_, &l)| l == SURFACE) {
            for &t in self.lists.cell(row + m) {
                // Exact comparisons first: a triangle whose yz box misses P's line, whose x
                // range ends before P or starts beyond R, cannot flip the parity.
                let b = &self.boxes[t as usize];
                let b = |k: usize| f64::from(b[k]);
                if p.y < b(2) || p.y > b(3) || p.z < b(4) || p.z > b(5) || b(1) < p.x || b(0) > r_x {
                    continue;
                }
                scratch.push(t);
            }
        }
        scratch.sort_unstable();
        scratch.dedup();
        for &t in scratch.iter() {
            let [a, b, c] = covering.triangle(t as usize);
            let nx = orient2d([a.y, a.z], [b.y, b.z], [c.y, c.z]);
            if nx == 0 || !inside_yz(a, b, c, p, nx) {
                continue;
            }
            if crossing_ahead(a, b, c, p, nx) && !r.is_some_and(|r| crossing_ahead(a, b, c, r, nx)) {
                parity = !parity;
            }
        }
        parity
    }
}

/// The largest f32 at most `x`.
fn down(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x { -next_up(-f) } else { f }
}

/// The smallest f32 at least `x`.
fn up(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) < x { next_up(f) } else { f }
}

/// The next f32 above `f` (`f32::next_up`, which needs Rust 1.86).
fn next_up(f: f32) -> f32 {
    if f.is_nan() || f == f32::INFINITY {
        f
    } else if f == 0.0 {
        f32::from_bits(1)
    } else if f > 0.0 {
        f32::from_bits(f.to_bits() + 1)
    } else {
        f32::from_bits(f.to_bits() - 1)
    }
}

impl VoxelSpace {
    /// The cell of `p` and its label byte (0 outside, 1 inside, 2 surface); points outside
    /// the bounding box grown by ε get (0, 0). The arithmetic of [`Cells::coords`]: after
    /// the box test every quotient is ≥ 0, where truncation is the floor.
    #[inline]
    fn lookup(&self, p: DVec3) -> (usize, u8) {
        if !self.surface.in_bounds(p) {
            return (0, 0);
        }
        let cells = self.lists.cells();
        let t = (p - cells.lo) / cells.cell;
        let n = cells.n as f64;
        if !(t.cmpge(DVec3::ZERO).all() && t.cmplt(DVec3::splat(n)).all()) {
            return (0, 0);
        }
        let c = cells.index([t.x as usize, t.y as usize, t.z as usize]);
        (c, self.labels[c])
    }
}

impl Classifier for VoxelSpace {
    fn name(&self) -> &str {
        "voxel-space"
    }

    #[inline]
    fn classify(&self, p: DVec3) -> Class {
        match self.lookup(p) {
            (_, OUTSIDE) => Class::Outside,
            (_, INSIDE) => Class::Inside,
            (c, _) => self.classify_near(p, c, &mut Vec::new()),
        }
    }

    /// In chunks: first every point's label byte, with no branch on the loaded bytes (so
    /// the memory reads of many points overlap), then the exact test for the points in
    /// surface cells.
    fn classify_all(&self, ps: &[DVec3]) -> Vec<Class> {
        let mut out = vec![Class::Outside; ps.len()];
        out.par_chunks_mut(2048).zip(ps.par_chunks(2048)).for_each(|(out, ps)| {
            let mut cells = [(0usize, 0u8); 2048];
            let mut scratch = Vec::new();
            for (slot, &p) in cells.iter_mut().zip(ps) {
                *slot = self.lookup(p);
            }
            for ((o, &p), &(c, label)) in out.iter_mut().zip(ps).zip(cells.iter()) {
                *o = match label {
                    OUTSIDE => Class::Outside,
                    INSIDE => Class::Inside,
                    _ => self.classify_near(p, c, &mut scratch),
                };
            }
        });
        out
    }

    fn build_stats(&self) -> BuildStats {
        self.stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f32_boxes_round_outwards_and_tightly() {
        let mut rng = crate::random::Rng::new(9);
        let mut values = vec![0.0, -0.0, 1.0, -1.0, 1e-45, -1e-45, 3.4e38, -3.4e38, 1e300, -1e300, 0.1, -0.1];
        values.extend(
            (0..10_000).map(|_| (rng.next_f64() - 0.5) * 10f64.powi((rng.next_f64() * 80.0) as i32 - 40)),
        );
        for x in values {
            let (d, u) = (down(x), up(x));
            assert!(f64::from(d) <= x && f64::from(u) >= x, "{x}: {d} {u}");
            // Tight: one f32 step inwards would cross x (within f32's range).
            if x.abs() < 3.0e38 {
                assert!(f64::from(next_up(d)) > x || f64::from(d) == x, "{x}: {d}");
                assert!(f64::from(-next_up(-u)) < x || f64::from(u) == x, "{x}: {u}");
            }
        }
    }
}

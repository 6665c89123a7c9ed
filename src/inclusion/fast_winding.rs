//! Inside by the generalized winding number, fast and certified: how `inclusion` and
//! `voxelize` answer, under `--allow-open`, for a mesh that is not a solid.
//!
//! **The rule** ([`crate::mesh::solidity`]): P is inside iff w(P) ≥ ½, w the generalized
//! winding number of the covering triangles; within ε of a face it is OnBoundary (the
//! shared predicate of [`super::surface`], decided exactly), for `voxelize` not occupied.
//!
//! **Per point.** After the exact boundary test, w(P) is estimated with the cluster tree
//! of [`super::multipole`], which returns w̃ and a bound E of its error; the label is
//! certain as soon as [w̃ − E, w̃ + E] lies on one side of ½. Otherwise the tree is walked
//! again with a per-cluster tolerance [`TOLERANCES`]`[1]` a hundred times smaller, and if
//! that still leaves ½ inside the interval, every triangle is summed directly with
//! compensated sums. A point still undecided then (w within the direct sum's own bound of
//! ½: it lies on the ½ level set itself or within about 1e-6 of a face) takes the side of
//! the direct sum's value.
//!
//! **Per cell.** Points are mostly far from the ½ level set, and w is smooth away from the
//! surface: its gradient is a line integral over the surface's *boundary curve* Γ (the
//! directed edges of the covering whose uses do not cancel; Biot–Savart), so
//! |∇w(X)| ≤ 1/(4π) Σ_{e∈Γ} m_e·|e| / dist(X, e)². On a closed mesh Γ is empty and w is
//! constant between the sheets. A box that no face comes within 2ε of is labelled whole
//! when w̃(centre) ± (E + |∇w|·radius) stays [`MARGIN`] away from ½ — the same answer every
//! point in it would get on its own. Boxes are split in halves down to single cells of a
//! lattice ([`Lattice`]): for `inclusion` cells of a grid over the mesh's box, sized by
//! the number of points; for `voxelize` the voxel centres themselves.
//!
//! **Near the surface.** Crossing the surface from the side its normal points to changes
//! w by exactly +1, so from an *anchor* Q with a certified estimate,
//! w(P) = w(Q) + (signed crossings of the segment QP) + drift, |drift| ≤ |∇w| bound × |QP|,
//! the crossings decided with exact orientation predicates ([`crate::exact`]). A segment
//! through an edge or a vertex, or a bound that does not decide, sends P to the per-point
//! path. Undecided `inclusion` cells get their centre as anchor; `voxelize` walks each row
//! of undecided voxels from one centre to the next (starting from the interval of the
//! block before it, or a fresh estimate), and takes a fresh estimate where a step does not
//! decide.
//!
//! Nothing here assumes a solid, so the meshes the solidity rule refuses — open,
//! self-intersecting, nested, inverted — all get this answer; on a valid solid w is 0 or 1
//! and it is the solid's own answer.

use std::f64::consts::PI;
use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;

use super::classifier::{BuildStats, Class, Classifier, vec_bytes};
use super::error::Result;
use super::multipole::{Estimate, Tree};
use super::surface::Surface;
use crate::exact::{closest_point_on_segment, orient2d, orient3d};
use crate::mesh::Mesh;
use crate::mesh::covering::Covering;
use crate::voxel::{Grid, Volume};

/// Per-cluster error tolerances of the two tree walks (units of w).
pub const TOLERANCES: [f64; 2] = [1e-2, 1e-4];
/// A cell is labelled whole only when its interval of w keeps this far from ½.
pub const MARGIN: f64 = 1e-3;
/// Fewer query points than this get no cell grid.
const MIN_POINTS_FOR_CELLS: usize = 20_000;
/// Largest cell grid for `inclusion` (n³ bytes).
const MAX_CELLS: usize = 96;
/// Boundary edges per group of the gradient bound.
const EDGE_GROUP: usize = 32;
/// `voxelize` does not try to decide blocks of fewer voxels whole: walking their rows
/// from a neighbour costs less than an estimate.
const MIN_VOXEL_BLOCK: usize = 256;

/// How a point's label was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tier {
    /// Within ε of a face.
    Boundary,
    /// Decided by the first (0) or second (1) tree walk.
    Tree(u8),
    /// Decided by the direct compensated sum.
    Direct,
    /// Not decided by any bound: the direct sum's value.
    Undecided,
}

/// The generalized winding number classifier with its cluster tree and, for many points,
/// a grid of certified cells.
#[derive(Clone, Debug)]
pub struct FastWinding {
    surface: Surface,
    tree: Tree,
    boundary: Boundary,
    cells: Option<Cells>,
    stats: BuildStats,
}

impl FastWinding {
    /// The classifier for `mesh` (any mesh: open, self-intersecting, …), with a cell grid
    /// sized for about `points` query points (none for few).
    pub fn new(mesh: &Mesh, points: usize) -> Result<FastWinding> {
        let start = Instant::now();
        let surface = Surface::with_policy(mesh, true)?;
        let tree = Tree::new(surface.covering());
        let boundary = Boundary::new(surface.covering());
        let mut fw = FastWinding { surface, tree, boundary, cells: None, stats: BuildStats::default() };
        if points >= MIN_POINTS_FOR_CELLS && !fw.tree.is_empty() {
            let n = ((points as f64 / 4.0).cbrt().round() as usize).clamp(4, MAX_CELLS);
            fw.cells = Some(fw.cells(n));
        }
        let bytes = fw.surface.bytes()
            + fw.tree.bytes()
            + vec_bytes(&fw.boundary.edges)
            + vec_bytes(&fw.boundary.groups)
            + fw.cells.as_ref().map_or(0, |c| vec_bytes(&c.labels) + vec_bytes(&c.anchors));
        fw.stats = BuildStats { build_time: start.elapsed(), bytes };
        Ok(fw)
    }

    pub fn surface(&self) -> &Surface {
        &self.surface
    }

    pub fn tree(&self) -> &Tree {
        &self.tree
    }

    /// Number of directed edges of the boundary curve Γ (0 for a closed mesh).
    pub fn boundary_edges(&self) -> usize {
        self.boundary.edges.len()
    }

    /// True when `p` is within ε of a face (the shared exact predicate).
    fn on_boundary(&self, p: DVec3) -> bool {
        self.surface.in_bounds(p)
            && self.tree.any_near(p, p, self.surface.eps(), |t| self.surface.on_boundary_near(t, p))
    }

    /// The label of `p` without the cell grid, and how it was found.
    pub fn classify_point(&self, p: DVec3) -> (Class, Tier) {
        if self.on_boundary(p) {
            return (Class::OnBoundary, Tier::Boundary);
        }
        let p = self.off_polygon_planes(p);
        let class = |inside: bool| if inside { Class::Inside } else { Class::Outside };
        for (k, &tol) in TOLERANCES.iter().enumerate() {
            if let Some(inside) = self.tree.winding(p, tol).decides(0.0) {
                return (class(inside), Tier::Tree(k as u8));
            }
        }
        let e = self.tree.direct(p);
        match e.decides(0.0) {
            Some(inside) => (class(inside), Tier::Direct),
            None => (class(e.w >= 0.5), Tier::Undecided),
        }
    }

    /// `p` moved ε/2 off the plane of a non-convex face it lies in (see
    /// [`Surface::off_polygon_planes`]): there the face's overlapping covering triangles
    /// would each see it on a side of their plane decided by rounding.
    fn off_polygon_planes(&self, p: DVec3) -> DVec3 {
        let c = self.surface.covering();
        if c.triangles.len() == c.num_faces() {
            return p;
        }
        let mut near = Vec::new();
        self.tree.any_near(p, p, self.surface.eps(), |t| {
            near.push(t);
            false
        });
        self.surface.off_polygon_planes(p, near)
    }

    /// The generalized winding number at `p` with its certified bound (first tree walk).
    pub fn estimate(&self, p: DVec3) -> Estimate {
        self.tree.winding(p, TOLERANCES[0])
    }

    /// Labels the samples of `lattice` in slices `j` that blocks decide whole (`put(i, j, k,
    /// class, interval of w)`, `i` a range along x) and returns the others, (i, j, k).
    /// Blocks of fewer than `min_block` samples are not tried (all their samples are
    /// returned).
    fn label_slab(
        &self,
        lattice: &Lattice,
        j: std::ops::Range<usize>,
        min_block: usize,
        put: &mut dyn FnMut(std::ops::Range<usize>, usize, usize, Class, Estimate),
    ) -> Vec<[u32; 3]> {
        let n = lattice.n;
        let mut left = Vec::new();
        let mut stack = vec![[0..n, j, 0..n]];
        while let Some(block) = stack.pop() {
            let size = block.iter().map(|r| r.len()).product::<usize>();
            let decided = if size >= min_block { self.certify(lattice, &block) } else { None };
            if let Some((class, e)) = decided {
                for jj in block[1].clone() {
                    for k in block[2].clone() {
                        put(block[0].clone(), jj, k, class, e);
                    }
                }
                continue;
            }
            let longest = (0..3).max_by_key(|&a| (block[a].len(), a)).unwrap_or(0);
            let r = &block[longest];
            if size < min_block || r.len() <= 1 {
                for jj in block[1].clone() {
                    for k in block[2].clone() {
                        left.extend(block[0].clone().map(|i| [i as u32, jj as u32, k as u32]));
                    }
                }
                continue;
            }
            let mid = r.start + r.len() / 2;
            let (mut a, mut b) = (block.clone(), block);
            a[longest] = a[longest].start..mid;
            b[longest] = mid..b[longest].end;
            stack.push(b);
            stack.push(a);
        }
        left
    }

    /// An anchor at `p` (off the boundary): the point evaluated and its estimate.
    fn anchor(&self, p: DVec3) -> (DVec3, Estimate) {
        let q = self.off_polygon_planes(p);
        (q, self.tree.winding(q, TOLERANCES[0]))
    }

    /// w(p) from the anchor `q` (off the boundary) with estimate `at_q`: the signed
    /// crossings of the segment qp added, the drift bounded by the gradient bound; `None`
    /// when the segment meets an edge or a vertex, or Γ comes too close.
    fn walk(&self, q: DVec3, at_q: Estimate, p: DVec3) -> Option<Estimate> {
        let (mut k, mut degenerate) = (0i32, false);
        self.tree.any_near(q.min(p), q.max(p), 0.0, |t| {
            match self.crossing(t, q, p) {
                Some(s) => k += s,
                None => degenerate = true,
            }
            degenerate
        });
        if degenerate { None } else { self.drift(q, at_q, p, k) }
    }

    /// Whether the segment q→p crosses covering triangle `t` (see [`crossing`]).
    fn crossing(&self, t: usize, q: DVec3, p: DVec3) -> Option<i32> {
        let [a, b, c] = self.surface.covering().triangle(t);
        crossing(a, b, c, q, p)
    }

    /// The estimate at `p` from the one at `q` and the `k` signed crossings between them.
    fn drift(&self, q: DVec3, at_q: Estimate, p: DVec3, k: i32) -> Option<Estimate> {
        let half = q.distance(p) * 0.5 * (1.0 + 1e-12);
        let slope = self.boundary.gradient_bound((q + p) * 0.5, half)?;
        Some(Estimate { w: at_q.w + k as f64, err: at_q.err + slope * 2.0 * half })
    }

    /// The class of `p` (off the boundary) from an anchor, or on its own.
    fn classify_from(&self, anchor: Option<&(DVec3, Estimate)>, p: DVec3) -> Class {
        let walked = anchor.and_then(|&(q, e)| self.walk(q, e, p)).and_then(|e| e.decides(0.0));
        self.decided_or_point(walked, p)
    }

    /// The class a bound decided (`Some(inside)`), else `p`'s own answer.
    fn decided_or_point(&self, decided: Option<bool>, p: DVec3) -> Class {
        match decided {
            Some(true) => Class::Inside,
            Some(false) => Class::Outside,
            None => self.classify_point(p).0,
        }
    }

    /// The class every sample of `block` has, when one evaluation at its centre proves it.
    /// With it, the interval of w that holds at every sample of the block.
    fn certify(&self, lattice: &Lattice, block: &[std::ops::Range<usize>; 3]) -> Option<(Class, Estimate)> {
        let eps = self.surface.eps();
        let lo = lattice.sample(block[0].start, block[1].start, block[2].start) - lattice.pad - eps;
        let hi = lattice.sample(block[0].end - 1, block[1].end - 1, block[2].end - 1) + lattice.pad + eps;
        if self.tree.may_meet_box(lo - eps, hi + eps) {
            return None;
        }
        let c = (lo + hi) * 0.5;
        let radius = (hi - lo).length() * 0.5 * (1.0 + 1e-12);
        let slope = self.boundary.gradient_bound(c, radius)?;
        let e = self.tree.winding(c, TOLERANCES[0]);
        let spread = Estimate { w: e.w, err: e.err + slope * radius };
        spread.decides(MARGIN).map(|inside| (if inside { Class::Inside } else { Class::Outside }, spread))
    }

    /// The cell grid for `inclusion`: n³ cells over the covering's box.
    fn cells(&self, n: usize) -> Cells {
        let (lo, hi) = self.surface.bounds();
        let side = (hi - lo).max_element().max(f64::MIN_POSITIVE);
        let h = side / n as f64;
        let origin = (lo + hi) * 0.5 - DVec3::splat(side * 0.5);
        let lattice = Lattice { origin, h, n, pad: 0.5 * h };
        let mut labels = vec![UNKNOWN; n * n * n];
        let slab = slab_height(n);
        let left: Vec<Vec<[u32; 3]>> = labels
            .par_chunks_mut(slab * n * n)
            .enumerate()
            .map(|(s, chunk)| {
                let j0 = s * slab;
                let j1 = (j0 + slab).min(n);
                let mut put = |i: std::ops::Range<usize>, j: usize, k: usize, class: Class, _: Estimate| {
                    let row = ((j - j0) * n + k) * n;
                    chunk[row + i.start..row + i.end].fill(class as u8);
                };
                self.label_slab(&lattice, j0..j1, 1, &mut put)
            })
            .collect();
        // Undecided cells get their centre as anchor (when it is off the boundary).
        let mut anchors: Vec<(u32, (DVec3, Estimate))> = left
            .concat()
            .into_par_iter()
            .filter_map(|[i, j, k]| {
                let c = lattice.sample(i as usize, j as usize, k as usize);
                let index = ((j as usize * n + k as usize) * n + i as usize) as u32;
                (!self.on_boundary(c)).then(|| (index, self.anchor(c)))
            })
            .collect();
        // By cell, for the binary search of `Cells::lookup`.
        anchors.par_sort_unstable_by_key(|a| a.0);
        Cells { lattice, labels, anchors }
    }

    /// The voxels of `grid` whose centre is inside by the rule: the same label `classify`
    /// gives each centre (centres on the boundary are not occupied).
    pub fn voxelize(&self, grid: &Grid) -> crate::voxel::Result<Volume> {
        let n = grid.n;
        let mut volume = Volume::new(n)?;
        let lattice = Lattice { origin: grid.min, h: grid.h(), n, pad: 0.0 };
        let slab = slab_height(n);
        volume.par_slabs(slab, |mut s| {
            let j = s.slices();
            // Where blocks decide: the voxels, and per row the spans with their interval of w.
            let mut spans: Vec<(u32, u32, u32, Estimate)> = Vec::new();
            let mut put = |i: std::ops::Range<usize>, j: usize, k: usize, class: Class, e: Estimate| {
                if class == Class::Inside {
                    s.xor_span(j, k, i.start, i.end);
                }
                spans.push((j as u32, k as u32, i.end as u32, e));
            };
            let (j0, rows) = (j.start, j.len());
            let left = self.label_slab(&lattice, j, MIN_VOXEL_BLOCK, &mut put);
            spans.sort_unstable_by_key(|&(j, k, i, _)| (j, k, i));
            // The undecided voxels as bits per row, read back in row order.
            let wpr = n.div_ceil(64);
            let mut bits = vec![0u64; rows * n * wpr];
            for [i, jj, k] in left {
                bits[((jj as usize - j0) * n + k as usize) * wpr + i as usize / 64] |= 1 << (i % 64);
            }
            let eps = self.surface.eps();
            let covering = self.surface.covering();
            let (mut near, mut row, mut steps, mut edge) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
            for (r, words) in bits.chunks(wpr).enumerate() {
                if words.iter().all(|&w| w == 0) {
                    continue;
                }
                row.clear();
                for (at, &w) in words.iter().enumerate() {
                    let mut w = w;
                    while w != 0 {
                        row.push(at * 64 + w.trailing_zeros() as usize);
                        w &= w - 1;
                    }
                }
                let (j, k) = (j0 + r / n, r % n);
                let (first, last) = (row[0], row[row.len() - 1]);
                // The triangles near this row, from the voxel before its first undecided one.
                near.clear();
                let (start, end) =
                    (lattice.sample(first.saturating_sub(1), j, k), lattice.sample(last, j, k));
                self.tree.any_near(start - 2.0 * eps, end + 2.0 * eps, 0.0, |t| {
                    let [a, b, c] = covering.triangle(t);
                    near.push((t, a.min(b).min(c), a.max(b).max(c)));
                    false
                });
                // Per voxel from the one before the first: the signed crossings of the step
                // from the previous centre (`None`: through an edge or a vertex), and whether
                // it is on the boundary; each triangle visits the few voxels it spans.
                let base = first.saturating_sub(1);
                let len = last + 1 - base;
                steps.clear();
                steps.resize(len, Some(0i32));
                edge.clear();
                edge.resize(len, false);
                let (h, ox) = (lattice.h, lattice.origin.x);
                let index = |x: f64| ((x - ox) / h - 0.5).floor();
                for &(t, lo, hi) in &near {
                    let from = (index(lo.x - eps) - 1.0).max(base as f64) as usize;
                    let to = (index(hi.x + eps) + 2.0).min(last as f64);
                    if to < from as f64 {
                        continue;
                    }
                    let to = to as usize;
                    let face = covering.face_of[t] as usize;
                    let [a, b, c] = covering.triangle(t);
                    let (y, z) = (start.y, start.z);
                    let near_yz = lo.y - eps <= y && y <= hi.y + eps && lo.z - eps <= z && z <= hi.z + eps;
                    if !near_yz {
                        continue;
                    }
                    // The row's line misses the triangle when its point in the yz plane is
                    // strictly outside the triangle's projection (as `crossing` decides it).
                    let yz = |v: DVec3| [v.y, v.z];
                    let nx = orient2d(yz(a), yz(b), yz(c));
                    let misses = nx != 0
                        && [(a, b), (b, c), (c, a)]
                            .iter()
                            .any(|&(u, v)| orient2d(yz(u), yz(v), [y, z]) == -nx);
                    // Off the plane by more than ε (with room for rounding): not on the boundary.
                    let n = (b - a).cross(c - a);
                    let off_plane = |p: DVec3| {
                        n.dot(p - a).abs() > (eps * (1.0 + 1e-9) + 1e-12 * p.distance(a)) * n.length()
                    };
                    let mut side = None;
                    for i in from..=to {
                        let p = lattice.sample(i, j, k);
                        if !edge[i - base]
                            && p.x >= lo.x - eps
                            && p.x <= hi.x + eps
                            && !off_plane(p)
                            && self.surface.on_face(face, p)
                        {
                            edge[i - base] = true;
                        }
                        if misses {
                            continue;
                        }
                        // Only a step whose ends are not strictly on one side may cross.
                        let here = orient3d(a, b, c, p);
                        if i > base && (side != Some(here) || here == 0) {
                            let q = lattice.sample(i - 1, j, k);
                            steps[i - base] = match (steps[i - base], crossing(a, b, c, q, p)) {
                                (Some(n), Some(d)) => Some(n + d),
                                _ => None,
                            };
                        }
                        side = Some(here);
                    }
                }
                let mut anchor: Option<(usize, DVec3, Estimate)> = None;
                // One gradient bound for the whole stretch of the row, when Γ keeps away.
                let slope =
                    self.boundary.gradient_bound((start + end) * 0.5, start.distance(end) * 0.5 + eps);
                for &i in &row {
                    let p = lattice.sample(i, j, k);
                    if edge[i - base] {
                        anchor = None;
                        continue;
                    }
                    // From the previous centre, or from a block that ends just before this one.
                    let prev = anchor.take().filter(|a| a.0 + 1 == i).or_else(|| {
                        let at =
                            spans.binary_search_by_key(&(j as u32, k as u32, i as u32), |x| (x.0, x.1, x.2));
                        at.ok().map(|at| (i - 1, lattice.sample(i - 1, j, k), spans[at].3))
                    });
                    let walked = prev
                        .and_then(|(_, q, e)| {
                            let step = steps[i - base]?;
                            if q != lattice.sample(i - 1, j, k) {
                                return self.walk(q, e, p); // an anchor moved off a polygon's plane
                            }
                            match slope {
                                Some(g) => Some(Estimate {
                                    w: e.w + step as f64,
                                    err: e.err + g * q.distance(p) * (1.0 + 1e-12),
                                }),
                                None => self.drift(q, e, p, step),
                            }
                        })
                        .filter(|e| e.decides(0.0).is_some());
                    let (q, e) = match walked {
                        Some(e) => (p, e),
                        None => self.anchor(p),
                    };
                    if self.decided_or_point(e.decides(0.0), p) == Class::Inside {
                        s.xor_span(j, k, i, i + 1);
                    }
                    anchor = Some((i, q, e));
                }
            }
        });
        Ok(volume)
    }
}

/// Whether the segment q→p crosses the triangle abc: 0 (no), +1 from the side its normal
/// points to, −1 the other way; `None` when it meets an edge or a vertex or has an end on
/// the triangle's plane where the line meets it (exact predicates).
fn crossing(a: DVec3, b: DVec3, c: DVec3, q: DVec3, p: DVec3) -> Option<i32> {
    let (sq, sp) = (orient3d(a, b, c, q), orient3d(a, b, c, p));
    if sq == sp && sq != 0 {
        return Some(0);
    }
    let t = [orient3d(q, p, a, b), orient3d(q, p, b, c), orient3d(q, p, c, a)];
    if t.contains(&1) && t.contains(&-1) {
        return Some(0);
    }
    if sq == 0 || sp == 0 || t.contains(&0) {
        return None;
    }
    Some(if sq > 0 { 1 } else { -1 })
}

/// Slices per parallel task of the cell labelling: about 16 slabs (large blocks stay
/// whole; two to a few dozen cores get work).
fn slab_height(n: usize) -> usize {
    n.div_ceil(16).max(4)
}

/// Cells (i, j, k) of size h from `origin`, each with its sample at the centre
/// `origin + (i + ½)·h` (per coordinate, as [`Grid::centre`] computes it); a block of cells
/// covers the box of its samples grown by `pad` (h/2: the whole cells; 0: the samples).
#[derive(Clone, Copy, Debug)]
struct Lattice {
    origin: DVec3,
    h: f64,
    n: usize,
    pad: f64,
}

impl Lattice {
    fn sample(&self, i: usize, j: usize, k: usize) -> DVec3 {
        let c = |o: f64, i: usize| o + (i as f64 + 0.5) * self.h;
        DVec3::new(c(self.origin.x, i), c(self.origin.y, j), c(self.origin.z, k))
    }
}

const UNKNOWN: u8 = 3;

/// Certified cells: labels (0 outside, 1 inside, [`UNKNOWN`]) of an n³ grid, x fastest,
/// and the anchors of the undecided cells (by cell index).
#[derive(Clone, Debug)]
struct Cells {
    lattice: Lattice,
    labels: Vec<u8>,
    anchors: Vec<(u32, (DVec3, Estimate))>,
}

impl Cells {
    /// The cell holding `p`: its label if it was decided whole, else its anchor (if any).
    /// (A point on a face between cells may land in either: both hold it.)
    fn lookup(&self, p: DVec3) -> Option<Result<Class, Option<&(DVec3, Estimate)>>> {
        let l = &self.lattice;
        let g = (p - l.origin) / l.h;
        if !(g.cmpge(DVec3::ZERO).all() && g.cmple(DVec3::splat(l.n as f64)).all()) {
            return None;
        }
        let idx = |x: f64| (x as usize).min(l.n - 1);
        let cell = (idx(g.y) * l.n + idx(g.z)) * l.n + idx(g.x);
        Some(match self.labels[cell] {
            0 => Ok(Class::Outside),
            1 => Ok(Class::Inside),
            _ => Err(self
                .anchors
                .binary_search_by_key(&(cell as u32), |a| a.0)
                .ok()
                .map(|at| &self.anchors[at].1)),
        })
    }
}

/// The boundary curve Γ: covering edges whose directed uses do not cancel, with their
/// net multiplicity, in spatial groups for [`Boundary::gradient_bound`].
#[derive(Clone, Debug)]
struct Boundary {
    /// End points and |net multiplicity|, grouped: group g is `edges[g·EDGE_GROUP..]`.
    edges: Vec<(DVec3, DVec3, f64)>,
    /// Per group: bounds and Σ multiplicity × length.
    groups: Vec<(DVec3, DVec3, f64)>,
}

impl Boundary {
    fn new(covering: &Covering) -> Boundary {
        let mut uses: Vec<(u32, u32, i32)> = covering
            .triangles
            .iter()
            .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
            .map(|(a, b)| if a < b { (a, b, 1) } else { (b, a, -1) })
            .collect();
        uses.par_sort_unstable_by_key(|&(a, b, _)| (a, b));
        let mut edges = Vec::new();
        for run in uses.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
            let m: i32 = run.iter().map(|x| x.2).sum();
            if m != 0 {
                let (a, b) = (covering.points[run[0].0 as usize], covering.points[run[0].1 as usize]);
                edges.push((a, b, m.unsigned_abs() as f64));
            }
        }
        group(&mut edges);
        let groups = edges
            .chunks(EDGE_GROUP)
            .map(|g| {
                g.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY, 0.0), |(lo, hi, l), &(a, b, m)| {
                    (lo.min(a).min(b), hi.max(a).max(b), l + m * a.distance(b))
                })
            })
            .collect();
        Boundary { edges, groups }
    }

    /// A bound of |∇w| over the ball of `radius` about `c` (`None`: Γ comes too close).
    fn gradient_bound(&self, c: DVec3, radius: f64) -> Option<f64> {
        let mut sum = 0.0;
        for (g, &(lo, hi, len)) in self.groups.iter().enumerate() {
            let gap = (lo - c).max(c - hi).max(DVec3::ZERO).length() - radius;
            if gap > 2.0 * (hi - lo).length() {
                sum += len / (gap * gap);
                continue;
            }
            let end = ((g + 1) * EDGE_GROUP).min(self.edges.len());
            for &(a, b, m) in &self.edges[g * EDGE_GROUP..end] {
                let d = c.distance(closest_point_on_segment(c, a, b)) * (1.0 - 1e-12) - radius;
                if d <= 0.0 {
                    return None;
                }
                sum += m * a.distance(b) / (d * d);
            }
        }
        // Relative margin for the rounding of the sum and the distances.
        Some(sum / (4.0 * PI) * (1.0 + 1e-9))
    }
}

/// Orders edges so that consecutive groups of [`EDGE_GROUP`] are compact (median splits
/// along the longest axis of their midpoints).
fn group(edges: &mut [(DVec3, DVec3, f64)]) {
    if edges.len() <= EDGE_GROUP {
        return;
    }
    let mid = |e: &(DVec3, DVec3, f64)| (e.0 + e.1) * 0.5;
    let (lo, hi) =
        edges.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(l, h), e| (l.min(mid(e)), h.max(mid(e))));
    let ext = hi - lo;
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    // Split at a multiple of the group size so that groups do not straddle the halves.
    let half = (edges.len() / 2).div_ceil(EDGE_GROUP) * EDGE_GROUP;
    if half >= edges.len() {
        return;
    }
    edges.select_nth_unstable_by(half, |a, b| mid(a)[axis].total_cmp(&mid(b)[axis]));
    let (a, b) = edges.split_at_mut(half);
    group(a);
    group(b);
}

impl Classifier for FastWinding {
    fn name(&self) -> &str {
        "fast-winding"
    }

    fn classify(&self, p: DVec3) -> Class {
        match self.cells.as_ref().and_then(|c| c.lookup(p)) {
            Some(Ok(class)) => class,
            Some(Err(anchor)) if !self.on_boundary(p) => self.classify_from(anchor, p),
            _ => self.classify_point(p).0,
        }
    }

    fn build_stats(&self) -> BuildStats {
        self.stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::procedural;

    #[test]
    fn every_undecided_cell_finds_its_anchor() {
        // A cube without its top: cells near its faces and its open side are undecided.
        let cube = procedural::cube();
        let open = Mesh::new(cube.positions().to_vec(), cube.faces().take(5).map(<[u32]>::to_vec).collect())
            .unwrap();
        let fw = FastWinding::new(&open, 100_000).unwrap();
        let cells = fw.cells.as_ref().unwrap();
        assert!(!cells.anchors.is_empty());
        let n = cells.lattice.n;
        for &(index, _) in &cells.anchors {
            let index = index as usize;
            let (i, k, j) = (index % n, (index / n) % n, index / (n * n));
            let found = cells.lookup(cells.lattice.sample(i, j, k));
            assert!(matches!(found, Some(Err(Some(_)))), "cell ({i}, {j}, {k})");
        }
    }
}

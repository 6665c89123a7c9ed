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
//! lattice ([`Lattice`]) of cells of a grid over the mesh's box, sized by the number of
//! points.
//!
//! **Near the surface.** Crossing the surface from the side its normal points to changes
//! w by exactly +1, so from an *anchor* Q with a certified estimate,
//! w(P) = w(Q) + (signed crossings of the segment QP) + drift, |drift| ≤ |∇w| bound × |QP|,
//! the crossings decided with exact orientation predicates ([`crate::exact`]). A segment
//! through an edge or a vertex, or a bound that does not decide, sends P to the per-point
//! path. Undecided cells get their centre as anchor.
//!
//! **Voxels.** `voxelize` closes the surface instead: over each loop of Γ a cone from the
//! loop's centroid ([`Caps`]), so that surface and caps form a closed chain C. Its winding
//! number is an integer, counted exactly along each row of voxel centres by the
//! scanline's signed crossings under its tie rule, as for a solid (the chain may cross
//! itself: the count is signed, not a parity); and w = w_C − w(caps). The caps are small
//! when the holes are: beyond a distance of each loop that a cone bound gives,
//! |w(caps)| ≤ ¼, so w ≥ ½ iff w_C ≥ 1 there, and nearer, w(caps) is evaluated with its
//! bound. A closed mesh (self-intersecting, nested, inverted) has no caps at all.
//!
//! Nothing here assumes a solid, so the meshes the solidity rule refuses — open,
//! self-intersecting, nested, inverted — all get this answer; on a valid solid w is 0 or 1
//! and it is the solid's own answer.

use std::f64::consts::PI;
use std::sync::OnceLock;
use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;

use super::classifier::{BuildStats, Class, Classifier, vec_bytes};
use super::error::Result;
use super::multipole::{Estimate, Tree};
use super::surface::Surface;
use crate::exact::{closest_point_on_segment, orient3d};
use crate::mesh::Mesh;
use crate::mesh::covering::Covering;
use crate::mesh::disjoint_sets::UnionFind;
use crate::voxel::scanline::{self, index_range, z_extent_at};
use crate::voxel::volume::slab_lists;
use crate::voxel::{Grid, Solid, Volume};

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
    tree: OnceLock<Tree>,
    boundary: Boundary,
    cells: Option<Cells>,
    stats: BuildStats,
}

impl FastWinding {
    /// The classifier for `mesh` (any mesh: open, self-intersecting, …), with a cell grid
    /// sized for about `points` query points (none for few).
    pub fn new(mesh: &Mesh, points: usize) -> Result<FastWinding> {
        let start = Instant::now();
        let mut fw = FastWinding::for_voxels(mesh)?;
        if points >= MIN_POINTS_FOR_CELLS && !fw.tree().is_empty() {
            let n = ((points as f64 / 4.0).cbrt().round() as usize).clamp(4, MAX_CELLS);
            fw.cells = Some(fw.cells(n));
        }
        let bytes = fw.surface.bytes()
            + fw.tree().bytes()
            + vec_bytes(&fw.boundary.edges)
            + vec_bytes(&fw.boundary.groups)
            + fw.cells.as_ref().map_or(0, |c| vec_bytes(&c.labels) + vec_bytes(&c.anchors));
        fw.stats = BuildStats { build_time: start.elapsed(), bytes };
        Ok(fw)
    }

    pub fn surface(&self) -> &Surface {
        &self.surface
    }

    /// The classifier for [`Self::voxelize`]: its cluster tree is only built if a voxel
    /// centre needs it (for a mesh with small holes, or none, usually none does).
    pub fn for_voxels(mesh: &Mesh) -> Result<FastWinding> {
        let surface = Surface::with_policy(mesh, true)?;
        let boundary = Boundary::new(surface.covering());
        Ok(FastWinding {
            surface,
            tree: OnceLock::new(),
            boundary,
            cells: None,
            stats: BuildStats::default(),
        })
    }

    pub fn tree(&self) -> &Tree {
        self.tree.get_or_init(|| Tree::new(self.surface.covering()))
    }

    /// Number of directed edges of the boundary curve Γ (0 for a closed mesh).
    pub fn boundary_edges(&self) -> usize {
        self.boundary.edges.len()
    }

    /// True when `p` is within ε of a face (the shared exact predicate).
    fn on_boundary(&self, p: DVec3) -> bool {
        self.surface.in_bounds(p)
            && self.tree().any_near(p, p, self.surface.eps(), |t| self.surface.on_boundary_near(t, p))
    }

    /// The label of `p` without the cell grid, and how it was found.
    pub fn classify_point(&self, p: DVec3) -> (Class, Tier) {
        if self.on_boundary(p) {
            return (Class::OnBoundary, Tier::Boundary);
        }
        let p = self.off_polygon_planes(p);
        let class = |inside: bool| if inside { Class::Inside } else { Class::Outside };
        for (k, &tol) in TOLERANCES.iter().enumerate() {
            if let Some(inside) = self.tree().winding(p, tol).decides(0.0) {
                return (class(inside), Tier::Tree(k as u8));
            }
        }
        let e = self.tree().direct(p);
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
        self.tree().any_near(p, p, self.surface.eps(), |t| {
            near.push(t);
            false
        });
        self.surface.off_polygon_planes(p, near)
    }

    /// The generalized winding number at `p` with its certified bound (first tree walk).
    pub fn estimate(&self, p: DVec3) -> Estimate {
        self.tree().winding(p, TOLERANCES[0])
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
        (q, self.tree().winding(q, TOLERANCES[0]))
    }

    /// w(p) from the anchor `q` (off the boundary) with estimate `at_q`: the signed
    /// crossings of the segment qp added, the drift bounded by the gradient bound; `None`
    /// when the segment meets an edge or a vertex, or Γ comes too close.
    fn walk(&self, q: DVec3, at_q: Estimate, p: DVec3) -> Option<Estimate> {
        let (mut k, mut degenerate) = (0i32, false);
        self.tree().any_near(q.min(p), q.max(p), 0.0, |t| {
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
        if self.tree().may_meet_box(lo - eps, hi + eps) {
            return None;
        }
        let c = (lo + hi) * 0.5;
        let radius = (hi - lo).length() * 0.5 * (1.0 + 1e-12);
        let slope = self.boundary.gradient_bound(c, radius)?;
        let e = self.tree().winding(c, TOLERANCES[0]);
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

    /// The voxels of `grid` whose centre is inside by the rule: the label
    /// [`Self::classify_point`] gives each centre (centres on the boundary are not occupied).
    ///
    /// The covering and its [`Caps`] form a closed chain, whose winding number the
    /// scanline's signed crossings give exactly along every row
    /// ([`scanline::winding_steps`]); w = that count − w(caps). Away from the caps
    /// |w(caps)| ≤ ¼, so the count alone decides (inside iff ≥ 1); near them w(caps) is
    /// evaluated with its bound. Centres within ε of a face are not occupied; a centre no
    /// bound decides, on a cap's plane, within ε of the plane of a polygon's covering
    /// triangle, or on a row whose crossings do not sum to 0, is classified on its own.
    pub fn voxelize(&self, grid: &Grid) -> crate::voxel::Result<Volume> {
        let n = grid.n;
        let mut volume = Volume::new(n)?;
        let covering = self.surface.covering();
        let caps = Caps::new(covering, &self.boundary.net);
        let own = covering.triangles.len();
        let chain = Solid {
            triangles: (0..own).map(|t| covering.triangle(t)).chain(caps.triangles.iter().copied()).collect(),
            // The scanline does not use the apex.
            apex: DVec3::ZERO,
        };
        let (h, eps, wpr) = (grid.h(), self.surface.eps(), n.div_ceil(64));
        // A triangle's setup is paid once per slab it meets: slabs as tall as keeps every
        // thread busy (eight per thread, as the scanline's planes), never below the
        // rasterizers' height. Rows do not depend on the slabs, so neither does the volume.
        let threads = rayon::current_num_threads();
        let slab = n.div_ceil(8 * threads).max(crate::voxel::volume::slab_height(n));
        let lists = slab_lists(
            n,
            slab,
            chain.triangles.iter().map(|&[a, b, c]| {
                index_range(grid.min.y, h, n, a.y.min(b.y).min(c.y) - eps, a.y.max(b.y).max(c.y) + eps)
            }),
        );
        volume.par_slabs(slab, |mut s| {
            let slices = s.slices();
            let j0 = slices.start;
            let list = &lists[j0 / slab];
            let mut steps = Vec::new();
            scanline::winding_steps(&chain, grid, list.iter().copied(), slices.clone(), &mut steps);
            // Centres on the boundary, and centres to classify on their own, as bits by row.
            let mut boundary = vec![0u64; slices.len() * n * wpr];
            let mut alone = boundary.clone();
            for &t in list.iter().filter(|&&t| (t as usize) < own) {
                let corners = chain.triangles[t as usize];
                self.near_centres(t as usize, corners, grid, slices.clone(), |j, k, i, on| {
                    let bits = if on { &mut boundary } else { &mut alone };
                    bits[((j - j0) * n + k) * wpr + i / 64] |= 1 << (i % 64);
                });
            }
            let mut ranges: Vec<std::ops::Range<usize>> = Vec::new();
            let mut at = 0;
            for j in slices {
                for k in 0..n {
                    let first = at;
                    while at < steps.len() && steps[at].0 as usize == j * n + k {
                        at += 1;
                    }
                    let row_steps = &steps[first..at];
                    ranges.clear();
                    ranges.extend(caps.on_row(grid, j, k));
                    if row_steps.is_empty() && ranges.is_empty() {
                        continue;
                    }
                    let point = |i: usize| self.classify_point(grid.centre(i, j, k)).0 == Class::Inside;
                    let set = |row: &mut [u64], i: usize, inside: bool| {
                        if inside {
                            row[i / 64] |= 1 << (i % 64);
                        } else {
                            row[i / 64] &= !(1 << (i % 64));
                        }
                    };
                    if row_steps.iter().map(|x| x.2 as i32).sum::<i32>() != 0 {
                        // Not for a closed chain; should it happen, every centre on its own.
                        let row = s.row_mut(j, k);
                        for i in 0..n {
                            set(row, i, point(i));
                        }
                        continue;
                    }
                    // Centres from..f have the count w.
                    let (mut w, mut from) = (0i32, 0usize);
                    for &(_, f, sign) in row_steps {
                        if w >= 1 {
                            s.xor_span(j, k, from, f as usize);
                        }
                        (w, from) = (w + sign as i32, f as usize);
                    }
                    let r = ((j - j0) * n + k) * wpr;
                    let (on, alone) = (&boundary[r..r + wpr], &alone[r..r + wpr]);
                    let row = s.row_mut(j, k);
                    for (x, &m) in row.iter_mut().zip(on) {
                        *x &= !m;
                    }
                    let taken = |i: usize| (on[i / 64] | alone[i / 64]) >> (i % 64) & 1 == 1;
                    for (word, (&a, &b)) in alone.iter().zip(on).enumerate() {
                        let mut m = a & !b;
                        while m != 0 {
                            let i = word * 64 + m.trailing_zeros() as usize;
                            set(row, i, point(i));
                            m &= m - 1;
                        }
                    }
                    // Near a cap: w = count − w(caps), each centre once.
                    ranges.sort_unstable_by_key(|r| r.start);
                    let mut done = 0;
                    for range in &ranges {
                        for i in range.start.max(done)..range.end {
                            if taken(i) {
                                continue;
                            }
                            let count =
                                row_steps.iter().take_while(|x| x.1 as usize <= i).map(|x| x.2 as i32).sum();
                            set(row, i, caps.inside(grid.centre(i, j, k), count).unwrap_or_else(|| point(i)));
                        }
                        done = done.max(range.end);
                    }
                }
            }
        });
        Ok(volume)
    }

    /// Calls `mark(j, k, i, on)` for the centres (j in `slices`) that may be within ε of
    /// covering triangle `t`'s face (`corners`, as [`Covering::triangle`] gives them): `on`
    /// when the exact predicate says they are; the others are reported only for a polygon's
    /// triangle, whose plane they are near (where [`Self::classify_point`] moves a point off
    /// the plane first).
    fn near_centres(
        &self,
        t: usize,
        corners: [DVec3; 3],
        grid: &Grid,
        slices: std::ops::Range<usize>,
        mut mark: impl FnMut(usize, usize, usize, bool),
    ) {
        let covering = self.surface.covering();
        let (eps, n, h) = (self.surface.eps(), grid.n, grid.h());
        let [a, b, c] = corners;
        let (lo, hi) = (a.min(b).min(c) - eps, a.max(b).max(c) + eps);
        let nrm = (b - a).cross(c - a);
        let (len, l1) = (nrm.length(), nrm.abs().element_sum());
        // Off the plane by more than ε (with room for rounding): not on the boundary.
        let off_plane = |p: DVec3| nrm.dot(p - a).abs() > (eps * (1.0 + 1e-9) + 1e-12 * p.distance(a)) * len;
        let js = index_range(grid.min.y, h, n, lo.y, hi.y);
        let ks = index_range(grid.min.z, h, n, lo.z, hi.z);
        let plane = Plane { a, normal: nrm, len, eps };
        if !plane.near_box(grid, (lo, hi), js.start.max(slices.start)..js.end.min(slices.end), ks.clone()) {
            return;
        }
        let face = covering.face_of[t] as usize;
        let polygon = covering.face_triangles(face).len() > 1;
        let steep = nrm.x.abs() >= 1e-3 * l1;
        let reach_x = (lo.x - a.x).abs().max((hi.x - a.x).abs());
        for j in js.start.max(slices.start)..js.end.min(slices.end) {
            let y = grid.centre_coord(grid.min.y, j);
            if y < lo.y || y > hi.y {
                continue;
            }
            let Some((zlo, zhi)) = z_window([a, b, c], y, eps, h, (lo.z, hi.z)) else { continue };
            let row_ks = index_range(grid.min.z, h, n, zlo, zhi);
            for k in row_ks.start.max(ks.start)..row_ks.end.min(ks.end) {
                let z = grid.centre_coord(grid.min.z, k);
                if z < zlo || z > zhi {
                    continue;
                }
                // A centre that passes `off_plane` has |g + n_x·(x − a.x)| ≤ 2ε|n| (and
                // rounding), with |x − a.x| ≤ reach_x in the box.
                let (dy, dz) = ((y - a.y).abs(), (z - a.z).abs());
                let g = nrm.y * (y - a.y) + nrm.z * (z - a.z);
                let slack = 1e-9 * l1 * (dy + dz + reach_x);
                if g.abs() > 2.0 * eps * len + nrm.x.abs() * reach_x + slack {
                    continue;
                }
                let xs = if steep {
                    // Usually no centre at all: the plane is within ε of the row only near
                    // x0. The margin covers the rounding of x0 and of the indices.
                    let x0 = a.x - g / nrm.x;
                    let half = (2.0 * eps * len + slack) / nrm.x.abs()
                        + 1e-9 * (a.x.abs() + x0.abs() + grid.min.x.abs() + grid.side);
                    let first = (((x0 - half).max(lo.x) - grid.min.x) / h - 0.5).ceil().max(0.0);
                    let last = (((x0 + half).min(hi.x) - grid.min.x) / h - 0.5).floor();
                    if last.is_nan() || last < first {
                        continue;
                    }
                    first as usize..(last as usize + 1).min(n)
                } else {
                    index_range(grid.min.x, h, n, lo.x, hi.x)
                };
                for i in xs {
                    let p = DVec3::new(grid.centre_coord(grid.min.x, i), y, z);
                    if p.x < lo.x || p.x > hi.x || off_plane(p) {
                        continue;
                    }
                    let on = self.surface.on_face(face, p);
                    if on || polygon {
                        mark(j, k, i, on);
                    }
                }
            }
        }
    }
}

/// A triangle's plane through its corner `a` with (unnormalized) `normal` of length
/// `len`, and the distance ε of the boundary test.
struct Plane {
    a: DVec3,
    normal: DVec3,
    len: f64,
    eps: f64,
}

impl Plane {
    /// Whether any voxel centre of the box `[lo, hi]` (rows `js` and `ks` of `grid`) may
    /// pass the near-plane test. Most triangles have no such centre (ε is far below a
    /// voxel), and a pass over the few centres of the box shows it before the rows are
    /// walked: whatever their distance to a, those centres' thresholds are at most the
    /// box's (rounding is monotone), so a centre whose |n·(p − a)| exceeds it is off the
    /// plane. NaN counts as near.
    fn near_box(
        &self,
        grid: &Grid,
        (lo, hi): (DVec3, DVec3),
        js: std::ops::Range<usize>,
        ks: std::ops::Range<usize>,
    ) -> bool {
        let (n, h, a) = (grid.n, grid.h(), self.a);
        let inner = |axis: usize, r: std::ops::Range<usize>| {
            let (min, mut r) = (grid.min[axis], r);
            while r.start < r.end && grid.centre_coord(min, r.start) < lo[axis] {
                r.start += 1;
            }
            while r.start < r.end && grid.centre_coord(min, r.end - 1) > hi[axis] {
                r.end -= 1;
            }
            r
        };
        let box_is = inner(0, index_range(grid.min.x, h, n, lo.x, hi.x));
        let box_js = inner(1, js);
        let box_ks = inner(2, ks);
        if box_is.is_empty() || box_js.is_empty() || box_ks.is_empty() {
            return false;
        }
        let reach = |axis: usize, r: &std::ops::Range<usize>| {
            let at = |i: usize| (grid.centre_coord(grid.min[axis], i) - a[axis]).abs();
            at(r.start).max(at(r.end - 1))
        };
        let far = DVec3::new(reach(0, &box_is), reach(1, &box_js), reach(2, &box_ks)).length();
        let threshold = (self.eps * (1.0 + 1e-9) + 1e-12 * far) * self.len;
        threshold.is_nan()
            || box_js.clone().any(|j| {
                let y = grid.centre_coord(grid.min.y, j);
                box_ks.clone().any(|k| {
                    let z = grid.centre_coord(grid.min.z, k);
                    box_is.clone().any(|i| {
                        let d = self.normal.dot(DVec3::new(grid.centre_coord(grid.min.x, i), y, z) - a).abs();
                        d.is_nan() || d <= threshold
                    })
                })
            })
    }
}

/// The z range of the row at `y` where a centre may lie within ε of the triangle
/// `corners`, clipped to `z_box`; `None` if empty. Such a centre has its (y, z) within ε
/// of the triangle's (y, z) projection: z within the projection's z extent over y ± ε,
/// grown by ε (the extent's ends are convex and concave in y, so the slices at y ± ε and
/// the corners between them bound it), with room for rounding (`h`: the voxel size).
fn z_window(corners: [DVec3; 3], y: f64, eps: f64, h: f64, z_box: (f64, f64)) -> Option<(f64, f64)> {
    let ey = 2.0 * eps + 1e-9 * (y.abs() + h);
    let (mut zlo, mut zhi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (l, u) in [y - ey, y + ey].into_iter().filter_map(|yy| z_extent_at(&corners, yy)) {
        (zlo, zhi) = (zlo.min(l), zhi.max(u));
    }
    for v in corners.into_iter().filter(|v| (v.y - y).abs() <= ey) {
        (zlo, zhi) = (zlo.min(v.z), zhi.max(v.z));
    }
    if zlo > zhi {
        return None;
    }
    let margin = ey + 1e-9 * (zlo.abs() + zhi.abs() + h);
    let (zlo, zhi) = ((zlo - margin).max(z_box.0), (zhi + margin).min(z_box.1));
    if zlo > zhi {
        return None;
    }
    Some((zlo, zhi))
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
    /// Γ by covering points: (a, b, m) with a < b, the edge a→b used m (≠ 0) more times
    /// than b→a.
    net: Vec<(u32, u32, i32)>,
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
        let net: Vec<(u32, u32, i32)> = uses
            .chunk_by(|x, y| (x.0, x.1) == (y.0, y.1))
            .map(|run| (run[0].0, run[0].1, run.iter().map(|x| x.2).sum()))
            .filter(|&(_, _, m)| m != 0)
            .collect();
        let mut edges: Vec<(DVec3, DVec3, f64)> = net
            .iter()
            .map(|&(a, b, m)| {
                (covering.points[a as usize], covering.points[b as usize], m.unsigned_abs() as f64)
            })
            .collect();
        group(&mut edges);
        let groups = edges
            .chunks(EDGE_GROUP)
            .map(|g| {
                g.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY, 0.0), |(lo, hi, l), &(a, b, m)| {
                    (lo.min(a).min(b), hi.max(a).max(b), l + m * a.distance(b))
                })
            })
            .collect();
        Boundary { edges, groups, net }
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

/// The boundary curve Γ capped: over each of its loops (connected components) the cone
/// from the loop's vertex centroid, oriented against Γ, so that the covering and the caps
/// together form a closed chain (every directed edge used as often as its reverse; the
/// caps may cross the surface).
#[derive(Clone, Debug)]
struct Caps {
    triangles: Vec<[DVec3; 3]>,
    /// Per loop: its apex, and the distance from it beyond which |w| of its cone is at
    /// most ¼ / (number of loops).
    balls: Vec<(DVec3, f64)>,
    /// The caps' triangles, for their winding number with a bound.
    tree: Tree,
}

impl Caps {
    fn new(covering: &Covering, net: &[(u32, u32, i32)]) -> Caps {
        let mut sets = UnionFind::new(covering.points.len());
        for &(a, b, _) in net {
            sets.union(a, b);
        }
        // Per loop: the sum and number of its vertices, and its number of triangles.
        let (mut loop_of, mut seen) =
            (vec![u32::MAX; covering.points.len()], vec![false; covering.points.len()]);
        let mut loops: Vec<(DVec3, usize, usize)> = Vec::new();
        for &(a, b, m) in net {
            let root = sets.find(a) as usize;
            if loop_of[root] == u32::MAX {
                loop_of[root] = loops.len() as u32;
                loops.push((DVec3::ZERO, 0, 0));
            }
            let l = &mut loops[loop_of[root] as usize];
            for v in [a as usize, b as usize] {
                if !std::mem::replace(&mut seen[v], true) {
                    l.0 += covering.points[v];
                    l.1 += 1;
                }
            }
            l.2 += m.unsigned_abs() as usize;
        }
        let apexes: Vec<DVec3> = loops.iter().map(|&(sum, count, _)| sum / count as f64).collect();
        let mut radius = vec![0.0f64; loops.len()];
        let mut triangles = Vec::new();
        for &(a, b, m) in net {
            let l = loop_of[sets.find(a) as usize] as usize;
            let (pa, pb, c) = (covering.points[a as usize], covering.points[b as usize], apexes[l]);
            radius[l] = radius[l].max(pa.distance(c)).max(pb.distance(c));
            let t = if m > 0 { [pb, pa, c] } else { [pa, pb, c] };
            triangles.extend(std::iter::repeat_n(t, m.unsigned_abs() as usize));
        }
        // m triangles within ρ of the apex, seen from d > ρ, each fill at most the spherical
        // cap of half-angle α = asin(ρ/d): |w| ≤ m (1 − cos α) / 2, at most ¼ / L (L loops)
        // when cos α ≥ 1 − 1/(2 m L). One per cent more for the rounding of ρ and d.
        let balls = apexes
            .iter()
            .zip(&radius)
            .zip(&loops)
            .map(|((&c, &rho), &(_, _, m))| {
                let cos = 1.0 - 0.5 / (m.max(1) * loops.len()) as f64;
                (c, rho / (1.0 - cos * cos).sqrt() * 1.01)
            })
            .collect();
        let tree = Tree::from_triangles(triangles.iter().copied());
        Caps { triangles, balls, tree }
    }

    /// The centres of row (j, k) (index ranges along x, with a margin) within a ball.
    fn on_row<'a>(
        &'a self,
        grid: &'a Grid,
        j: usize,
        k: usize,
    ) -> impl Iterator<Item = std::ops::Range<usize>> + 'a {
        let (y, z) = (grid.centre_coord(grid.min.y, j), grid.centre_coord(grid.min.z, k));
        self.balls.iter().filter_map(move |&(c, r)| {
            let d2 = r * r - (y - c.y) * (y - c.y) - (z - c.z) * (z - c.z);
            let half = d2.sqrt();
            (d2 >= 0.0)
                .then(|| index_range(grid.min.x, grid.h(), grid.n, c.x - half, c.x + half))
                .filter(|r| !r.is_empty())
        })
    }

    /// Whether w ≥ ½ at `p` (off the boundary), where the closed chain winds `count` times
    /// (under the tie rule): w = count − w(caps), when a bound decides it and `p` is on no
    /// cap triangle's plane (where w(caps) would jump); `None` otherwise.
    fn inside(&self, p: DVec3, count: i32) -> Option<bool> {
        let on_plane = self.tree.any_near(p, p, 0.0, |t| {
            let [a, b, c] = self.triangles[t];
            orient3d(a, b, c, p) == 0
        });
        if on_plane {
            return None;
        }
        TOLERANCES.iter().find_map(|&tol| {
            let e = self.tree.winding(p, tol);
            let k = count as f64;
            Estimate { w: k - e.w, err: e.err + 2.0 * f64::EPSILON * (k.abs() + e.w.abs()) }.decides(0.0)
        })
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

//! The exact Feito-Torres point-in-solid test (Alg. 4-1, §4.3.1, made precise in SPEC §3.1).
//!
//! For every covering tetra T = (O, Q1, Q2, Q3) with sign s, P adds 2s when strictly
//! inside T, s when on exactly one face through O (that face's other tetra adds the other
//! half), and nothing when outside; P within ε of a base triangle's face is OnBoundary.
//! The sum is 2·w(P), w the winding number, so P is Inside iff the sum is non-zero (the
//! thesis' `acc == 2` for every valid solid, where w ∈ {0, 1}).
//!
//! ## Points on an apex edge O–Qj: the thesis' vertex-set rule is not exact
//!
//! Alg. 4-1 adds +2 once per vertex Qj if any positive tetra has P on O–Qj, and −2 once
//! if any negative one has. The exact contribution of the fan of tetras around O–Qj is
//! 2k, k the winding number of Qj's link (its neighbours' polygon) projected along O–Qj
//! around that line. The rule assumes k = [some fan tetra positive] − [some negative]:
//!
//! - right when the fan has one sign and Qj is a manifold vertex of an embedded surface
//!   (its link is a simple loop, so k = ±1), or when the fan is mixed and the link does
//!   not wind (k = 0), e.g. an L-prism's reflex corner or a dimple seen from the side;
//! - **wrong** for a saddle vertex seen so that its link folds back but still winds once
//!   (mixed signs, k = 1: the rule adds 0 instead of 2);
//! - **wrong** at a non-manifold vertex, e.g. two cubes sharing an edge, O inside one cube
//!   and P on the segment from O to an end of the shared edge: the fan of the other cube is
//!   mixed (k = 0 there) while the first cube's fan is positive (k = 1), and the rule,
//!   which counts each vertex once per sign, adds 0 instead of 2.
//!
//! `tests/inclusion_cpu.rs` builds these cases and checks them against the winding-number
//! oracle. Exactness wins (SPEC §3.1): by default ([`EdgeRule::Rerun`]) a point on an
//! apex edge is resolved like P = O or P in a flat tetra — by running the test again with
//! another apex, from a fixed pseudo-random sequence. [`EdgeRule::VertexSets`] keeps the
//! thesis' rule for comparison.
//!
//! ## Exactness
//!
//! With the tolerance rule of [`crate::inclusion`], every decision is either taken with a
//! margin > ε (so f64 rounding cannot flip it), shared bit for bit with the one other tetra
//! it concerns (faces through O), or sent to the fallback: a re-run with another apex when
//! the pass saw an apex edge, the apex, a flat tetra, or ended with an odd sum (a pairing
//! broken by a degenerate neighbour), and points within `1e-4·D` of the apex go straight
//! to a re-run. The winding number, reliable off the boundary, has the last word after
//! [`MAX_RERUNS`] ambiguous re-runs, and at once for a point on an apex edge within
//! [`NEAR_VERTEX`]·ε of its base vertex (a point off the boundary but that close to a mesh
//! vertex or face centroid is within ε of every apex edge ending there, for any apex).
//!
//! Within ε of a base plane the point is first checked against the face itself
//! (OnBoundary); if it is off the face, the side of the base is taken from the face's own
//! plane when the face is a planar n-gon, so that a non-convex face's overlapping positive
//! and negative triangles decide alike and cancel.
//!
//! ## Speed
//!
//! `classify` is the thesis' baseline: one pass over every tetra, four plane tests each,
//! evaluated without early exits (which tetras a point misses follows no pattern a branch
//! predictor learns). Tetras are stored along a Morton curve of their triangles, so the
//! optimizers, which read scattered subsets, touch runs of neighbours; they also prefilter
//! with f32 planes ([`CompactPlanes`]) that only reject what the f64 test rejects.

use std::time::Instant;

use glam::DVec3;

use super::classifier::{BuildStats, Class, Classifier, vec_bytes};
use super::error::Result;
use super::surface::Surface;
use super::tetra::{CompactPlanes, CompactPoint, Contact, TetraPlanes, Verdict, octant_bit};
use super::winding;
use crate::mesh::Mesh;
use crate::mesh::covering::Covering;
use crate::random::Rng;

/// Re-runs with other apexes before giving up and using the winding number.
pub const MAX_RERUNS: usize = 8;
/// Points closer than this (× bounding-box diagonal, max-norm) to the apex are re-run
/// with another apex: near O the faces through O crowd within ε of each other.
pub const APEX_BALL: f64 = 1e-4;
/// A point this close (× ε) to a covering point, but off the boundary, is within ε of every
/// apex edge ending there whatever the apex: re-runs cannot help, the winding number decides.
pub const NEAR_VERTEX: f64 = 4.0;
/// Default apex: the bounding-box centre moved by this (× the box's extent per axis), so
/// symmetric models do not put the apex on their symmetry planes, edges or vertices.
pub const APEX_SHIFT: DVec3 = DVec3::new(0.013_7, -0.021_1, 0.017_3);
const RERUN_SEED: u64 = 0x7e7a_a9e7;

/// How a point on an apex edge O–Qj is counted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeRule {
    /// Re-run with another apex (exact; the default).
    Rerun,
    /// The thesis' positive/negative vertex sets (not exact, see the module docs).
    VertexSets,
}

/// What happened while classifying one point (for tests, debugging and GPU fallbacks).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Trace {
    pub class: Class,
    /// Sum of the last pass (2·winding number when decided).
    pub acc: i32,
    /// Tetras the point was strictly inside of, on one face through O of, on an apex edge of.
    pub interior: u32,
    pub side: u32,
    pub apex_edges: u32,
    /// Tetras whose base plane the point was within ε of.
    pub near_base: u32,
    /// Flat tetras the point was in.
    pub flat: u32,
    /// Passes run again with another apex.
    pub reruns: u32,
    /// True when the winding number had the last word.
    pub fallback: bool,
}

/// The exact Feito-Torres classifier (Alg. 4-1, §4.3.1) with basic preprocessing (Table
/// 4-1, optimizer 1): every tetra's planes and sign computed once, every tetra tested.
#[derive(Clone, Debug)]
pub struct FeitoTorres {
    surface: Surface,
    apex: DVec3,
    tetras: Vec<TetraPlanes>,
    /// Covering triangle of each tetra: tetras follow a Morton curve through the triangles'
    /// centroids, so tetras near in space are near in memory (cell lists of the TetraGrid,
    /// BVH leaves and GPU groups read runs of neighbours).
    order: Vec<u32>,
    rule: EdgeRule,
    apex_ball: f64,
    stats: BuildStats,
}

/// The apex used when none is given: near the centre of the bounding box (SPEC §3.1: any
/// point works; a central one keeps the tetras and the determinants small).
pub fn default_apex(surface: &Surface) -> DVec3 {
    let (lo, hi) = surface.bounds();
    (lo + hi) * 0.5 + APEX_SHIFT * (hi - lo)
}

enum Pass {
    Boundary,
    Decided(Class),
    Ambiguous,
}

#[derive(Default)]
struct Tally {
    acc: i32,
    ambiguous: bool,
    /// P is on an apex edge within [`NEAR_VERTEX`]·ε of its base vertex: no apex helps.
    near_vertex: bool,
    trace: Trace,
    /// The thesis' PosVert / NegVert (only filled with [`EdgeRule::VertexSets`]).
    pos: Vec<u32>,
    neg: Vec<u32>,
}

impl FeitoTorres {
    /// The classifier with the default apex and exact apex-edge handling.
    pub fn new(mesh: &Mesh) -> Result<FeitoTorres> {
        FeitoTorres::with_options(mesh, None, EdgeRule::Rerun)
    }

    /// The classifier with apex `apex` (the thesis uses the origin). Precision is best with
    /// the apex in or near the bounding box.
    pub fn with_apex(mesh: &Mesh, apex: DVec3) -> Result<FeitoTorres> {
        FeitoTorres::with_options(mesh, Some(apex), EdgeRule::Rerun)
    }

    pub fn with_options(mesh: &Mesh, apex: Option<DVec3>, rule: EdgeRule) -> Result<FeitoTorres> {
        FeitoTorres::with_policy(mesh, apex, rule, false)
    }

    /// As [`Self::with_options`]; `allow_open` accepts open surfaces (see [`Surface::with_policy`]).
    pub fn with_policy(
        mesh: &Mesh,
        apex: Option<DVec3>,
        rule: EdgeRule,
        allow_open: bool,
    ) -> Result<FeitoTorres> {
        let start = Instant::now();
        let surface = Surface::with_policy(mesh, allow_open)?;
        let apex = apex.unwrap_or_else(|| default_apex(&surface));
        let order = morton_order(surface.covering());
        let tetras = order.iter().map(|&t| tetra_at(&surface, apex, t as usize)).collect();
        let mut ft = FeitoTorres {
            order,
            apex_ball: APEX_BALL * surface.scale(),
            surface,
            apex,
            tetras,
            rule,
            stats: BuildStats::default(),
        };
        let bytes = ft.surface.bytes() + vec_bytes(&ft.tetras) + vec_bytes(&ft.order);
        ft.stats = BuildStats { build_time: start.elapsed(), bytes };
        Ok(ft)
    }

    pub fn apex(&self) -> DVec3 {
        self.apex
    }

    pub fn surface(&self) -> &Surface {
        &self.surface
    }

    pub fn edge_rule(&self) -> EdgeRule {
        self.rule
    }

    /// Per-tetra planes (relative to [`Self::apex`]), indexed by tetra id; tetra `t` is
    /// built on covering triangle [`Self::tetra_triangle`]`(t)`.
    pub fn tetras(&self) -> &[TetraPlanes] {
        &self.tetras
    }

    /// The covering triangle (index into `surface().covering().triangles`) of tetra `t`.
    pub fn tetra_triangle(&self, t: usize) -> usize {
        self.order[t] as usize
    }

    /// Q1, Q2, Q3 of tetra `t` (absolute); the fourth vertex is the apex.
    pub fn tetra_vertices(&self, t: usize) -> [DVec3; 3] {
        self.surface.covering().triangle(self.tetra_triangle(t))
    }

    /// Flat upload arrays for a GPU pass: Q1, Q2, Q3 of every tetra relative to the apex
    /// (9 floats each) and its sign (+1, −1, or 0 for flat/degenerate tetras, whose points
    /// must be resolved by [`Classifier::classify`]).
    pub fn flat_arrays(&self) -> (Vec<f32>, Vec<f32>) {
        let mut q = Vec::with_capacity(self.tetras.len() * 9);
        for t in 0..self.tetras.len() {
            for v in self.tetra_vertices(t) {
                q.extend_from_slice(&(v - self.apex).as_vec3().to_array());
            }
        }
        (q, self.tetras.iter().map(|t| t.sign as f32).collect())
    }

    /// Classifies `p` testing only the tetras in `candidates`. Exact as long as the
    /// candidates hold every tetra whose grown box and octant mask hold `p` (the others
    /// would answer `Outside` anyway), which is how the optimizers use it.
    pub fn classify_among(&self, p: DVec3, candidates: impl IntoIterator<Item = u32>) -> Class {
        self.run(p, candidates, None).class
    }

    /// [`Self::classify_among`] with every candidate first checked against its f32 planes
    /// (`compact[t]`, built by [`Self::compact_planes`]): same answers, fewer f64 tests and
    /// cache lines for the optimizers, which visit tetras in scattered order.
    pub fn classify_among_compact(
        &self,
        p: DVec3,
        candidates: impl IntoIterator<Item = u32>,
        compact: &[CompactPlanes],
    ) -> Class {
        self.run(p, candidates, Some(compact)).class
    }

    /// The f32 prefilter planes of every tetra, for [`Self::classify_among_compact`].
    pub fn compact_planes(&self) -> Vec<CompactPlanes> {
        self.tetras.iter().map(CompactPlanes::new).collect()
    }

    /// Classifies `p` and reports what the passes saw.
    pub fn trace(&self, p: DVec3) -> Trace {
        self.run(p, 0..self.tetras.len() as u32, None)
    }

    fn run(
        &self,
        p: DVec3,
        candidates: impl IntoIterator<Item = u32>,
        compact: Option<&[CompactPlanes]>,
    ) -> Trace {
        let mut tally = Tally::default();
        if !self.surface.in_bounds(p) {
            return tally.trace;
        }
        let q = p - self.apex;
        let pass = if q.abs().max_element() <= self.apex_ball {
            Pass::Ambiguous
        } else {
            let eps = self.surface.eps();
            let octant = octant_bit(q);
            let sign_tie = |t: u32| {
                let tp = &self.tetras[t as usize];
                (tp.sign, tp.tie)
            };
            let verdict = |t: u32| (t, self.tetras[t as usize].verdict(q, octant, eps));
            match compact {
                None => self.fold(p, &mut tally, candidates.into_iter().map(verdict), &sign_tie),
                Some(compact) => {
                    let cq = CompactPoint::new(q, eps);
                    let kept = candidates.into_iter().filter(|&t| !compact[t as usize].rejects(&cq));
                    self.fold(p, &mut tally, kept.map(verdict), &sign_tie)
                }
            }
        };
        let class = match pass {
            Pass::Boundary => Class::OnBoundary,
            Pass::Decided(c) => c,
            Pass::Ambiguous if tally.near_vertex => self.fallback(p, &mut tally),
            Pass::Ambiguous => self.rerun(p, &mut tally),
        };
        tally.trace.class = class;
        tally.trace
    }

    /// Re-runs the whole test with apexes from a fixed pseudo-random sequence around the
    /// default one, building each tetra on the fly (no preprocessing: the rare path).
    fn rerun(&self, p: DVec3, tally: &mut Tally) -> Class {
        let mut rng = Rng::new(RERUN_SEED);
        let eps = self.surface.eps();
        let reach = 0.1 * self.surface.scale();
        for _ in 0..MAX_RERUNS {
            let o = self.apex + rng.point_in_box(DVec3::NEG_ONE, DVec3::ONE) * reach;
            tally.trace.reruns += 1;
            let q = p - o;
            if q.abs().max_element() <= self.apex_ball {
                continue;
            }
            let octant = octant_bit(q);
            *tally = Tally { trace: tally.trace, ..Tally::default() };
            let n = self.tetras.len() as u32;
            let at = |t: u32| tetra_at(&self.surface, o, self.order[t as usize] as usize);
            let verdicts = (0..n).map(|t| (t, at(t).verdict(q, octant, eps)));
            let sign_tie = |t: u32| {
                let tp = at(t);
                (tp.sign, tp.tie)
            };
            match self.fold(p, tally, verdicts, &sign_tie) {
                Pass::Boundary => return Class::OnBoundary,
                Pass::Decided(c) => return c,
                Pass::Ambiguous if tally.near_vertex => break,
                Pass::Ambiguous => {}
            }
        }
        self.fallback(p, tally)
    }

    /// The last word: the winding number, reliable for points off the boundary (which
    /// every pass has already checked).
    #[cold]
    fn fallback(&self, p: DVec3, tally: &mut Tally) -> Class {
        tally.trace.fallback = true;
        winding::classify_nonzero(&self.surface, p)
    }

    /// Alg. 4-1's loop: sums the tetras' contributions, stopping early on the boundary.
    #[inline]
    fn fold(
        &self,
        p: DVec3,
        tally: &mut Tally,
        verdicts: impl Iterator<Item = (u32, Verdict)>,
        sign_tie: &dyn Fn(u32) -> (i8, i8),
    ) -> Pass {
        for (t, v) in verdicts {
            if !matches!(v, Verdict::Outside) && self.absorb(p, t, v, sign_tie, tally) {
                return Pass::Boundary;
            }
        }
        tally.trace.acc = tally.acc;
        if tally.ambiguous || tally.acc % 2 != 0 {
            Pass::Ambiguous
        } else {
            Pass::Decided(if tally.acc != 0 { Class::Inside } else { Class::Outside })
        }
    }

    /// Adds one non-outside verdict of tetra `t`; true when `p` is on the boundary.
    #[cold]
    fn absorb(
        &self,
        p: DVec3,
        t: u32,
        v: Verdict,
        sign_tie: &dyn Fn(u32) -> (i8, i8),
        tally: &mut Tally,
    ) -> bool {
        let covering = self.surface.covering();
        let tri = self.order[t as usize] as usize;
        let face = covering.face_of[tri] as usize;
        let contact = match v {
            Verdict::Outside => return false,
            Verdict::Contact(c) => c,
            Verdict::NearBase { contact, inward } => {
                tally.trace.near_base += 1;
                if self.surface.on_face(face, p) {
                    return true;
                }
                // Off the face but within ε of its plane: decide the base side with the
                // face's own plane when it is a planar n-gon, so that the overlapping
                // positive and negative triangles of a non-convex face agree.
                let tie = sign_tie(t).1;
                let inside = if tie != 0 {
                    tie as f64 * self.surface.face_distance(face, p) > 0.0
                } else {
                    inward > 0.0
                };
                if !inside {
                    return false;
                }
                contact
            }
            Verdict::Flat => {
                tally.trace.flat += 1;
                tally.ambiguous = true;
                return self.surface.on_face(face, p);
            }
            Verdict::Degenerate => return self.surface.on_face(face, p),
        };
        let s = sign_tie(t).0 as i32;
        match contact {
            Contact::Interior => {
                tally.trace.interior += 1;
                tally.acc += 2 * s;
            }
            Contact::Side => {
                tally.trace.side += 1;
                tally.acc += s;
            }
            Contact::ApexEdge(j) => {
                tally.trace.apex_edges += 1;
                let qj = covering.triangles[tri][j as usize];
                let near = p.distance(covering.points[qj as usize]) <= NEAR_VERTEX * self.surface.eps();
                tally.near_vertex |= near;
                match self.rule {
                    EdgeRule::Rerun => tally.ambiguous = true,
                    EdgeRule::VertexSets => {
                        let set = if s > 0 { &mut tally.pos } else { &mut tally.neg };
                        if !set.contains(&qj) {
                            set.push(qj);
                            tally.acc += 2 * s;
                        }
                    }
                }
            }
            Contact::Apex => tally.ambiguous = true,
        }
        false
    }
}

/// Covering triangles sorted along a Z-order (Morton) curve of their centroids in the
/// bounding box (10 bits per axis), ties by index.
fn morton_order(covering: &Covering) -> Vec<u32> {
    let (lo, hi) = covering.bounds();
    let scale = 1023.0 / (hi - lo).max(DVec3::splat(f64::MIN_POSITIVE));
    let spread = |v: u32| (0..10).fold(0u32, |k, b| k | ((v >> b) & 1) << (3 * b));
    let mut keyed: Vec<(u32, u32)> = (0..covering.triangles.len())
        .map(|t| {
            let [a, b, c] = covering.triangle(t);
            let q = (((a + b + c) / 3.0 - lo) * scale).clamp(DVec3::ZERO, DVec3::splat(1023.0)).as_uvec3();
            (spread(q.x) | spread(q.y) << 1 | spread(q.z) << 2, t as u32)
        })
        .collect();
    keyed.sort_unstable();
    keyed.into_iter().map(|(_, t)| t).collect()
}

/// The tetra of covering triangle `t` with apex `o`.
fn tetra_at(surface: &Surface, o: DVec3, t: usize) -> TetraPlanes {
    let covering = surface.covering();
    let face = covering.face_of[t] as usize;
    TetraPlanes::new(o, covering.triangle(t), surface.eps(), surface.face_plane(face).map(|(n, _)| n))
}

impl Classifier for FeitoTorres {
    fn name(&self) -> &str {
        "cpu"
    }

    fn classify(&self, p: DVec3) -> Class {
        self.classify_among(p, 0..self.tetras.len() as u32)
    }

    fn build_stats(&self) -> BuildStats {
        self.stats
    }
}

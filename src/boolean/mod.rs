//! Boolean operations on triangle-mesh solids (SPEC §6, 2006 thesis Ch. 6).
//!
//! The evaluation of §6.3, one file per step:
//!
//! 0. [`input`]: both operands must be closed, consistently oriented solids of positive
//!    volume whose faces do not cross (non-manifold ones and polygon faces included; faces
//!    of no area are left out);
//!    [`Transform`] ([`crate::mesh::transform`]) places B (the thesis applies a full transform
//!    to each mesh).
//! 1. **Refinement** (§6.4) — [`index`] finds candidate triangle pairs in one spatial
//!    index over both meshes, [`intersect`] decides each pair with exact predicates and
//!    names every intersection point symbolically, [`refine`] keeps each one implicit
//!    (never rounded while deciding) and re-triangulates each cut triangle by exact
//!    orientations with the intersection segments as constraints. Afterwards every
//!    triangle of A is wholly in, out or on B, and vice versa.
//! 2. **Classification** (§6.5) — [`classify`]: "on" triangles exactly, the others by
//!    groups of connected triangles (§6.5.1), one exact probe per group: the exact side
//!    of a piece against the other surface, or a point-in-solid test at an input vertex
//!    against the other operand's triangles (the surface the refinement cuts, not the
//!    covering of its polygon faces) with any inclusion method: the thesis' GPU test with
//!    its exact fallback, or a CPU one
//!    (the default, `octants`, is the fastest exact one for the few points grouped
//!    classification tests; on lavapipe the GPU test's set-up alone costs more). With the
//!    default, an operand that gets at most [`classify::FEW_POINTS`] points is not even
//!    built: its points are answered by exact ray crossings over its triangles
//!    ([`classify::ray_crossings`]), which costs less than building any structure.
//! 3. **Selection** (§6.2.2, §6.5.2) — [`select`]: every operation, regularized or
//!    not, picked from the same refinement and classification, then compacted.
//! 4. **Output** — [`output`]: a regularized result is checked as an operand would be,
//!    once rounded to f64, and repaired where rounding alone made faces cross or fold;
//!    one that cannot be made valid is an error, never written.
//!
//! [`expr`] evaluates CSG expressions (`(a | b) - c`) as a tree of these operations,
//! whose inner results stay exact: [`operand`] holds such a result (implicit points,
//! every triangle on an input plane) and the [`operand::Solid`] trait lets the refinement
//! and the classification take it or a file's mesh alike ([`evaluate_exact`]).
//!
//! A mesh without faces is the empty solid, a valid operand and result: A ∪ ∅ = A,
//! A ∩ ∅ = ∅, A − ∅ = A, ∅ − A = ∅, A ⊖ ∅ = A come out of the same steps.
//!
//! [`cgal`] runs the independent reference (CGAL corefinement with an exact kernel).

use std::time::{Duration, Instant};

use glam::DVec3;
use rayon::prelude::*;

use crate::exact::rounding::Ball;
use crate::exact::volume;
use crate::gpu::Context;
use crate::inclusion::{self, Choice, Method, solver::Solver};
use crate::mesh::Mesh;
use crate::mesh::frame::Frame;
use crate::mesh::intersect::TriangleSoup;
use crate::mesh::solidity::{Memory, Solidity};
use operand::{ExactSolid, Solid};

pub mod cgal;
pub mod classify;
pub mod expr;
pub mod index;
pub mod input;
pub mod intersect;
pub mod operand;
pub mod output;
pub mod refine;
pub mod select;

pub use crate::exact::volume::Volume;
pub use crate::mesh::transform::Transform;
pub use classify::{Class, Classification, ClassifyStats, Grouping};
pub use input::InputError;
pub use output::{InvalidResult, Repair};
pub use refine::{RefineStats, Refinement, Side};
pub use select::Operation;

/// How to evaluate.
#[derive(Clone, Debug)]
pub struct Options {
    /// The inclusion method for the point tests.
    pub method: Choice,
    /// One point test per group (default) or per triangle.
    pub grouping: Grouping,
    /// Go on with operands whose faces cross each other (results are then those of the
    /// refinement of the crossing surfaces, not of a solid).
    pub allow_self_intersections: bool,
    /// Settings of the inclusion methods.
    pub inclusion: inclusion::Options,
    /// Build the CPU classifiers while the refinement runs (the phases then overlap in
    /// wall time; benchmarks that split phases turn this off).
    pub overlap: bool,
    /// Take an operand's solid check from the user's cache when an earlier run found the
    /// same mesh a valid solid, and remember the verdicts found here
    /// ([`crate::mesh::solidity::Memory`], as every command does); benchmarks that
    /// time the checks turn this off.
    pub remember_verdicts: bool,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            method: Choice::Fixed(Method::Octants),
            grouping: Grouping::Grouped,
            allow_self_intersections: false,
            inclusion: inclusion::Options::default(),
            overlap: true,
            remember_verdicts: true,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum BooleanError {
    /// An operand is not a valid solid.
    #[error("{name} is not a valid solid: {reason}")]
    Input { name: String, reason: InputError },
    #[error(transparent)]
    Refine(#[from] refine::RefineError),
    #[error(transparent)]
    Classify(#[from] classify::ClassifyError),
    #[error("preparing the inclusion test of {name}: {source}")]
    Inclusion { name: String, source: inclusion::InclusionError },
    #[error(transparent)]
    Mesh(#[from] crate::mesh::MeshError),
    /// A regularized result of closed operands is not closed: a bug, reported.
    #[error(
        "internal error: the {op} is not closed ({boundary} boundary edge(s), {misoriented} misoriented); please report it"
    )]
    NotClosed { op: Operation, boundary: usize, misoriented: usize },
    /// A regularized result that rounding to f64 left invalid and that could not be
    /// repaired ([`output`]).
    #[error("the {op} cannot be written as a valid solid: {reason}")]
    Invalid { op: Operation, reason: InvalidResult },
}

pub type Result<T, E = BooleanError> = std::result::Result<T, E>;

/// Wall time of each phase (Table 6-1 splits phase 1 = index + refinement and
/// phase 2 = classification + assembly).
#[derive(Clone, Copy, Debug, Default)]
pub struct Timings {
    /// Operand checks (closed, oriented, volume, self-intersection) and tessellation.
    pub check: Duration,
    /// Phase 1: index, pair tests, intersection points, re-triangulation.
    pub refine: Duration,
    /// Building the inclusion classifiers (none when few points are tested: see
    /// [`classify::FEW_POINTS`]).
    pub classifiers: Duration,
    /// On-tests, groups and point tests.
    pub classify: Duration,
}

impl Timings {
    /// Phase 2 without the assembly of a result (added per operation).
    pub fn classification(&self) -> Duration {
        self.classifiers + self.classify
    }
}

/// Both operands refined and classified: every operation can be read from it.
pub struct Evaluation {
    pub a: TriangleSoup,
    pub b: TriangleSoup,
    pub refinement: Refinement,
    pub classification: Classification,
    pub timings: Timings,
    /// Name of the inclusion method used.
    pub method: String,
    /// The operands' common frame ([`crate::mesh::frame`]): everything above is in it,
    /// [`Evaluation::result`] gives the result back in the operands' units.
    pub frame: Frame,
    /// The operands when they are exact results of earlier steps of an expression
    /// ([`evaluate_exact`]); `a` and `b` are then their triangles over rounded points.
    pub exact: Option<Box<[ExactSolid; 2]>>,
}

/// The two operands' names in messages (e.g. their file names).
#[derive(Clone, Copy, Debug)]
pub struct Names<'a> {
    pub a: &'a str,
    pub b: &'a str,
}

impl Default for Names<'_> {
    fn default() -> Self {
        Names { a: "A", b: "B" }
    }
}

/// Checks both operands, given in `frame` (in parallel), and returns their triangles and
/// the verdicts of the solid check (`known` where given: remembered from an earlier run).
pub fn check_operands(
    a: &Mesh,
    b: &Mesh,
    names: Names,
    frame: Frame,
    allow_self: bool,
    known: [Option<Solidity>; 2],
) -> Result<[(TriangleSoup, Option<Solidity>); 2]> {
    let [ka, kb] = known;
    let (ra, rb) = rayon::join(
        || input::check_known(a, frame, allow_self, ka),
        || input::check_known(b, frame, allow_self, kb),
    );
    let sa = ra.map_err(|reason| BooleanError::Input { name: names.a.to_string(), reason })?;
    let sb = rb.map_err(|reason| BooleanError::Input { name: names.b.to_string(), reason })?;
    Ok([sa, sb])
}

/// Evaluates A against B (§6.3): checks, refinement, classification, in the operands'
/// common [`Frame`] (scale-free). `ctx` is needed by the GPU inclusion methods.
pub fn evaluate(
    a: &Mesh,
    b: &Mesh,
    names: Names,
    options: &Options,
    ctx: Option<&Context>,
) -> Result<Evaluation> {
    evaluate_in(a, b, names, options, ctx, Frame::of(&[a, b]))
}

/// [`evaluate`] in a given frame (an expression's, common to all its operands).
pub fn evaluate_in(
    a: &Mesh,
    b: &Mesh,
    names: Names,
    options: &Options,
    ctx: Option<&Context>,
    frame: Frame,
) -> Result<Evaluation> {
    let mut timings = Timings::default();
    let start = Instant::now();
    let memory = options.remember_verdicts.then(|| {
        let (x, y) = rayon::join(|| Memory::of(a), || Memory::of(b));
        [x, y]
    });
    let known = memory.as_ref().map_or([None, None], |m| m.each_ref().map(Memory::recall));
    let fresh = known.each_ref().map(Option::is_none);
    let (framed_a, framed_b) = rayon::join(|| frame.mesh_in_ref(a), || frame.mesh_in_ref(b));
    let [(sa, va), (sb, vb)] =
        check_operands(&framed_a, &framed_b, names, frame, options.allow_self_intersections, known)?;
    if let Some(memory) = &memory {
        for (memory, fresh, verdict) in [(&memory[0], fresh[0], va), (&memory[1], fresh[1], vb)] {
            if let (true, Some(v)) = (fresh, verdict) {
                memory.remember(&v);
            }
        }
    }
    // The point tests answer for the surface the refinement cuts: the operands'
    // triangles. (A polygon face is its covering for the inclusion methods, which differs
    // from its triangles on a non-planar face whose centroid fan folds, by up to the
    // face's distance from a plane: a vertex of the other operand in that gap would take
    // the wrong side, and the groups around it with it.)
    let (a, b) = rayon::join(|| sa.to_mesh(), || sb.to_mesh());
    let (a, b) = (&a?, &b?);
    timings.check = start.elapsed();
    let (refinement, classification, method) =
        refine_and_classify((&sa, &sb), (a, b), names, options, ctx, &mut timings)?;
    Ok(Evaluation { a: sa, b: sb, refinement, classification, timings, method, frame, exact: None })
}

/// Evaluates two exact results of earlier steps of an expression against each other, in
/// the expression's frame (where their points are): refinement and classification as
/// [`evaluate`]'s, nothing rounded; their inclusion methods are built on their rounded
/// meshes ([`point_test`]). They need no operand check: each is a refinement's product,
/// closed and oriented ([`Evaluation::exact_result`] checks), and its faces do not cross.
pub fn evaluate_exact(
    a: ExactSolid,
    b: ExactSolid,
    names: Names,
    options: &Options,
    ctx: Option<&Context>,
    frame: Frame,
) -> Result<Evaluation> {
    let mut timings = Timings::default();
    let start = Instant::now();
    let (ma, mb) = rayon::join(|| rounded_mesh(&a), || rounded_mesh(&b));
    let (ma, mb) = (ma?, mb?);
    timings.check = start.elapsed();
    let (refinement, classification, method) =
        refine_and_classify((&a, &b), (&ma, &mb), names, options, ctx, &mut timings)?;
    let soup = |s: &ExactSolid| TriangleSoup {
        positions: s.rounded.clone(),
        triangles: s.triangles.clone(),
        face_of: (0..s.triangles.len() as u32).collect(),
        failed: Vec::new(),
    };
    let (sa, sb) = (soup(&a), soup(&b));
    let exact = Some(Box::new([a, b]));
    Ok(Evaluation { a: sa, b: sb, refinement, classification, timings, method, frame, exact })
}

/// Refinement and classification of two checked operands (`meshes`: their triangles, for
/// the inclusion methods); the name of the method used.
fn refine_and_classify<S: Solid>(
    (sa, sb): (&S, &S),
    (a, b): (&Mesh, &Mesh),
    names: Names,
    options: &Options,
    ctx: Option<&Context>,
    timings: &mut Timings,
) -> Result<(Refinement, Classification, String)> {
    // The operands' closure is checked above.
    let inclusion = inclusion::Options { known_closed: true, ..options.inclusion };
    let build = |mesh: &Mesh| Solver::new(options.method, mesh, &inclusion, ctx, None);
    let named = |name: &str| {
        let name = name.to_string();
        move |source| BooleanError::Inclusion { name, source }
    };
    // With the default method, grouped classification tests a few points against each
    // operand: those are answered by exact ray crossings over its triangles, and the
    // method is built (after the refinement) only for an operand that gets more
    // ([`classify::FEW_POINTS`]). Otherwise both are built up front.
    let lazy = options.grouping == Grouping::Grouped && options.method.fixed() == Some(Method::Octants);
    let build_both = || {
        let start = Instant::now();
        let solvers = if lazy {
            Ok((None, None))
        } else if options.method.is_cpu() {
            let (x, y) =
                rayon::join(|| build(a).map_err(named(names.a)), || build(b).map_err(named(names.b)));
            x.and_then(|x| Ok((Some(x), Some(y?))))
        } else {
            build(a)
                .map_err(named(names.a))
                .and_then(|x| Ok((Some(x), Some(build(b).map_err(named(names.b))?))))
        };
        (solvers, start.elapsed())
    };
    let refine_timed = || {
        let start = Instant::now();
        (refine::refine(sa, sb), start.elapsed())
    };
    // GPU solvers hold the device: build them on this thread.
    let ((refinement, t_refine), (solvers, t_build)) = if options.overlap && options.method.is_cpu() && !lazy
    {
        rayon::join(refine_timed, build_both)
    } else {
        let r = refine_timed();
        (r, build_both())
    };
    timings.refine = t_refine;
    timings.classifiers = t_build;
    let refinement = refinement?;
    let mut solvers = {
        let (x, y) = solvers?;
        [x, y]
    };
    let method = match &solvers[0] {
        Some(s) => s.name().to_string(),
        None => Method::Octants.name().to_string(),
    };

    let start = Instant::now();
    let mut counts = TestCounts::default();
    // The operand whose lazily built method failed, to name it in the error.
    let mut failed = None;
    let mut test = |side: Side, points: &[DVec3]| -> inclusion::Result<Vec<inclusion::Class>> {
        let (k, mesh, soup) = match side {
            Side::A => (0, a, sa),
            Side::B => (1, b, sb),
        };
        let make = || build(mesh).inspect_err(|_| failed = Some(side));
        point_test(soup, points, &mut solvers[k], make, &mut counts)
    };
    let classified = classify::classify(&refinement, sa, sb, options.grouping, &mut test);
    let mut classification = match (classified, failed) {
        (Err(classify::ClassifyError::Inclusion(source)), Some(side)) => {
            let name = if side == Side::A { names.a } else { names.b };
            return Err(named(name)(source));
        }
        (classified, _) => classified?,
    };
    classification.stats.ray_tests = counts.ray_tests;
    timings.classifiers += counts.built;
    timings.classify = start.elapsed().saturating_sub(counts.built);
    Ok((refinement, classification, method))
}

/// What [`point_test`] did besides the method's tests.
#[derive(Clone, Copy, Debug, Default)]
pub struct TestCounts {
    /// Points answered by exact ray crossings ([`classify::ray_crossings`]).
    pub ray_tests: usize,
    /// Time spent building methods when first needed.
    pub built: Duration,
}

/// The classification's point tests against one operand `solid` ([`classify::PointTest`]):
/// `solver` is its inclusion method, built by `build` when first needed. With none built
/// yet, at most [`classify::FEW_POINTS`] points are answered by exact ray crossings over
/// its triangles instead. On an operand with implicit points the method is the one built
/// on its rounded mesh ([`rounded_mesh`]), whose Inside and Outside answers hold for the
/// exact surface when [`rounded_method_is_exact`] (the argument is in [`classify`]'s
/// documentation; its OnBoundary answers go to the exact parity there, as always); when
/// that does not hold, every point is answered by exact ray crossings.
pub fn point_test<S: Solid>(
    solid: &S,
    points: &[DVec3],
    solver: &mut Option<Solver>,
    build: impl FnOnce() -> inclusion::Result<Solver>,
    counts: &mut TestCounts,
) -> inclusion::Result<Vec<inclusion::Class>> {
    let rays = solver.is_none() && points.len() <= classify::FEW_POINTS;
    if rays || (!S::EXPLICIT && !rounded_method_is_exact(solid)) {
        counts.ray_tests += points.len();
        return Ok(classify::ray_crossings(points, solid));
    }
    if solver.is_none() {
        let start = Instant::now();
        *solver = Some(build()?);
        counts.built += start.elapsed();
    }
    let Some(solver) = solver else { unreachable!("built above") };
    solver.classify_fine(points, 4)
}

/// An operand's triangles over its rounded positions ([`Solid::rounded`]), for building
/// inclusion methods (for an operand with implicit points see [`point_test`]).
pub fn rounded_mesh<S: Solid>(solid: &S) -> Result<Mesh> {
    let triangles = solid.triangles();
    let offsets = (0..=triangles.len()).map(|t| 3 * t).collect();
    Ok(Mesh::from_parts(solid.rounded().to_vec(), offsets, triangles.as_flattened().to_vec())?)
}

/// A bound on how far rounding moves any vertex of `solid` (Euclidean): 0 for an
/// explicit operand; else each coordinate of an implicit point is rounded to nearest,
/// off by at most half an ulp of the rounded value, ≤ 2⁻⁵³·|x| (plus the smallest
/// subnormal's half), so √3 of that at the largest |x|, below 2⁻⁵²·max |x| + the smallest
/// normal.
pub fn rounding_displacement<S: Solid>(solid: &S) -> f64 {
    if S::EXPLICIT {
        return 0.0;
    }
    let largest =
        solid.rounded().par_iter().with_min_len(4096).map(|p| p.abs().max_element()).reduce(|| 0.0, f64::max);
    largest * f64::EPSILON + f64::MIN_POSITIVE
}

/// True when an inclusion method built on the rounded mesh of `solid` answers Inside and
/// Outside for its exact surface too: always for an explicit operand; else when rounding
/// moves no vertex by more than 1/64 of the methods' boundary band ε = 10⁻⁹ of the
/// diagonal of the triangles' box ([`crate::inclusion`]; the surface's box, over every
/// position, is no smaller). The room covers the methods' own f64 evaluation near ε,
/// a few ulps of the coordinates. In the evaluation's frame (coordinates at most about
/// 2) it fails only for an operand whose diagonal is under about 3·10⁻⁵.
pub fn rounded_method_is_exact<S: Solid>(solid: &S) -> bool {
    if S::EXPLICIT {
        return true;
    }
    let (positions, triangles) = (solid.rounded(), solid.triangles());
    let (lo, hi) = triangles
        .iter()
        .flatten()
        .map(|&v| positions[v as usize])
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)));
    let band = inclusion::surface::REL_TOL * (hi - lo).length();
    64.0 * rounding_displacement(solid) < band
}

/// One operation's result, as it is written.
#[derive(Clone, Debug)]
pub struct Output {
    pub mesh: Mesh,
    /// How many of its faces, the first ones, come from A (the rest come from B).
    pub from_a: usize,
    /// What the check after rounding found and repaired (nothing for non-regularized
    /// results, which are not checked).
    pub repair: Repair,
}

impl Evaluation {
    /// The result of `op` (regularized or not) as a mesh of triangles in the operands'
    /// units: [`Evaluation::output`].
    pub fn result(&self, op: Operation, regularized: bool) -> Result<Mesh> {
        Ok(self.output(op, regularized)?.mesh)
    }

    /// [`Evaluation::result`] in the operands' frame and how many of its faces, the first
    /// ones, come from A (the rest come from B), for pictures that colour faces by operand
    /// (Figs. 6-9 … 6-12).
    pub fn result_by_operand(&self, op: Operation, regularized: bool) -> Result<(Mesh, usize)> {
        let out = self.output_in_frame(op, regularized)?;
        Ok((out.mesh, out.from_a))
    }

    /// The result of `op` in the operands' units. A regularized result must be closed and
    /// consistently oriented (if it is not, that is a bug, returned as
    /// [`BooleanError::NotClosed`]), and is checked and repaired after rounding
    /// ([`output`]; [`BooleanError::Invalid`] when it cannot be made valid).
    pub fn output(&self, op: Operation, regularized: bool) -> Result<Output> {
        let out = self.output_in_frame(op, regularized)?;
        Ok(Output { mesh: self.frame.mesh_out(out.mesh)?, ..out })
    }

    /// The volume of the exact result of `op`, before rounding to f64 and any repair, in the
    /// operands' units: the selected triangles over the exact points (input vertices, and
    /// the implicit intersection points divided out in double-double), with a certified
    /// error bound ([`crate::exact::volume`]: of the order of 10⁻¹⁶ relative, slivers
    /// included). Its `rounding` bounds what rounding the intersection points alone moves
    /// it by; a repair ([`Output::repair`]) may move it more. Computed on request (a few %
    /// of a plain evaluation's instructions for a large result): commands ask for it with
    /// `--stats` or `--json`.
    pub fn exact_volume(&self, op: Operation, regularized: bool) -> Volume {
        let (r, c) = (&self.refinement, &self.classification);
        let (tris, _) = select::select(op, regularized, (&r.a.triangles, &c.a), (&r.b.triangles, &c.b));
        // Points that are rounded when written: the intersection points, and every point
        // of an exact operand (explicit ones round to themselves).
        let first = if self.exact.is_some() { 0 } else { r.first_new };
        let implicit: Vec<[Ball; 3]> = (first..r.points.len() as u32)
            .into_par_iter()
            .with_min_len(256)
            .map(|id| r.point(id).coordinates())
            .collect();
        let v = volume::signed_volume(&tris, |id| {
            if id < first {
                (r.points[id as usize].to_array().map(Ball::of), false)
            } else {
                (implicit[(id - first) as usize], true)
            }
        });
        v.scaled(|x| self.frame.volume_out(x))
    }

    /// The exact result of `op`, in the operands' frame, as an operand for a further step:
    /// the selected triangles over the exact points, nothing rounded
    /// ([`select::assemble_exact`]).
    pub fn exact_result(&self, op: Operation, regularized: bool) -> Result<ExactSolid> {
        let (r, c) = (&self.refinement, &self.classification);
        let (tris, _) = select::select(op, regularized, (&r.a.triangles, &c.a), (&r.b.triangles, &c.b));
        if regularized {
            let (boundary, misoriented) = crate::mesh::validate::edge_defects(&tris);
            if boundary > 0 || misoriented > 0 {
                return Err(BooleanError::NotClosed { op, boundary, misoriented });
            }
        }
        let support = match self.exact.as_deref() {
            Some([a, b]) => select::selected_supports(op, regularized, r, (a, &c.a), (b, &c.b)),
            None => select::selected_supports(op, regularized, r, (&self.a, &c.a), (&self.b, &c.b)),
        };
        Ok(select::assemble_exact(r, &tris, support))
    }

    /// [`Evaluation::output`] in the operands' frame (a power-of-two scale: the rounding,
    /// and so the check, is the same in the operands' units).
    fn output_in_frame(&self, op: Operation, regularized: bool) -> Result<Output> {
        let (r, c) = (&self.refinement, &self.classification);
        let (tris, from_a) = select::select(op, regularized, (&r.a.triangles, &c.a), (&r.b.triangles, &c.b));
        if !regularized {
            let mesh = select::assemble(&r.points, &tris);
            return Ok(Output { mesh, from_a, repair: Repair::default() });
        }
        // The same walk as `select`: which selected triangles are uncut input triangles.
        // Exact operands' triangles are all rounded here for the first time, and all
        // their points with them.
        let exact = self.exact.is_some();
        let mut changed = Vec::with_capacity(tris.len());
        for (from_a, side, classes) in [(true, &r.a, &c.a), (false, &r.b, &c.b)] {
            for (t, &class) in classes.iter().enumerate() {
                if op.keeps(from_a, class, regularized).is_some() {
                    changed.push(exact || side.cut[side.parent[t] as usize]);
                }
            }
        }
        let first_new = if exact { 0 } else { (self.a.positions.len() + self.b.positions.len()) as u32 };
        let (lo, hi) = self
            .a
            .positions
            .iter()
            .chain(&self.b.positions)
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        let diagonal = (hi - lo).length();
        // The closure test runs beside the check after rounding; its verdict comes first.
        let (done, (boundary, misoriented)) = rayon::join(
            || output::finish(&r.points, first_new, &tris, &changed, diagonal),
            || crate::mesh::validate::edge_defects(&tris),
        );
        if boundary > 0 || misoriented > 0 {
            return Err(BooleanError::NotClosed { op, boundary, misoriented });
        }
        let done = done.map_err(|reason| BooleanError::Invalid { op, reason: reason.out_of(self.frame) })?;
        let from_a = done.origin.iter().filter(|&&o| (o as usize) < from_a).count();
        let repair = Repair { moved: self.frame.length_out(done.repair.moved), ..done.repair };
        let mesh = select::assemble(&done.positions, &done.triangles);
        if !repair.is_clean() {
            // What the repair changed gets the whole operand check (nesting and orientation
            // of shells included): never a result texgeo would refuse as an operand.
            input::check(&mesh, self.frame, false).map_err(|e| BooleanError::Invalid {
                op,
                reason: InvalidResult::NotOperand { reason: e.to_string() },
            })?;
        }
        Ok(Output { mesh, from_a, repair })
    }

    /// Refined operand A (`b` false) or B (`b` true) as a mesh, in the operands' frame: its
    /// triangles with the cut curve among their edges.
    pub fn refined_operand(&self, b: bool) -> Mesh {
        let r = if b { &self.refinement.b } else { &self.refinement.a };
        select::assemble(&self.refinement.points, &r.triangles)
    }

    /// The cut curve as 3D segments (where the two surfaces meet), for pictures.
    pub fn cut_curve(&self) -> Vec<[DVec3; 2]> {
        self.refinement.curve.iter().map(|s| s.map(|i| self.refinement.points[i as usize])).collect()
    }
}

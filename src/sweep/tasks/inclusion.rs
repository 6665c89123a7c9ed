//! `--task inclusion`: classify seeded random points in the mesh's bounding box with the
//! method under test and compare every answer with an exact CPU method.

use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::inclusion::solver::Solver;
use crate::inclusion::{self, Choice, Class, InclusionError, Method};
use crate::mesh::Mesh;
use crate::mesh::solidity::{Policy, require_solid};
use crate::random::Rng;
use crate::sweep::record::{Fnv, Record};
use crate::sweep::task::{Failure, Input, Task};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Options {
    /// The method under test (`texgeo inclusion --method`; `auto` is recorded as `method`).
    pub method: Choice,
    /// Uniform random points in the bounding box.
    pub points: usize,
    pub seed: u64,
    /// TetraGrid resolution (tetragrid, gpu+tetragrid, and the GPU paths' exact fallback).
    pub grid: usize,
    /// GPU methods: tetrahedra per point-vertex.
    pub batch: Option<u32>,
    /// A CPU method every answer is compared with (`none`: no comparison).
    #[serde(with = "crate::choice::by_name_or_none")]
    pub reference: Option<Method>,
    /// Accept meshes that are not solids (open, self-intersecting, nested, inverted): their
    /// points are classified by the generalized winding number (inside iff w ≥ ½) on the
    /// CPU whatever the method, compared with the direct sum over every triangle, and the
    /// defect is recorded (`non_solid`).
    pub allow_open: bool,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            method: Choice::Auto,
            points: 1000,
            seed: 1,
            grid: inclusion::tetragrid::DEFAULT_RESOLUTION,
            batch: None,
            reference: Some(Method::Cpu),
            allow_open: false,
        }
    }
}

/// Point in solid (Feito-Torres and its optimizers, GPU paths, baselines).
#[derive(Default)]
pub struct Inclusion;

impl Task for Inclusion {
    const NAME: &'static str = "inclusion";
    type Options = Options;

    fn validate(o: &Options) -> Result<(), String> {
        if let Some(m) = o.reference.filter(|m| !m.is_cpu()) {
            return Err(format!("reference '{m}' must be a CPU method (or none)"));
        }
        if o.points == 0 || o.points > 100_000_000 {
            return Err(format!("points {} is outside 1..=100000000", o.points));
        }
        Ok(())
    }

    fn needs_device(o: &Options) -> bool {
        !o.method.is_cpu()
    }

    fn run(&mut self, input: Input, o: &Options, out: &mut Record) -> Result<(), Failure> {
        let Input { ctx, mesh, .. } = input;
        // The same gate as `texgeo inclusion`: what the command refuses, the sweep refuses.
        let policy = Policy { allow_open: o.allow_open, ..Policy::default() };
        let accepted = require_solid(mesh.clone(), policy).map_err(Failure::not_solid)?;
        let mesh = &accepted.mesh;
        let (lo, hi) = mesh.bounds();
        let points = Rng::new(o.seed).points_in_box(o.points, lo, hi);
        out.size("points", points.len());
        let options = inclusion::Options {
            tetragrid_resolution: o.grid,
            allow_open: o.allow_open,
            non_solid: accepted.non_solid.is_some(),
            points: points.len(),
            ..Default::default()
        };
        if let Some(defect) = &accepted.non_solid {
            out.check("non_solid", defect.slug());
            return winding_rule(mesh, &options, &points, o, out);
        }

        let t = Instant::now();
        let mut solver = Solver::new(o.method, mesh, &options, ctx, o.batch).map_err(refusal)?;
        if o.method == Choice::Auto {
            out.check("method", solver.name());
        }
        out.time("build", t.elapsed());
        let t = Instant::now();
        let classes = solver.classify_all(&points).map_err(refusal)?;
        out.time("classify", t.elapsed());

        let count = |c: Class| classes.iter().filter(|&&x| x == c).count();
        out.size("inside", count(Class::Inside));
        out.size("outside", count(Class::Outside));
        out.size("boundary", count(Class::OnBoundary));
        if let Some(g) = solver.gpu_stats() {
            out.size("flagged", g.flagged);
        }
        let mut h = Fnv::default();
        h.bytes(&classes.iter().map(|&c| c as u8).collect::<Vec<_>>());
        out.hash("classes", &h);

        let Some(reference) = o.reference else {
            return Ok(());
        };
        let t = Instant::now();
        let mut exact = Solver::new(reference, mesh, &options, None, None).map_err(refusal)?;
        let expected = exact.classify_all(&points).map_err(refusal)?;
        out.time("reference", t.elapsed());
        compare(&classes, &expected, &format!("the {reference} answer"), out)
    }
}

/// Records how many answers differ from the reference's, and fails when any does.
fn compare(classes: &[Class], expected: &[Class], reference: &str, out: &mut Record) -> Result<(), Failure> {
    let differing = classes.iter().zip(expected).filter(|(a, b)| a != b).count();
    out.check("differing", differing);
    if differing > 0 {
        return Err(Failure::failed(
            "check",
            format!("{differing} of {} points differ from {reference}", classes.len()),
        ));
    }
    Ok(())
}

/// A mesh that is not a solid, under `allow_open`: the certified winding-number
/// classifier (whatever the method: the GPU methods answer for solids only), checked
/// against the winding number summed directly over every triangle.
fn winding_rule(
    mesh: &Mesh,
    options: &inclusion::Options,
    points: &[glam::DVec3],
    o: &Options,
    out: &mut Record,
) -> Result<(), Failure> {
    use crate::inclusion::Classifier;
    let t = Instant::now();
    let fast = inclusion::fast_winding::FastWinding::new(mesh, options.points).map_err(refusal)?;
    out.time("build", t.elapsed());
    let t = Instant::now();
    let classes = fast.classify_all(points);
    out.time("classify", t.elapsed());
    let count = |c: Class| classes.iter().filter(|&&x| x == c).count();
    out.size("inside", count(Class::Inside));
    out.size("outside", count(Class::Outside));
    out.size("boundary", count(Class::OnBoundary));
    let mut h = Fnv::default();
    h.bytes(&classes.iter().map(|&c| c as u8).collect::<Vec<_>>());
    out.hash("classes", &h);
    if o.reference.is_none() {
        return Ok(());
    }
    let t = Instant::now();
    let direct = inclusion::winding::WindingNumber::with_policy(mesh, true).map_err(refusal)?;
    let expected = direct.classify_all(points);
    out.time("reference", t.elapsed());
    compare(&classes, &expected, "the winding number summed directly", out)
}

/// Refusals (what `texgeo inclusion` would reject) and failures.
fn refusal(e: InclusionError) -> Failure {
    match e {
        InclusionError::NotClosed { .. } => Failure::refused("not-closed", e),
        InclusionError::TooLarge(_) => Failure::refused("too-large", e),
        InclusionError::Resolution(_)
        | InclusionError::OctreeDepth(_)
        | InclusionError::Options(_)
        | InclusionError::NotForNonSolids(_) => Failure::refused("options", e),
        InclusionError::Gpu(_) => Failure::failed("gpu", e),
        InclusionError::NeedsGpu(_) => Failure::failed("device", e),
        InclusionError::Points(_) => Failure::failed("points", e),
    }
}

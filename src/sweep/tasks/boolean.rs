//! `--task boolean`: a Boolean operation of each mesh with a second solid — by default a
//! copy of itself turned 10° about y and moved 1 % of its diagonal (the armadillo
//! case, `texgeo bench boolean`'s pairs) — checked for a closed result, the volume
//! identities, and optionally against CGAL's corefinement.

use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::boolean::{self, BooleanError, InputError, Names, Operation, Transform, cgal};
use crate::inclusion::Choice;
use crate::mesh::covering::measures;
use crate::mesh::spec::{MeshSpec, Placed};
use crate::mesh::{Mesh, procedural};
use crate::report::bench::boolean::turned_copy;
use crate::sweep::record::{Record, mesh_hash};
use crate::sweep::task::{Failure, Input, Task, relative};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Options {
    /// union, intersection, difference or symmetric-difference.
    pub op: Operation,
    /// The second operand: `turned` (the mesh turned 10° about y and moved 1 % of its
    /// diagonal), `transform:STEPS` (the mesh moved by `texgeo boolean --transform-b`
    /// steps), or `builtin:NAME`, placed by `@STEPS` if given ([`Placed`]).
    pub with: String,
    /// Inclusion method for the point tests (`texgeo boolean --method`).
    pub method: Choice,
    /// Regularized sets (the default) or the thesis' plain ones.
    pub regularized: bool,
    /// `cgal` (volume and area of the result against CGAL's, 1e-9 relative) or `none`.
    #[serde(with = "crate::choice::by_name_or_none")]
    pub reference: Option<Reference>,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            op: Operation::Difference,
            with: "turned".into(),
            method: boolean::Options::default().method,
            regularized: true,
            reference: None,
        }
    }
}

/// What a Boolean's result is compared with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Reference {
    /// CGAL's Nef polyhedra: volume and area of the result.
    Cgal,
}

/// Relative volume/area agreement asked of CGAL's result (as the tests ask).
const CGAL_TOLERANCE: f64 = 1e-9;

impl Options {
    /// The second operand for `mesh`.
    fn other(&self, mesh: &Mesh) -> Result<Mesh, String> {
        if self.with == "turned" {
            return turned_copy(mesh).map_err(|e| e.to_string());
        }
        if let Some(steps) = self.with.strip_prefix("transform:") {
            return Transform::parse(steps)?.apply(mesh).map_err(|e| e.to_string());
        }
        if MeshSpec::parse(&self.with).builtin().is_some() {
            return Placed::parse(&self.with)?.load().map_err(|e| e.to_string());
        }
        Err(format!(
            "unknown second operand '{}' (expected turned, transform:STEPS or builtin:NAME)",
            self.with
        ))
    }
}

/// Booleans need no state between meshes (the GPU point tests build their solver per pair).
#[derive(Default)]
pub struct BooleanTask;

impl Task for BooleanTask {
    const NAME: &'static str = "boolean";
    type Options = Options;

    fn validate(o: &Options) -> Result<(), String> {
        o.other(&procedural::cube())?;
        Ok(())
    }

    fn needs_device(o: &Options) -> bool {
        !o.method.is_cpu()
    }

    fn run(&mut self, input: Input, o: &Options, out: &mut Record) -> Result<(), Failure> {
        let Input { ctx, mesh, .. } = input;
        let op = o.op;
        let other = o.other(mesh).map_err(|e| Failure::failed("options", e))?;
        let options = boolean::Options { method: o.method, ..boolean::Options::default() };
        let names = Names { a: "the mesh", b: "the second operand" };
        let ev = boolean::evaluate(mesh, &other, names, &options, ctx).map_err(refusal)?;
        let t = &ev.timings;
        for (k, d) in [
            ("check", t.check),
            ("refine", t.refine),
            ("classifiers", t.classifiers),
            ("classify", t.classify),
        ] {
            out.time(k, d);
        }
        let r = &ev.refinement.stats;
        let c = &ev.classification.stats;
        out.size("triangles_a", ev.a.triangles.len());
        out.size("triangles_b", ev.b.triangles.len());
        out.size("cut_a", r.cut_a);
        out.size("cut_b", r.cut_b);
        out.size("groups", c.groups);
        out.size("point_tests", c.point_tests);
        out.check("tests_saved", relative(c.saved_share()));

        let start = Instant::now();
        let result = ev.result(op, o.regularized).map_err(refusal)?;
        out.time("assemble", start.elapsed());
        out.size("result_faces", result.num_faces());
        out.hash("result", &mesh_hash(&result));
        let (volume, area) = measures(&result);
        out.check("volume", relative(volume));

        // vol(A ∪ B) + vol(A ∩ B) = vol(A) + vol(B), from the same refinement.
        if o.regularized {
            let union = ev.result(Operation::Union, true).map_err(refusal)?;
            let inter = ev.result(Operation::Intersection, true).map_err(refusal)?;
            let ((va, aa), (vb, ab)) = (measures(mesh), measures(&other));
            let scale = (va.abs() + vb.abs()).max(f64::MIN_POSITIVE);
            let gap = (measures(&union).0 + measures(&inter).0 - va - vb).abs() / scale;
            let tolerance = identity_tolerance(&[mesh, &other], aa + ab, scale);
            out.check("volume_identity", relative(gap));
            if gap > tolerance {
                return Err(Failure::failed(
                    "check",
                    format!(
                        "vol(A∪B) + vol(A∩B) differs from vol(A) + vol(B) by {gap:e} relative \
                         (allowed {tolerance:e} for these operands)"
                    ),
                ));
            }
        }

        if o.reference == Some(Reference::Cgal) {
            let start = Instant::now();
            // CGAL refusing an operand texgeo accepts (a non-manifold solid, say) is recorded,
            // not failed: it is the reference that cannot answer.
            let reference = match cgal::reference(mesh, &other, None) {
                Ok(r) => r,
                Err(cgal::CgalError::Helper { message, .. }) => {
                    // The reason only (the message names temporary files).
                    let reason = message.rsplit(": ").next().unwrap_or_default();
                    out.check("cgal", format!("declined: {reason}"));
                    return Ok(());
                }
                Err(e) => return Err(Failure::failed("cgal", e)),
            };
            out.time("reference", start.elapsed());
            let Some((cv, ca)) = reference.measures(op) else {
                out.check("cgal", "declined");
                return Ok(());
            };
            let rel = |x: f64, y: f64| (x - y).abs() / y.abs().max(f64::MIN_POSITIVE);
            let (dv, da) = (rel(volume, cv), rel(area, ca));
            out.check("cgal_volume", relative(dv));
            out.check("cgal_area", relative(da));
            if dv > CGAL_TOLERANCE || da > CGAL_TOLERANCE {
                return Err(Failure::failed(
                    "check",
                    format!("volume/area differ from CGAL's by {dv:e}/{da:e} relative"),
                ));
            }
        }
        Ok(())
    }
}

/// The relative gap allowed in the volume identity: [`CGAL_TOLERANCE`], plus what rounding
/// the operands' coordinates may move the cut surface by. Every new vertex of the
/// refinement is rounded to f64 at the size L of the largest coordinate, and moving the
/// surfaces (of area S in all, each piece in the union or the intersection once) by u·L
/// changes the volumes by at most S·u·L; a factor 16 covers the few roundings per vertex.
/// Far from the origin (L ≫ the operands' size) this term is what counts.
fn identity_tolerance(operands: &[&Mesh], area: f64, volume: f64) -> f64 {
    let largest =
        operands.iter().flat_map(|m| m.positions()).map(|p| p.abs().max_element()).fold(0.0, f64::max);
    CGAL_TOLERANCE + 16.0 * f64::EPSILON * largest * area / volume
}

/// Refusals (what `texgeo boolean` would reject) and failures.
fn refusal(e: BooleanError) -> Failure {
    match e {
        BooleanError::Input { reason: InputError::NotSolid(n), .. } => Failure::not_solid(n),
        BooleanError::Input { .. } => Failure::refused("invalid-operand", e),
        BooleanError::NotClosed { .. } => Failure::failed("open-result", e),
        BooleanError::Invalid { .. } => Failure::failed("invalid-result", e),
        BooleanError::Refine(_) => Failure::failed("refine", e),
        BooleanError::Classify(_) | BooleanError::Inclusion { .. } => Failure::failed("classify", e),
        BooleanError::Mesh(_) => Failure::failed("mesh", e),
    }
}

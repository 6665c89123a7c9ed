//! `--task subdivide`: Catmull-Clark to a level with fragment meshes on the GPU (or the
//! CPU reference) and compare the result with a reference refinement vertex by vertex.

use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::choice::{self, Choice};
use crate::subdiv::compare::Comparison;
use crate::subdiv::gpu::{Options as GpuOptions, Subdivider};
use crate::subdiv::{Method, SubdivError, cpu, osd};
use crate::sweep::record::{Record, mesh_hash as hash};
use crate::sweep::task::{Failure, Input, Task, relative};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Options {
    /// `gpu` (fragment meshes) or `cpu` (the f64 reference), as `texgeo subdivide --method`.
    #[serde(with = "crate::choice::by_name")]
    pub method: Method,
    pub level: u32,
    /// `auto` (the CPU reference for `gpu`, OpenSubdiv for `cpu`), `cpu`, `osd` or `none`.
    #[serde(with = "crate::choice::choice_or_none")]
    pub reference: Option<Choice<Reference>>,
    /// Largest position error accepted, × the reference's bounding-box diagonal
    /// (default: 1e-5 for `gpu`, 1e-12 for `cpu`, as `texgeo subdivide --validate`).
    pub tolerance: Option<f64>,
}

impl Default for Options {
    fn default() -> Options {
        Options { method: Method::Gpu, level: 2, reference: Some(Choice::Auto), tolerance: None }
    }
}

/// What a refinement is compared with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Reference {
    /// The f64 CPU reference.
    Cpu,
    /// OpenSubdiv (its helper, built by `tools/setup`).
    Osd,
}

/// The highest level a sweep asks for (each level multiplies the faces by four).
const MAX_LEVEL: u32 = 8;

impl Options {
    /// The reference `auto` stands for: the CPU one for `gpu`, OpenSubdiv for `cpu`.
    fn reference(&self) -> Option<Reference> {
        self.reference.map(|r| {
            r.fixed().unwrap_or(match self.method {
                Method::Gpu => Reference::Cpu,
                Method::Cpu => Reference::Osd,
            })
        })
    }
}

/// Catmull-Clark; keeps one [`Subdivider`] (pipeline, targets) for all the worker's meshes.
#[derive(Default)]
pub struct Subdivide {
    subdivider: Option<Subdivider>,
}

impl Task for Subdivide {
    const NAME: &'static str = "subdivide";
    type Options = Options;

    fn validate(o: &Options) -> Result<(), String> {
        if o.level > MAX_LEVEL {
            return Err(format!("level {} is above {MAX_LEVEL}", o.level));
        }
        if o.tolerance.is_some_and(|t| !(t.is_finite() && t >= 0.0)) {
            return Err("tolerance must be a non-negative number".into());
        }
        Ok(())
    }

    fn needs_device(o: &Options) -> bool {
        o.method == Method::Gpu
    }

    fn run(&mut self, input: Input, o: &Options, out: &mut Record) -> Result<(), Failure> {
        let Input { ctx, mesh, .. } = input;
        let gpu = o.method == Method::Gpu;
        out.size("level", o.level);
        let refined = if gpu {
            let ctx = ctx.ok_or_else(|| Failure::failed("device", "the GPU method needs a Vulkan device"))?;
            if self.subdivider.is_none() {
                self.subdivider = Some(Subdivider::new(ctx).map_err(refusal)?);
            }
            let Some(subdivider) = self.subdivider.as_mut() else {
                return Err(Failure::failed("device", "no subdivider"));
            };
            let run = subdivider.refine(ctx, mesh, o.level, &GpuOptions::default()).map_err(refusal)?;
            let t = &run.times;
            for (k, d) in [
                ("base", t.base),
                ("fragments", t.fragments),
                ("upload", t.upload),
                ("passes", t.passes_total()),
                ("readback", t.readback),
                ("submit", t.submit),
                ("assembly", t.assembly),
                ("refine", t.total),
            ] {
                out.time(k, d);
            }
            out.size("fragments", run.fragments);
            out.size("gpu_levels", run.gpu_levels);
            run.mesh
        } else {
            let t = Instant::now();
            let refined = cpu::refine(mesh, o.level).map_err(refusal)?;
            out.time("refine", t.elapsed());
            refined
        };
        out.size("out_vertices", refined.num_vertices());
        out.size("out_faces", refined.num_faces());
        out.hash("mesh", &hash(&refined));

        let Some(reference) = o.reference() else {
            return Ok(());
        };
        let t = Instant::now();
        let expected = match reference {
            Reference::Cpu => cpu::refine(mesh, o.level),
            Reference::Osd => osd::refine(mesh, o.level),
        }
        .map_err(|e| match e {
            SubdivError::HelperMissing { .. } | SubdivError::Helper { .. } | SubdivError::Io { .. } => {
                Failure::failed("reference", e)
            }
            e => refusal(e),
        })?;
        out.time("reference", t.elapsed());
        let tolerance = o.tolerance.unwrap_or(if gpu { 1e-5 } else { 1e-12 });
        let c = Comparison::new(&refined, &expected, tolerance);
        let rel = if c.diagonal > 0.0 { c.max_error / c.diagonal } else { c.max_error };
        out.check("max_error", relative(rel));
        out.check("matches", c.is_match());
        if !c.is_match() {
            return Err(Failure::failed(
                "check",
                format!(
                    "differs from the {} reference beyond {tolerance:e} × diagonal: {}",
                    choice::name(&reference),
                    c
                )
                .trim_end()
                .replace('\n', ";"),
            ));
        }
        Ok(())
    }
}

/// Refusals (input Catmull-Clark cannot refine, levels too large) and failures.
fn refusal(e: SubdivError) -> Failure {
    let reason = match &e {
        SubdivError::Feature(_) => "feature-tags",
        SubdivError::TooLarge { .. } | SubdivError::Memory { .. } => "too-large",
        SubdivError::Fragment(_) => "fragment-mesh",
        SubdivError::GpuLimit(_) => "gpu-limit",
        SubdivError::Gpu(_) => return Failure::failed("gpu", e),
        SubdivError::Mesh(_) => return Failure::failed("mesh", e),
        SubdivError::HelperMissing { .. } | SubdivError::Helper { .. } | SubdivError::Io { .. } => {
            return Failure::failed("error", e);
        }
    };
    Failure::refused(reason, e)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_keep_their_spelling_and_auto_picks_the_reference_by_method() {
        let text = r#"{"method":"gpu","level":2,"reference":"auto","tolerance":null}"#;
        assert_eq!(serde_json::to_string(&Options::default()).unwrap(), text);
        assert_eq!(serde_json::from_str::<Options>(text).unwrap(), Options::default());
        assert_eq!(Options::default().reference(), Some(Reference::Cpu));
        let cpu: Options = serde_json::from_str(r#"{"method":"cpu"}"#).unwrap();
        assert_eq!(cpu.reference(), Some(Reference::Osd));
        let fixed: Options = serde_json::from_str(r#"{"method":"cpu","reference":"cpu"}"#).unwrap();
        assert_eq!(fixed.reference(), Some(Reference::Cpu));
        let none: Options = serde_json::from_str(r#"{"reference":"none"}"#).unwrap();
        assert_eq!(none.reference(), None);
        assert!(serde_json::from_str::<Options>(r#"{"reference":"gpu"}"#).is_err());
        assert!(serde_json::from_str::<Options>(r#"{"method":"osd"}"#).is_err());
    }
}

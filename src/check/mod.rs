//! `texgeo check`: the shader correctness suite for a device. Every shader and pass runs
//! on small built-in cases through the same library paths the commands use, and its
//! output is compared with the CPU reference of the same algorithm, bit for bit where the
//! algorithm is exact (reduction of integers, XOR parity, voxels, inclusion classes) and to
//! the float32 tolerance elsewhere (subdivision). A check the device cannot run (no
//! `logicOp`, too few samples or too small textures, or a feature hidden by
//! `TEXGEO_MASK_FEATURES`) is *not supported*, never passed. No shader of texgeo uses
//! float64, so no check needs `shaderFloat64`.
//!
//! One file per group of checks ([`gpu`]: reduction and XOR rasterization, [`inclusion`],
//! [`voxel`], [`subdiv`], [`render`]); [`report`] prints the table and the JUnit XML.

mod gpu;
mod inclusion;
mod render;
pub mod report;
mod subdiv;
mod voxel;

use std::fmt;
use std::time::{Duration, Instant};

use crate::gpu::{Context, DeviceInfo, GpuError};
use crate::inclusion::InclusionError;
use crate::render::RenderError;
use crate::subdiv::SubdivError;
use crate::voxel::VoxelError;

/// The first difference between what a pass produced and the CPU reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Mismatch {
    /// Where: a texel, voxel, point, vertex or pixel, with the case it belongs to.
    pub item: String,
    pub expected: String,
    pub got: String,
}

/// Why a check failed.
#[derive(Clone, Debug, PartialEq)]
pub enum Failure {
    /// The output differs from the reference.
    Mismatch(Mismatch),
    /// The pass did not run to the end (an error, a validation message, a panic), or it
    /// ran but left its work to the CPU.
    Error(String),
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Failure::Mismatch(m) => write!(f, "{}: expected {}, got {}", m.item, m.expected, m.got),
            Failure::Error(e) => f.write_str(e),
        }
    }
}

/// The outcome of one check.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    Pass,
    Fail(Failure),
    /// The device lacks what the check needs (the reason names it).
    NotSupported(String),
}

/// What stops a check early; `?` turns library errors into it.
#[derive(Debug)]
pub(crate) enum Stop {
    Fail(Failure),
    Unsupported(String),
}

impl Stop {
    /// A mismatch at `item`.
    pub(crate) fn mismatch(item: impl Into<String>, expected: impl fmt::Debug, got: impl fmt::Debug) -> Stop {
        Stop::Fail(Failure::Mismatch(Mismatch {
            item: item.into(),
            expected: format!("{expected:?}"),
            got: format!("{got:?}"),
        }))
    }

    /// A failure that is not a value mismatch.
    pub(crate) fn error(message: impl Into<String>) -> Stop {
        Stop::Fail(Failure::Error(message.into()))
    }
}

impl From<GpuError> for Stop {
    fn from(e: GpuError) -> Stop {
        match e {
            GpuError::Unsupported(why) => Stop::Unsupported(why),
            e => Stop::error(e.to_string()),
        }
    }
}

/// `From` a module's error for `?`: its GPU error as a [`GpuError`] is taken, the listed
/// variant (what this device or these sizes cannot do) is not supported, anything else fails.
macro_rules! stop_from {
    ($error:ident, $gpu:ident $(, $unsupported:pat)?) => {
        impl From<$error> for Stop {
            fn from(e: $error) -> Stop {
                match e {
                    $error::$gpu(g) => g.into(),
                    $(e @ $unsupported => Stop::Unsupported(e.to_string()),)?
                    e => Stop::error(e.to_string()),
                }
            }
        }
    };
}

stop_from!(VoxelError, Gpu, VoxelError::Resolution { .. });
stop_from!(InclusionError, Gpu, InclusionError::TooLarge(_));
stop_from!(SubdivError, Gpu, SubdivError::GpuLimit(_));
stop_from!(RenderError, Gpu);

impl From<crate::mesh::MeshError> for Stop {
    fn from(e: crate::mesh::MeshError) -> Stop {
        Stop::error(format!("building the case: {e}"))
    }
}

pub(crate) type Step = std::result::Result<(), Stop>;

/// What a check needs of the device beyond texgeo's baseline (Vulkan 1.3, push
/// descriptors), decided before it runs.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Needs {
    pub logic_op: bool,
    /// Largest side of a 2D texture or viewport the cases draw into.
    pub texture: u32,
    /// Samples per pixel of colour and depth targets.
    pub samples: u32,
}

impl Needs {
    /// Why `info` cannot run the check, if it cannot.
    fn missing(&self, info: &DeviceInfo) -> Option<String> {
        if self.logic_op && !info.logic_op {
            return Some(if info.masked.iter().any(|m| m == "logic_op") {
                "logicOp (hidden by TEXGEO_MASK_FEATURES)".into()
            } else {
                "the device has no logicOp".into()
            });
        }
        let side = info.max_image_2d.min(info.max_viewport[0]).min(info.max_viewport[1]);
        if self.texture > side {
            return Some(format!("{}² textures (the device draws up to {side}²)", self.texture));
        }
        if self.samples > 1 {
            let offered = info.colour_samples & info.depth_samples;
            if offered & self.samples == 0 {
                return Some(format!("{} samples per pixel in colour and depth targets", self.samples));
            }
        }
        None
    }
}

/// One check: a pass (or a few) on built-in cases against the CPU reference.
pub struct Check {
    pub name: &'static str,
    /// What the check runs and compares, in one line.
    pub what: &'static str,
    pub(crate) needs: Needs,
    pub(crate) run: fn(&Context) -> Step,
}

impl Check {
    /// The group the check belongs to: its name up to the first `-` (`--only` takes it).
    pub fn group(&self) -> &'static str {
        self.name.split('-').next().unwrap_or(self.name)
    }
}

/// Every check, in the order they run.
pub fn all() -> Vec<Check> {
    let mut checks = gpu::checks();
    checks.extend(inclusion::checks());
    checks.extend(voxel::checks());
    checks.extend(subdiv::checks());
    checks.extend(render::checks());
    checks
}

/// The checks `only` names (check names or group names); all of them when `only` is
/// empty. An unknown name is an error listing the valid ones.
pub fn select(only: &[String]) -> std::result::Result<Vec<Check>, String> {
    let checks = all();
    if only.is_empty() {
        return Ok(checks);
    }
    for name in only {
        if !checks.iter().any(|c| c.name == name || c.group() == name) {
            let mut groups: Vec<&str> = checks.iter().map(Check::group).collect();
            groups.dedup();
            let names: Vec<&str> = checks.iter().map(|c| c.name).collect();
            return Err(format!(
                "no check '{name}' (groups: {}; checks: {})",
                groups.join(", "),
                names.join(", ")
            ));
        }
    }
    Ok(checks.into_iter().filter(|c| only.iter().any(|n| c.name == n || c.group() == n)).collect())
}

/// The outcome of one check and how long it took.
#[derive(Clone, Debug)]
pub struct Record {
    pub name: &'static str,
    pub what: &'static str,
    pub outcome: Outcome,
    pub time: Duration,
}

/// Runs `check` on `ctx`: not supported when the device lacks what it needs; failed on a
/// mismatch, an error, a panic or a validation message it caused.
pub fn run(ctx: &Context, check: &Check) -> Record {
    let start = Instant::now();
    // Messages of earlier work are not this check's.
    let earlier = ctx.check_validation();
    let outcome = if let Err(e) = earlier {
        Outcome::Fail(Failure::Error(format!("before this check: {e}")))
    } else if let Some(why) = check.needs.missing(ctx.info()) {
        Outcome::NotSupported(why)
    } else {
        let ran = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| (check.run)(ctx)));
        let outcome = match ran {
            Ok(Ok(())) => Outcome::Pass,
            Ok(Err(Stop::Fail(f))) => Outcome::Fail(f),
            Ok(Err(Stop::Unsupported(why))) => Outcome::NotSupported(why),
            Err(panic) => {
                let text = panic
                    .downcast_ref::<String>()
                    .map(String::as_str)
                    .or_else(|| panic.downcast_ref::<&str>().copied())
                    .unwrap_or("(no message)");
                Outcome::Fail(Failure::Error(format!("panicked: {text}")))
            }
        };
        // A validation message fails the check that caused it, whatever it computed.
        match ctx.check_validation() {
            Err(e) => Outcome::Fail(Failure::Error(e.to_string())),
            Ok(()) => outcome,
        }
    };
    Record { name: check.name, what: check.what, outcome, time: start.elapsed() }
}

/// Compares two equally long sequences and stops at the first difference, naming the
/// item with `item(index)`.
pub(crate) fn first_difference<T: PartialEq + fmt::Debug>(
    expected: &[T],
    got: &[T],
    item: impl Fn(usize) -> String,
) -> Step {
    if expected.len() != got.len() {
        return Err(Stop::mismatch(
            format!("{} (count)", item(expected.len().min(got.len()))),
            expected.len(),
            got.len(),
        ));
    }
    match expected.iter().zip(got).position(|(e, g)| e != g) {
        Some(i) => Err(Stop::mismatch(item(i), &expected[i], &got[i])),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fake(run: fn(&Context) -> Step, needs: Needs) -> Check {
        Check { name: "fake-check", what: "a check of the checks", needs, run }
    }

    #[test]
    fn mismatches_errors_panics_and_missing_features_are_never_passes() {
        let ctx = Context::from_env().expect("a Vulkan device (run tools/setup)");
        let record = run(&ctx, &fake(|_| Ok(()), Needs::default()));
        assert_eq!(record.outcome, Outcome::Pass);
        let record = run(
            &ctx,
            &fake(|_| first_difference(&[1, 2, 3], &[1, 2, 4], |i| format!("texel {i}")), Needs::default()),
        );
        let want = Mismatch { item: "texel 2".into(), expected: "3".into(), got: "4".into() };
        assert_eq!(record.outcome, Outcome::Fail(Failure::Mismatch(want)));
        let record = run(&ctx, &fake(|_| panic!("boom"), Needs::default()));
        assert_eq!(record.outcome, Outcome::Fail(Failure::Error("panicked: boom".into())));
        let record = run(&ctx, &fake(|_| Err(GpuError::Usage("bad".into()).into()), Needs::default()));
        assert_eq!(record.outcome, Outcome::Fail(Failure::Error("bad".into())));
        let record = run(&ctx, &fake(|_| Err(GpuError::Unsupported("no X".into()).into()), Needs::default()));
        assert_eq!(record.outcome, Outcome::NotSupported("no X".into()));
        // Needs beyond the device are not run at all.
        let huge = Needs { texture: u32::MAX, ..Needs::default() };
        let record = run(&ctx, &fake(|_| panic!("must not run"), huge));
        assert!(matches!(&record.outcome, Outcome::NotSupported(w) if w.contains("textures")), "{record:?}");
    }

    #[test]
    fn a_validation_message_fails_the_check_that_caused_it() {
        use crate::gpu::{Attachment, Buffer, ContextOptions, Load, TexFormat, Texture, XorRaster};
        if !crate::gpu::validation_layer_installed() {
            eprintln!(
                "the validation layer is not installed: nothing to check here (tools/setup installs it)"
            );
            return;
        }
        let options = ContextOptions { validation: Some(true), ..ContextOptions::default() };
        let ctx = Context::new(&options).expect("a Vulkan device with the validation layer");
        if !ctx.info().logic_op {
            return;
        }
        // Copying out of an attachment without the barrier: a hazard the layer reports,
        // although lavapipe computes the right texels anyway.
        let hazard: fn(&Context) -> Step = |ctx| {
            let xor = XorRaster::new(ctx, TexFormat::R32Ui)?;
            let target = Texture::new(ctx, TexFormat::R32Ui, 8, 8, "hazard")?;
            let tri: Vec<[f32; 2]> = vec![[0.0, 0.0], [8.0, 0.0], [0.0, 8.0]];
            let vb = Buffer::with_data(ctx, &tri, "tri")?;
            ctx.submit(|rec| {
                rec.render(&[Attachment::new(&target, Load::Zero)], None, &[], |p| {
                    xor.draw(p, &vb, 3, [8, 8], 1)
                })?;
                rec.skip_next_barrier_for_test(&target, false);
                rec.readback(&target)
            })?;
            Ok(())
        };
        let record = run(&ctx, &fake(hazard, Needs::default()));
        assert!(
            matches!(&record.outcome, Outcome::Fail(Failure::Error(e)) if e.contains("alidation")),
            "{record:?}"
        );
        // The next check starts clean.
        assert_eq!(run(&ctx, &fake(|_| Ok(()), Needs::default())).outcome, Outcome::Pass);
    }

    #[test]
    fn only_takes_check_and_group_names() {
        let names = |only: &[&str]| -> Vec<&str> {
            let only: Vec<String> = only.iter().map(|s| s.to_string()).collect();
            select(&only).unwrap().iter().map(|c| c.name).collect()
        };
        assert_eq!(names(&["xor"]), ["xor-parity", "xor-top-left"]);
        assert_eq!(names(&["render-msaa", "reduce-npot"]), ["reduce-npot", "render-msaa"]);
        assert_eq!(names(&[]).len(), all().len());
        let err = select(&["nope".to_string()]).err().unwrap();
        assert!(err.contains("no check 'nope'") && err.contains("subdiv-valence"), "{err}");
    }
}

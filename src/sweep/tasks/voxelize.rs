//! `--task voxelize`: voxelize at N³ with the method under test and compare the bit
//! volume with an exact method, voxel by voxel.

use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::gpu::Context;
use crate::mesh::solidity::{Policy, require_solid};
use crate::mesh::{Mesh, Report};
use crate::sweep::record::{Fnv, Record};
use crate::sweep::task::{Failure, Input, Task};
use crate::voxel::auto::{Counts, Device, Plan};
use crate::voxel::{Choice, Grid, Method, Solid, VoxelError, Voxelizer, Zone, grid};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Options {
    /// The method under test (`texgeo voxelize --method`; `auto` chooses among the
    /// methods the worker's device runs, and is recorded as `method`).
    pub method: Choice,
    /// Voxels per side.
    pub res: usize,
    /// The method every voxel is compared with (`none`: no comparison).
    #[serde(with = "crate::choice::by_name_or_none")]
    pub reference: Option<Method>,
    /// Zone height for `zoned` (default: chosen from the mesh and memory).
    pub zone: Option<usize>,
    /// Accept meshes that are not solids (`voxelize --allow-open`): their voxels are the
    /// centres inside by the generalized winding number (on the CPU whatever the method),
    /// checked against the per-point classification of every centre, and the defect is
    /// recorded (`non_solid`).
    pub allow_open: bool,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            method: Choice::Auto,
            res: 64,
            reference: Some(Method::Scanline),
            zone: None,
            allow_open: false,
        }
    }
}

/// Solid voxelization by slicing tetrahedra; keeps one [`Voxelizer`] (and its pipelines)
/// for all the worker's meshes.
#[derive(Default)]
pub struct Voxelize {
    voxelizer: Option<Voxelizer>,
    with_device: bool,
}

impl Voxelize {
    fn voxelizer(&mut self, ctx: Option<&Context>, zone: Option<usize>) -> &mut Voxelizer {
        if self.voxelizer.is_none() || (!self.with_device && ctx.is_some()) {
            self.voxelizer = Some(Voxelizer::new(ctx.cloned()));
            self.with_device = ctx.is_some();
        }
        let v = self.voxelizer.get_or_insert_with(|| Voxelizer::new(None));
        v.zone = zone.and_then(std::num::NonZeroUsize::new).map(Zone::Slices).unwrap_or_default();
        v
    }
}

impl Task for Voxelize {
    const NAME: &'static str = "voxelize";
    type Options = Options;

    fn validate(o: &Options) -> Result<(), String> {
        grid::check_resolution(o.res).map_err(|e| e.to_string())
    }

    fn needs_device(o: &Options) -> bool {
        [o.method.fixed(), o.reference].into_iter().flatten().any(Method::uses_gpu)
    }

    fn run(&mut self, input: Input, o: &Options, out: &mut Record) -> Result<(), Failure> {
        let Input { ctx, mesh, report } = input;
        let refusal = |e: VoxelError| refusal(e, report);
        // The same gate as `texgeo voxelize`: what the command refuses, the sweep refuses.
        let policy = Policy { allow_open: o.allow_open, ..Policy::default() };
        let accepted = require_solid(mesh.clone(), policy).map_err(Failure::not_solid)?;
        let mesh = &accepted.mesh;
        if let Some(defect) = &accepted.non_solid {
            out.check("non_solid", defect.slug());
            return winding_rule(mesh, o, out);
        }
        let t = Instant::now();
        let grid = Grid::for_mesh(mesh, o.res).map_err(refusal)?;
        let solid = Solid::new(mesh).map_err(refusal)?;
        out.time("covering", t.elapsed());
        out.size("res", o.res);
        let m = o.method.fixed().unwrap_or_else(|| {
            let threads = rayon::current_num_threads();
            let m = Plan::choose(Counts::new(&solid, &grid), Device::of(ctx), threads).method;
            out.check("method", m.name());
            m
        });

        let result = self.voxelizer(ctx, o.zone).run(&solid, &grid, m).map_err(refusal)?;
        let t = result.timings;
        for (k, d) in [
            ("prepare", t.prepare),
            ("draw", t.draw),
            ("copy", t.copy),
            ("readback", t.readback),
            ("fallback", t.fallback),
            ("voxelize", t.total),
        ] {
            out.time(k, d);
        }
        out.size("occupied", result.volume.count());
        out.size("band_candidates", result.band.candidates);
        out.size("band_corrected", result.band.changed);
        let mut h = Fnv::default();
        for j in 0..o.res {
            for k in 0..o.res {
                for &w in result.volume.row(j, k) {
                    h.u64(w);
                }
            }
        }
        out.hash("volume", &h);

        let Some(r) = o.reference else {
            return Ok(());
        };
        let t = Instant::now();
        let expected = self.voxelizer(ctx, o.zone).run(&solid, &grid, r).map_err(refusal)?;
        out.time("reference", t.elapsed());
        let differing = result.volume.count_differences(&expected.volume).map_err(refusal)?;
        out.check("differing", differing);
        if differing > 0 {
            return Err(Failure::failed("check", format!("{differing} voxels differ from the {r} volume")));
        }
        Ok(())
    }
}

/// A mesh that is not a solid, under `allow_open`: the voxels whose centre is inside by
/// the generalized winding number, checked centre by centre against the per-point
/// classification (`inclusion --allow-open`).
fn winding_rule(mesh: &Mesh, o: &Options, out: &mut Record) -> Result<(), Failure> {
    use rayon::prelude::*;
    let map = |e: crate::inclusion::InclusionError| Failure::failed("winding", e);
    let grid = Grid::for_mesh(mesh, o.res).map_err(|e| Failure::refused("flat", e))?;
    out.size("res", o.res);
    let t = Instant::now();
    let fast = crate::inclusion::fast_winding::FastWinding::for_voxels(mesh).map_err(map)?;
    let volume = fast.voxelize(&grid).map_err(|e| Failure::failed("winding", e))?;
    out.time("voxelize", t.elapsed());
    out.size("occupied", volume.count());
    let mut h = Fnv::default();
    for j in 0..o.res {
        for k in 0..o.res {
            for &w in volume.row(j, k) {
                h.u64(w);
            }
        }
    }
    out.hash("volume", &h);
    if o.reference.is_none() {
        return Ok(());
    }
    let t = Instant::now();
    let n = o.res;
    let differing: u64 = (0..n * n)
        .into_par_iter()
        .map(|jk| {
            let (j, k) = (jk / n, jk % n);
            (0..n)
                .filter(|&i| {
                    let inside =
                        fast.classify_point(grid.centre(i, j, k)).0 == crate::inclusion::Class::Inside;
                    inside != volume.get(i, j, k)
                })
                .count() as u64
        })
        .sum();
    out.time("reference", t.elapsed());
    out.check("differing", differing);
    if differing > 0 {
        return Err(Failure::failed(
            "check",
            format!("{differing} voxels differ from their centres' labels"),
        ));
    }
    Ok(())
}

/// Refusals (what `texgeo voxelize` would reject) and failures.
fn refusal(e: VoxelError, report: &Report) -> Failure {
    match e {
        VoxelError::Mesh(_) if !report.is_closed() => Failure::refused("not-closed", e),
        VoxelError::Mesh(_) if report.faces == 0 => Failure::refused("empty", e),
        VoxelError::Mesh(_) => Failure::refused("flat", e),
        VoxelError::Resolution { .. } => Failure::refused("options", e),
        VoxelError::Memory { .. } => Failure::refused("too-large", e),
        VoxelError::Gpu(_) => Failure::failed("gpu", e),
        VoxelError::Usage(_)
        | VoxelError::Binvox { .. }
        | VoxelError::Io { .. }
        | VoxelError::MeshFile(_) => Failure::failed("error", e),
    }
}

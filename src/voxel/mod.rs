//! Solid voxelization by slicing the tetras of a simplicial covering with XOR (2006
//! thesis, Ch. 5; SPEC §4).
//!
//! Every method returns the same bit volume: voxel (i, j, k) is occupied iff its centre
//! ([`Grid::centre`]) is inside the solid, with centres on the surface decided by the
//! tie rule of [`exact`] (pushed along +x, then +z, then +y: top-left in a slice, half-
//! open along y). Methods that rasterize in floating point hand the centres within their
//! error bound of the surface to the exact classifier ([`band`]), so none of them is ever
//! silently wrong (SPEC §0).
//!
//! "Inside" is the parity of the XOR accumulation (§5.3.1): an odd number of covering
//! tetras, i.e. an odd winding number. On a valid solid ([`crate::mesh::solidity`]: the
//! winding number is 0 or 1) that is `inclusion`'s answer too; `texgeo voxelize` refuses
//! meshes that are not valid solids (nested or overlapping shells would give winding 2,
//! which parity calls outside), or flips inverted ones with `--flip-inverted`. Where
//! `inclusion` answers OnBoundary, the tie rule gives the voxel's value.
//!
//! | method | what it is |
//! |---|---|
//! | `cpu` | tetra slicing (Table 5-1) + scanline XOR rasterizer (§5.3.2) |
//! | `fgpu` | the CPU slices, the GPU rasterizes with logic op XOR (§5.3.3) |
//! | `pgpu` | Alg. 5-2: the vertex shader slices a static buffer of tetras (§5.3.4) |
//! | `zoned` | PGPU-MP: tetras grouped by y-zone, each slice draws only its zone |
//! | `fang` | Fang & Chen: surface triangles sliced into slabs, XOR along y (§5.2.6) |
//! | `scanline` | exact ray parity along x rows (§5.2.1) |
//!
//! `auto` ([`crate::choice::Choice::Auto`], the command's default) picks the fastest of them for the
//! device, solid and resolution from measured cost models ([`auto`]).

pub mod aspect;
pub mod auto;
pub mod band;
pub mod binvox;
pub mod cpu;
pub mod error;
pub mod exact;
mod fang;
mod fgpu;
pub mod grid;
mod layers;
pub mod npy;
pub mod pgpu;
pub mod pictures;
pub mod raster;
pub mod scanline;
pub mod slicing;
pub mod solid;
pub mod volume;

use std::time::{Duration, Instant};

pub use band::BandReport;
pub use error::{Result, VoxelError};
pub use grid::{Grid, MAX_RES};
pub use solid::Solid;
pub use volume::Volume;

use crate::gpu::Context;
use crate::mesh::Mesh;

/// A voxelization method (see the module table; `--method`). A new method is one variant
/// here and one arm in [`Voxelizer::run`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Method {
    /// Tetra slicing (Table 5-1) + scanline XOR rasterizer on the CPU.
    Cpu,
    /// The CPU slices, the GPU rasterizes with logic-op XOR.
    Fgpu,
    /// Alg. 5-2: the vertex shader slices a static buffer of tetras, one draw per slice.
    Pgpu,
    /// PGPU-MP: one display list per zone of slices (`--zone`).
    Zoned,
    /// Fang & Chen: surface triangles cut into slabs, XOR along y.
    Fang,
    /// Exact ray parity along x rows.
    Scanline,
}

impl Method {
    pub const ALL: [Method; 6] =
        [Method::Cpu, Method::Fgpu, Method::Pgpu, Method::Zoned, Method::Fang, Method::Scanline];

    pub fn name(self) -> &'static str {
        match self {
            Method::Cpu => "cpu",
            Method::Fgpu => "fgpu",
            Method::Pgpu => "pgpu",
            Method::Zoned => "zoned",
            Method::Fang => "fang",
            Method::Scanline => "scanline",
        }
    }

    /// Whether the method needs a Vulkan device.
    pub fn uses_gpu(self) -> bool {
        matches!(self, Method::Fgpu | Method::Pgpu | Method::Zoned | Method::Fang)
    }
}

/// `--method`: one method, or `auto`, the fastest one by the cost models of [`auto`].
pub type Choice = crate::choice::Choice<Method>;

/// The zone height of `zoned` (PGPU-MP, §5.4.2; `--zone`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Zone {
    /// [`pgpu::default_zone`]: N/8 slices, between 4 and 32.
    #[default]
    Auto,
    /// This many slices per zone (at least 1).
    Slices(std::num::NonZeroUsize),
}

impl Zone {
    /// The height in slices at resolution `n`.
    pub fn slices(self, n: usize) -> usize {
        match self {
            Zone::Auto => pgpu::default_zone(n),
            Zone::Slices(z) => z.get(),
        }
    }
}

impl std::str::FromStr for Zone {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Zone, String> {
        if s == "auto" {
            return Ok(Zone::Auto);
        }
        match s.parse::<usize>() {
            Ok(z) => std::num::NonZeroUsize::new(z).map(Zone::Slices).ok_or_else(|| {
                "a zone holds at least 1 slice (or 'auto': N/8, between 4 and 32)".to_string()
            }),
            Err(_) => Err(format!("'{s}' is not a number of slices or 'auto'")),
        }
    }
}

impl std::fmt::Display for Zone {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Zone::Auto => f.write_str("auto"),
            Zone::Slices(z) => write!(f, "{z}"),
        }
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Where the time of one voxelization went (`voxelize --json`: in ms).
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct Timings {
    /// CPU work before drawing: tetras, vertex buffers, zones, slab pieces.
    #[serde(rename = "prepare_ms", serialize_with = "crate::json::ms")]
    pub prepare: Duration,
    /// Rasterization: GPU time of the draws (timestamps), or the CPU rasterizer.
    #[serde(rename = "draw_ms", serialize_with = "crate::json::ms")]
    pub draw: Duration,
    /// GPU time of the image-to-buffer copies.
    #[serde(rename = "copy_ms", serialize_with = "crate::json::ms")]
    pub copy: Duration,
    /// Host side of the readback: bits moved from the 32-slices-per-texel layers into
    /// the volume.
    #[serde(rename = "readback_ms", serialize_with = "crate::json::ms")]
    pub readback: Duration,
    /// Finding the centres near the surface and classifying them exactly.
    #[serde(rename = "fallback_ms", serialize_with = "crate::json::ms")]
    pub fallback: Duration,
    /// Wall time of the whole call.
    #[serde(rename = "total_ms", serialize_with = "crate::json::ms")]
    pub total: Duration,
}

/// What `texgeo voxelize --json` prints.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Summary {
    /// Voxels per side.
    pub resolution: usize,
    pub occupied: u64,
    /// The method as the CLI spells it (`fast-winding` for a mesh taken by `--allow-open`).
    pub method: String,
    /// The grid: voxel (i, j, k)'s centre is `origin + (i + ½, j + ½, k + ½) · pitch`.
    pub origin: [f64; 3],
    pub pitch: f64,
    pub timings: Timings,
    /// The exact fallback near the surface (GPU methods).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exact_fallback: Option<BandReport>,
    /// The written file.
    pub output: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub device: Option<String>,
}

impl Summary {
    /// A summary of `occupied` voxels on `grid` by `method`; the rest as given.
    pub fn new(
        grid: &Grid,
        occupied: u64,
        method: &str,
        timings: Timings,
        output: &std::path::Path,
    ) -> Summary {
        let (origin, side) = grid.cube_out();
        Summary {
            resolution: grid.n,
            occupied,
            method: method.to_string(),
            origin: origin.to_array(),
            pitch: side / grid.n as f64,
            timings,
            exact_fallback: None,
            output: output.display().to_string(),
            device: None,
        }
    }
}

/// The result of one voxelization.
#[derive(Clone, Debug)]
pub struct Voxelization {
    pub grid: Grid,
    pub volume: Volume,
    pub band: BandReport,
    pub timings: Timings,
}

/// Voxelizes `n`³ voxels of a mesh that
/// [`require_solid`](crate::mesh::solidity::require_solid) accepted, as `texgeo voxelize`
/// does: a mesh taken under allow-open by its generalized winding number on the CPU
/// ([`voxelize_non_solid`]), a solid by `choice` ([`choose_method`]). Returns the grid, the
/// volume and the name of the method that ran (Python's `Mesh.voxelize`).
pub fn voxelize_accepted(
    accepted: &crate::mesh::solidity::Accepted,
    n: usize,
    choice: Choice,
    ctx: impl FnOnce() -> Result<Context>,
) -> Result<(Grid, Volume, String)> {
    let grid = Grid::for_mesh(&accepted.mesh, n)?.in_frame(accepted.frame);
    if accepted.non_solid.is_some() {
        check_non_solid(choice)?;
        return Ok((grid, voxelize_non_solid(&accepted.mesh, &grid)?, "fast-winding".to_string()));
    }
    let solid = Solid::new(&accepted.mesh)?;
    let chosen = choose_method(choice, &solid, &grid, false, |_| ctx())?;
    let result = Voxelizer::new(chosen.ctx).run(&solid, &grid, chosen.method)?;
    Ok((grid, result.volume, chosen.method.name().to_string()))
}

/// Refuses a GPU method for a mesh accepted under allow-open without being a solid: only
/// its generalized winding number on the CPU voxelizes it.
pub fn check_non_solid(choice: Choice) -> Result<()> {
    match choice.fixed() {
        Some(m) if m.uses_gpu() => Err(VoxelError::Usage(format!(
            "method {m} voxelizes solids only; under --allow-open a mesh that is not a solid is voxelized \
             by its generalized winding number on the CPU (--method auto, cpu or scanline)"
        ))),
        _ => Ok(()),
    }
}

/// The voxels of a mesh accepted under allow-open without being a solid: occupied iff the
/// generalized winding number at the centre is at least ½ (centres on the surface empty).
pub fn voxelize_non_solid(mesh: &Mesh, grid: &Grid) -> Result<Volume> {
    let winding = crate::inclusion::fast_winding::FastWinding::for_voxels(mesh)
        .map_err(|e| VoxelError::Mesh(e.to_string()))?;
    winding.voxelize(grid)
}

/// The method [`choose_method`] settled on, and the device it opened.
pub struct Chosen {
    pub method: Method,
    /// What `auto` weighed (`None` for a fixed method).
    pub plan: Option<auto::Plan>,
    /// The device, when the method needs one or the caller asked for it.
    pub ctx: Option<Context>,
}

/// The method `choice` stands for on `solid` at `grid`, and the device it runs with.
/// `auto` asks the cost models as if the GPU's draws were free, so that no device is
/// opened while a CPU method still wins (the usual case on lavapipe and, by the models,
/// elsewhere); when a GPU method wins, or `with_device` (the caller needs the device
/// anyway), it opens the device and asks again for its kind. `open` is called at most
/// once, with the fixed method (`None` under `auto`).
pub fn choose_method<E>(
    choice: Choice,
    solid: &Solid,
    grid: &Grid,
    with_device: bool,
    open: impl FnOnce(Option<Method>) -> std::result::Result<Context, E>,
) -> std::result::Result<Chosen, E> {
    match choice {
        Choice::Fixed(method) => {
            let ctx = if method.uses_gpu() || with_device { Some(open(Some(method))?) } else { None };
            Ok(Chosen { method, plan: None, ctx })
        }
        Choice::Auto => {
            let counts = auto::Counts::new(solid, grid);
            let threads = rayon::current_num_threads();
            let mut plan = auto::Plan::choose(counts, auto::Device::Gpu, threads);
            let mut ctx = None;
            if plan.method.uses_gpu() || with_device {
                let c = open(None)?;
                plan = auto::Plan::choose(counts, auto::Device::of(Some(&c)), threads);
                ctx = Some(c);
            }
            Ok(Chosen { method: plan.method, plan: Some(plan), ctx })
        }
    }
}

/// Runs methods, keeping GPU pipelines alive between runs (a benchmark runs many).
pub struct Voxelizer {
    ctx: Option<Context>,
    /// Alg. 5-2 pipeline (pgpu, zoned), made on first use.
    slice: Option<crate::gpu::Pipeline>,
    /// Pass-through pipeline (fgpu, fang), made on first use.
    section: Option<crate::gpu::Pipeline>,
    /// Zone height for `zoned`.
    pub zone: Zone,
    /// Apply the exact fallback near the surface (on by default; off only to study a
    /// method's raw output — it can then be wrong there).
    pub fallback: bool,
}

impl Voxelizer {
    /// A voxelizer; GPU methods need `ctx`.
    pub fn new(ctx: Option<Context>) -> Voxelizer {
        Voxelizer { ctx, slice: None, section: None, zone: Zone::Auto, fallback: true }
    }

    fn context(&self, method: Method) -> Result<&Context> {
        self.ctx.as_ref().ok_or_else(|| VoxelError::Usage(format!("method {method} needs a Vulkan device")))
    }

    /// The τ of the GPU methods on this voxelizer's device.
    pub fn gpu_tolerance(&self, n: usize) -> Option<f64> {
        self.ctx.as_ref().map(|c| band::tolerance_gpu(n, c.info().sub_pixel_bits))
    }

    /// Voxelizes `solid` on `grid` with `method`.
    pub fn run(&mut self, solid: &Solid, grid: &Grid, method: Method) -> Result<Voxelization> {
        let start = Instant::now();
        let mut timings = Timings::default();
        if solid.triangles.is_empty() {
            // The empty solid: no voxel is inside, whatever the method (nothing to draw).
            let volume = Volume::new(grid.n)?;
            timings.total = start.elapsed();
            return Ok(Voxelization { grid: *grid, volume, band: BandReport::default(), timings });
        }
        let (volume, band) = match method {
            Method::Cpu => {
                let t = Instant::now();
                let mut volume = cpu::rasterize(solid, grid)?;
                timings.draw = t.elapsed();
                let t = Instant::now();
                let report = self.fix(&mut volume, solid, grid, band::tolerance_f64(grid.n))?;
                timings.fallback = t.elapsed();
                (volume, report)
            }
            Method::Scanline => {
                let t = Instant::now();
                let volume = scanline::voxelize(solid, grid)?;
                timings.draw = t.elapsed();
                (volume, BandReport::default())
            }
            Method::Pgpu | Method::Zoned | Method::Fgpu | Method::Fang => {
                let ctx = self.context(method)?.clone();
                let mut volume = self.run_gpu(&ctx, solid, grid, method, &mut timings)?;
                let t = Instant::now();
                let tau = band::tolerance_gpu(grid.n, ctx.info().sub_pixel_bits);
                let report = self.fix(&mut volume, solid, grid, tau)?;
                timings.fallback = t.elapsed();
                (volume, report)
            }
        };
        timings.total = start.elapsed();
        Ok(Voxelization { grid: *grid, volume, band, timings })
    }
}

impl Voxelizer {
    fn fix(&self, volume: &mut Volume, solid: &Solid, grid: &Grid, tau: f64) -> Result<BandReport> {
        if self.fallback {
            band::fix(volume, solid, grid, tau)
        } else {
            Ok(BandReport { tolerance: tau, ..BandReport::default() })
        }
    }

    fn run_gpu(
        &mut self,
        ctx: &Context,
        solid: &Solid,
        grid: &Grid,
        method: Method,
        timings: &mut Timings,
    ) -> Result<Volume> {
        layers::check_device(ctx, grid.n)?;
        match method {
            Method::Pgpu | Method::Zoned => {
                if self.slice.is_none() {
                    self.slice = Some(pgpu::pipeline(ctx)?);
                }
                let pipeline = self.slice.as_ref().ok_or_else(|| VoxelError::Usage("no pipeline".into()))?;
                let zone = (method == Method::Zoned).then(|| self.zone.slices(grid.n));
                let t = Instant::now();
                let mut painter = pgpu::Tetras::new(ctx, pipeline, solid, grid, zone)?;
                timings.prepare += t.elapsed();
                layers::render(ctx, grid.n, &mut painter, timings)
            }
            _ => {
                if self.section.is_none() {
                    self.section = Some(fgpu::pipeline(ctx)?);
                }
                let pipeline =
                    self.section.as_ref().ok_or_else(|| VoxelError::Usage("no pipeline".into()))?;
                let t = Instant::now();
                if method == Method::Fgpu {
                    let mut painter = fgpu::Fgpu::new(ctx, pipeline, solid, grid);
                    timings.prepare += t.elapsed();
                    layers::render(ctx, grid.n, &mut painter, timings)
                } else {
                    let mut painter = fang::Fang::new(ctx, pipeline, solid, grid);
                    timings.prepare += t.elapsed();
                    layers::render(ctx, grid.n, &mut painter, timings)
                }
            }
        }
    }
}

/// Voxelizes `mesh` at resolution `n` with `method` (GPU methods need `ctx`).
pub fn voxelize(ctx: Option<&Context>, mesh: &Mesh, n: usize, method: Method) -> Result<Voxelization> {
    let grid = Grid::for_mesh(mesh, n)?;
    let solid = Solid::new(mesh)?;
    Voxelizer::new(ctx.cloned()).run(&solid, &grid, method)
}

#[cfg(test)]
mod tests {
    use clap::ValueEnum;

    use super::Method;

    /// `name` is the spelling `--method` accepts, for every method, in one order.
    #[test]
    fn names_are_the_command_line_ones() {
        assert_eq!(Method::value_variants(), Method::ALL);
        for m in Method::ALL {
            assert_eq!(m.to_possible_value().unwrap().get_name(), m.name());
        }
    }
}

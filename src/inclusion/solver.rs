//! The one factory of inclusion methods, CPU and GPU: [`Solver::new`] builds any
//! [`Method`] behind one interface, for the command line and the benchmarks; [`build`]
//! gives the CPU classifiers as [`Classifier`] objects.
//!
//! It also applies the one rule every method follows ([`crate::mesh::solidity`]): under
//! `allow_open`, a mesh that is not a solid is classified by its generalized winding
//! number (inside iff w ≥ ½), whichever CPU method is asked for, by
//! [`FastWinding`]; the GPU methods refuse it.

use std::time::{Duration, Instant};

use glam::DVec3;

use super::auto::{self, Pick};
use super::bvh::Bvh;
use super::classifier::{BuildStats, Class, Classifier};
use super::cpu::{EdgeRule, FeitoTorres};
use super::error::{InclusionError, Result};
use super::fast_winding::FastWinding;
use super::gpu::{GpuInclusion, GpuOptions, GpuStats, Phase2};
use super::gpu_grid::GpuGridInclusion;
use super::jordan::Jordan;
use super::method::{Choice, Method, Options};
use super::octants::Octants;
use super::octree::JordanOctree;
use super::points::PointReader;
use super::tetragrid::GridClassifier;
use super::voxel_space::VoxelSpace;
use super::winding::WindingNumber;
use crate::gpu::Context;
use crate::mesh::Mesh;
use crate::mesh::covering::Covering;
use crate::mesh::solidity::{Accepted, Defect};

/// Defaults for the GPU methods: tetrahedra per point-vertex.
pub const GPU_BATCH: u32 = super::gpu::DEFAULT_BATCH;
pub const GPU_GRID_BATCH: u32 = super::gpu_grid::DEFAULT_BATCH;

/// What `texgeo inclusion --json` prints: the counts of each class, the method and where
/// the time went (milliseconds).
#[derive(Clone, Debug, serde::Serialize)]
pub struct Summary {
    pub points: usize,
    pub inside: usize,
    pub outside: usize,
    pub boundary: usize,
    /// The method as the CLI spells it.
    pub method: String,
    /// What `--method auto` chose and why.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub auto: Option<String>,
    #[serde(rename = "build_ms", serialize_with = "crate::json::ms")]
    pub build: std::time::Duration,
    /// Heap bytes of the method's structures.
    pub structure_bytes: usize,
    /// Reading and classifying the points.
    #[serde(rename = "classify_ms", serialize_with = "crate::json::ms")]
    pub classify: std::time::Duration,
    /// The GPU methods' counts and times.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gpu: Option<GpuStats>,
    /// The device's label, for the GPU methods.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub device: Option<String>,
}

/// Any inclusion method, ready to classify points.
pub enum Solver {
    Cpu(Box<dyn Classifier>),
    Gpu(Box<GpuInclusion>),
    GpuGrid(Box<GpuGridInclusion>),
}

/// Whether the winding-number rule for meshes that are not solids applies: under
/// `allow_open`, to a mesh the caller found not to be a solid, or whose surface is not
/// closed.
pub fn winding_rule(mesh: &Mesh, options: &Options) -> bool {
    options.allow_open
        && (options.non_solid || (!options.known_closed && Covering::new(mesh).unbalanced_edge().is_some()))
}

/// The method `auto` stands for on `mesh` with `options` (other methods: themselves).
/// Under the winding-number rule ([`winding_rule`]) it is `winding`, evaluated by
/// [`FastWinding`].
pub fn resolve(method: impl Into<Choice>, mesh: &Mesh, options: &Options) -> (Method, Options, Option<Pick>) {
    if let Choice::Fixed(method) = method.into() {
        return (method, *options, None);
    }
    if winding_rule(mesh, options) {
        let choice = Pick { method: Method::Winding, resolution: None, predicted: f64::NAN };
        return (Method::Winding, *options, Some(choice));
    }
    let choice = auto::choose(triangles(mesh), options.points);
    let mut options = *options;
    if choice.resolution.is_some() && options.voxel_space_resolution.is_none() {
        options.voxel_space_resolution = choice.resolution;
    }
    (choice.method, options, Some(choice))
}

/// Refuses a GPU method for a mesh that [`require_solid`](crate::mesh::solidity::require_solid)
/// accepted without being a solid (under allow-open): only the CPU methods evaluate its
/// generalized winding number.
pub fn check_method(solid: &Accepted, method: Choice) -> Result<()> {
    match method.fixed() {
        Some(m) if solid.non_solid.is_some() && !m.is_cpu() => Err(InclusionError::NotForNonSolids(m.name())),
        _ => Ok(()),
    }
}

/// The options for `points` query points against a mesh that
/// [`require_solid`](crate::mesh::solidity::require_solid) accepted: its verdict says
/// whether the winding-number rule applies and spares the closure check.
pub fn options_for(solid: &Accepted, points: usize, allow_open: bool) -> Options {
    Options {
        points,
        allow_open,
        non_solid: solid.non_solid.is_some(),
        known_closed: !matches!(solid.non_solid, Some(Defect::Open(_))),
        ..Options::default()
    }
}

/// Classifies `points`, given in the input's units, against a mesh that
/// [`require_solid`](crate::mesh::solidity::require_solid) accepted, as `texgeo inclusion`
/// does: the options from the verdict, `auto` resolved for the number of points, the
/// points moved into the mesh's frame. `ctx` is called only for a GPU method. Returns
/// the classes and the name of the method that ran (Python's `Mesh.contains`).
pub fn classify_accepted(
    solid: &Accepted,
    points: &[DVec3],
    method: Choice,
    allow_open: bool,
    ctx: impl FnOnce() -> std::result::Result<Context, crate::gpu::GpuError>,
) -> Result<(Vec<Class>, String)> {
    check_method(solid, method)?;
    let options = options_for(solid, points.len(), allow_open);
    let (method, options, _) = resolve(method, &solid.mesh, &options);
    let ctx = if method.is_cpu() { None } else { Some(ctx()?) };
    let mut solver = Solver::new(method, &solid.mesh, &options, ctx.as_ref(), None)?;
    let frame = solid.frame;
    let framed: Vec<DVec3>;
    let points = if frame.is_identity() {
        points
    } else {
        framed = points.iter().map(|&p| frame.point_in(p)).collect();
        &framed
    };
    let classes = solver.classify_all(points)?;
    Ok((classes, solver.name().to_string()))
}

/// What [`Solver::classify_stream`] counted.
#[derive(Clone, Debug, Default)]
pub struct Streamed {
    /// Points per [`Class`], indexed by its value.
    pub counts: [usize; 3],
    /// Reading and classifying the points (not the sink's time).
    pub classify: Duration,
    /// The GPU's counts and times summed over the blocks (GPU methods).
    pub gpu: Option<GpuStats>,
}

impl Streamed {
    pub fn total(&self) -> usize {
        self.counts.iter().sum()
    }

    pub fn count(&self, class: Class) -> usize {
        self.counts[class as usize]
    }
}

/// The triangles the cost models count: a triangle is one, a polygon of n sides n (its
/// fan about the centroid).
fn triangles(mesh: &Mesh) -> usize {
    mesh.faces().map(|f| if f.len() == 3 { 1 } else { f.len() }).sum()
}

/// Builds the CPU classifier `method` for `mesh` (GPU methods: [`Solver::new`]).
pub fn build(method: impl Into<Choice>, mesh: &Mesh, options: &Options) -> Result<Box<dyn Classifier>> {
    let (method, options, _) = resolve(method, mesh, options);
    let options = &options;
    if winding_rule(mesh, options) {
        if !method.is_cpu() {
            return Err(InclusionError::NotForNonSolids(method.name()));
        }
        return Ok(Box::new(FastWinding::new(mesh, options.points)?));
    }
    // A closure the caller has checked is not checked again.
    let ft = || {
        FeitoTorres::with_policy(
            mesh,
            options.apex,
            EdgeRule::Rerun,
            options.allow_open || options.known_closed,
        )
    };
    Ok(match method {
        Method::Cpu => Box::new(ft()?),
        Method::Bvh => Box::new(Bvh::new(ft()?)),
        Method::Octants => Box::new(Octants::new(ft()?)),
        Method::TetraGrid => Box::new(GridClassifier::new(ft()?, options.tetragrid_resolution)?),
        Method::Jordan => Box::new(Jordan::with_policy(mesh, options.allow_open)?),
        Method::JordanOctree => {
            Box::new(JordanOctree::with_policy(mesh, options.octree_depth, options.allow_open)?)
        }
        Method::Winding => Box::new(WindingNumber::with_policy(mesh, options.allow_open)?),
        Method::VoxelSpace => {
            let n = options
                .voxel_space_resolution
                .unwrap_or_else(|| super::voxel_space::resolution_for(triangles(mesh), options.points));
            // Without the closure check when the caller made it (the same unbalanced-edge test).
            Box::new(VoxelSpace::new(mesh, n, options.allow_open || options.known_closed)?)
        }
        Method::Gpu | Method::CpuGpu | Method::GpuTetraGrid => {
            return Err(InclusionError::NeedsGpu(method.name()));
        }
    })
}

impl Solver {
    /// Builds `method` for `mesh`. GPU methods need `ctx`; `batch` overrides their
    /// tetrahedra per point-vertex.
    pub fn new(
        method: impl Into<Choice>,
        mesh: &Mesh,
        options: &Options,
        ctx: Option<&Context>,
        batch: Option<u32>,
    ) -> Result<Solver> {
        let (method, options, _) = resolve(method, mesh, options);
        let options = &options;
        if method.is_cpu() {
            return Ok(Solver::Cpu(build(method, mesh, options)?));
        }
        if winding_rule(mesh, options) {
            return Err(InclusionError::NotForNonSolids(method.name()));
        }
        let grid = || {
            GridClassifier::new(
                FeitoTorres::with_policy(mesh, options.apex, EdgeRule::Rerun, options.allow_open)?,
                options.tetragrid_resolution,
            )
        };
        let ctx = ctx.ok_or(InclusionError::NeedsGpu(method.name()))?;
        Ok(match method {
            Method::GpuTetraGrid => Solver::GpuGrid(Box::new(GpuGridInclusion::new(
                ctx,
                grid()?,
                batch.unwrap_or(GPU_GRID_BATCH),
            )?)),
            _ => {
                let phase2 = if method == Method::Gpu { Phase2::Gpu } else { Phase2::Host };
                let opts = GpuOptions { batch: batch.unwrap_or(GPU_BATCH), phase2, ..GpuOptions::default() };
                Solver::Gpu(Box::new(GpuInclusion::new(ctx, grid()?, opts)?))
            }
        })
    }

    pub fn name(&self) -> &str {
        match self {
            Solver::Cpu(c) => c.name(),
            Solver::Gpu(g) => g.name(),
            Solver::GpuGrid(_) => Method::GpuTetraGrid.name(),
        }
    }

    pub fn classify_all(&mut self, points: &[DVec3]) -> Result<Vec<Class>> {
        match self {
            Solver::Cpu(c) => Ok(c.classify_all(points)),
            Solver::Gpu(g) => g.classify_all(points),
            Solver::GpuGrid(g) => g.classify_all(points),
        }
    }

    /// Classifies the next block of `source` (`None` at its end), in the parts it was
    /// read in: a CPU method classifies each part in the task that parsed it, a GPU
    /// method the whole block in its draws.
    pub fn classify_next(&mut self, source: &mut PointReader) -> Result<Option<Vec<Vec<Class>>>> {
        if let Solver::Cpu(c) = self {
            return Ok(source.next_block_with(|points| c.classify_all(&points))?);
        }
        source.next_block()?.map(|points| self.classify_all(&points).map(|c| vec![c])).transpose()
    }

    /// Classifies `first` (a block already read: its size sized the method), then the rest
    /// of `source` block by block, handing the classes to `sink` in the order of the
    /// points, a part at a time, as `texgeo inclusion` writes them.
    pub fn classify_stream<E: From<InclusionError>>(
        &mut self,
        first: Option<Vec<DVec3>>,
        source: &mut PointReader,
        mut sink: impl FnMut(&[Class]) -> std::result::Result<(), E>,
    ) -> std::result::Result<Streamed, E> {
        let gpu = self.gpu_stats().map(|_| GpuStats::default());
        let mut streamed = Streamed { gpu, ..Streamed::default() };
        let mut block = first.map(|points| vec![points]);
        loop {
            let t = Instant::now();
            let parts = match block.take() {
                Some(parts) => parts.iter().map(|points| self.classify_all(points)).collect::<Result<_>>()?,
                None => match self.classify_next(source)? {
                    Some(parts) => parts,
                    None => break,
                },
            };
            streamed.classify += t.elapsed();
            if let (Some(sum), Some(g)) = (&mut streamed.gpu, self.gpu_stats()) {
                sum.add(g);
            }
            for classes in &parts {
                for &c in classes {
                    streamed.counts[c as usize] += 1;
                }
                sink(classes)?;
            }
        }
        Ok(streamed)
    }

    /// Classifies a few points (the Booleans' groups of points): a CPU method one point
    /// per task in tasks of at least `grain` points, finer than [`Solver::classify_all`]'s
    /// blocks; a GPU method in its draws.
    pub fn classify_fine(&mut self, points: &[DVec3], grain: usize) -> Result<Vec<Class>> {
        use rayon::prelude::*;
        match self {
            Solver::Cpu(c) => Ok(points.par_iter().with_min_len(grain).map(|&p| c.classify(p)).collect()),
            other => other.classify_all(points),
        }
    }

    /// GPU time split of the last call (`None` for CPU methods).
    pub fn gpu_stats(&self) -> Option<&GpuStats> {
        match self {
            Solver::Cpu(_) => None,
            Solver::Gpu(g) => Some(g.stats()),
            Solver::GpuGrid(g) => Some(g.stats()),
        }
    }

    /// Preprocessing cost of the CPU structures (the GPU methods report the TetraGrid
    /// they use for exact fallback and cell lists).
    pub fn build_stats(&self) -> BuildStats {
        match self {
            Solver::Cpu(c) => c.build_stats(),
            Solver::Gpu(g) => g.exact().build_stats(),
            Solver::GpuGrid(g) => g.grid().build_stats(),
        }
    }
}

//! Any inclusion method behind one interface: the CPU classifiers and the GPU paths,
//! for the command line and the benchmarks.

use glam::DVec3;

use super::gpu::{GpuInclusion, GpuOptions, GpuStats, Phase2};
use super::gpu_grid::GpuGridInclusion;
use super::tetragrid::TetraGrid;
use super::{BuildStats, Class, Classifier, FeitoTorres, Method, Options, Result, build};
use crate::gpu::Context;
use crate::mesh::Mesh;

/// Defaults for the GPU methods: tetrahedra per point-vertex, measured on lavapipe
/// (`texgeo bench inclusion` reports the thesis' batch of 1 beside them).
pub const GPU_BATCH: u32 = 64;
pub const GPU_GRID_BATCH: u32 = 64;

pub enum Solver {
    Cpu(Box<dyn Classifier>),
    Gpu(Box<GpuInclusion>),
    GpuGrid(Box<GpuGridInclusion>),
}

impl Solver {
    /// Builds `method` for `mesh`. GPU methods need `ctx`; `batch` overrides their
    /// tetrahedra per point-vertex.
    pub fn new(
        method: Method,
        mesh: &Mesh,
        options: &Options,
        ctx: Option<&Context>,
        batch: Option<u32>,
    ) -> Result<Solver> {
        let grid = || {
            TetraGrid::new(
                FeitoTorres::with_policy(mesh, options.apex, super::EdgeRule::Rerun, options.allow_open)?,
                options.tetragrid_resolution,
            )
        };
        let need_ctx = || ctx.ok_or(super::InclusionError::NeedsGpu(method));
        let solver = match method {
            Method::Gpu | Method::CpuGpu => {
                let phase2 = if method == Method::Gpu { Phase2::Gpu } else { Phase2::Host };
                let opts = GpuOptions { batch: batch.unwrap_or(GPU_BATCH), phase2, ..GpuOptions::default() };
                Solver::Gpu(Box::new(GpuInclusion::new(need_ctx()?, grid()?, opts)?))
            }
            Method::GpuTetraGrid => Solver::GpuGrid(Box::new(GpuGridInclusion::new(
                need_ctx()?,
                grid()?,
                batch.unwrap_or(GPU_GRID_BATCH),
            )?)),
            cpu => Solver::Cpu(build(cpu, mesh, options)?),
        };
        Ok(solver)
    }

    pub fn name(&self) -> &str {
        match self {
            Solver::Cpu(c) => c.name(),
            Solver::Gpu(g) => g.name(),
            Solver::GpuGrid(_) => "gpu+tetragrid",
        }
    }

    pub fn classify_all(&mut self, points: &[DVec3]) -> Result<Vec<Class>> {
        match self {
            Solver::Cpu(c) => Ok(c.classify_all(points)),
            Solver::Gpu(g) => g.classify_all(points),
            Solver::GpuGrid(g) => g.classify_all(points),
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

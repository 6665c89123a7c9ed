//! Inclusion errors.

use crate::mesh::covering::UnbalancedEdge;

#[derive(Debug, thiserror::Error)]
pub enum InclusionError {
    /// The covering methods need a closed, consistently oriented boundary (SPEC §1).
    #[error("the mesh is not closed and consistently oriented: {0}")]
    NotClosed(UnbalancedEdge),
    #[error("tetragrid resolution {0} is outside 2..=64")]
    Resolution(usize),
    #[error("octree depth {0} is outside 1..=10")]
    OctreeDepth(u32),
    #[error("GPU: {0}")]
    Gpu(crate::gpu::GpuError),
    #[error("too large for the GPU path: {0}")]
    TooLarge(String),
    #[error("invalid options: {0}")]
    Options(String),
    #[error("method '{0}' runs on the GPU and needs a Vulkan device")]
    NeedsGpu(&'static str),
    /// A GPU method asked for a mesh that is not a solid under `--allow-open`.
    #[error(
        "method {0} answers for solids only; under --allow-open a mesh that is not a solid is classified \
         by its generalized winding number on the CPU (--method auto, or any CPU method)"
    )]
    NotForNonSolids(&'static str),
    /// Reading the points to classify.
    #[error(transparent)]
    Points(#[from] crate::mesh::MeshError),
}

impl From<crate::gpu::GpuError> for InclusionError {
    fn from(e: crate::gpu::GpuError) -> InclusionError {
        InclusionError::Gpu(e)
    }
}

impl From<UnbalancedEdge> for InclusionError {
    fn from(e: UnbalancedEdge) -> InclusionError {
        InclusionError::NotClosed(e)
    }
}

pub type Result<T, E = InclusionError> = std::result::Result<T, E>;

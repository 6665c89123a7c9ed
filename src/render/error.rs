use std::path::PathBuf;

use crate::gpu::GpuError;
use crate::mesh::MeshError;

pub type Result<T, E = RenderError> = std::result::Result<T, E>;

#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A request the renderer cannot honour (sizes, colour counts, empty scenes).
    #[error("{0}")]
    Usage(String),
    #[error("{}: {source}", path.display())]
    Io { path: PathBuf, source: std::io::Error },
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error(transparent)]
    Mesh(#[from] MeshError),
    #[error(transparent)]
    Subdiv(#[from] crate::subdiv::SubdivError),
    #[error(transparent)]
    Voxel(#[from] crate::voxel::VoxelError),
}

//! Voxelization errors: bad requests (resolution, memory), meshes the method cannot
//! voxelize, and failures of the GPU, the file formats or the file system underneath.

use std::path::PathBuf;

use crate::gpu::GpuError;
use crate::mesh::MeshError;

pub type Result<T, E = VoxelError> = std::result::Result<T, E>;

#[derive(Debug, thiserror::Error)]
pub enum VoxelError {
    /// The resolution is outside what texgeo supports.
    #[error("resolution {res} is outside 1..={max}{why}")]
    Resolution { res: usize, max: usize, why: String },
    /// The request needs more memory than is available (checked before allocating).
    #[error("{what} at resolution {res} needs {need_mib} MiB, but only {have_mib} MiB are available")]
    Memory { what: String, res: usize, need_mib: crate::host::Mib, have_mib: u64 },
    /// The mesh cannot be voxelized (empty, flat, not closed).
    #[error("cannot voxelize this mesh: {0}")]
    Mesh(String),
    /// Inconsistent arguments (e.g. volumes of different sizes compared).
    #[error("{0}")]
    Usage(String),
    /// A binvox file that cannot be read.
    #[error("{}: {message}", path.display())]
    Binvox { path: PathBuf, message: String },
    /// (The OS error is part of the message, not a `source`, so chains print it once.)
    #[error("{}: {error}", path.display())]
    Io { path: PathBuf, error: std::io::Error },
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error(transparent)]
    MeshFile(#[from] MeshError),
}

impl From<crate::output::Error> for VoxelError {
    fn from(e: crate::output::Error) -> VoxelError {
        VoxelError::Io { path: e.path, error: e.error }
    }
}

impl VoxelError {
    pub(crate) fn io(path: impl Into<PathBuf>, error: std::io::Error) -> VoxelError {
        VoxelError::Io { path: path.into(), error }
    }
}

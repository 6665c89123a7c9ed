//! Subdivision errors: input Catmull-Clark cannot refine the way OpenSubdiv does, and
//! failures of the OpenSubdiv helper.

use std::path::PathBuf;

use crate::mesh::MeshError;

pub type Result<T, E = SubdivError> = std::result::Result<T, E>;

#[derive(Debug, thiserror::Error)]
pub enum SubdivError {
    /// A sharp feature that does not fit the mesh (an edge that does not exist, a vertex
    /// or face out of range, a negative sharpness).
    #[error("sharp feature: {0}")]
    Feature(String),
    /// The mesh has more elements than 32-bit indices can address at the requested level.
    #[error("level {level} would be too large for 32-bit indices ({vertices} vertices)")]
    TooLarge { level: u32, vertices: u64 },
    /// The level would not fit the memory the system has available.
    #[error("level {level} needs {need_mib} MiB but only {have_mib} MiB are available; use a lower level")]
    Memory { level: u32, need_mib: crate::host::Mib, have_mib: u64 },
    /// The fragment-mesh path cannot represent this input or stream (SPEC §5.2).
    #[error("fragment mesh: {0}")]
    Fragment(String),
    /// The GPU fragment path needs more than the device offers (texture size, classes).
    #[error("GPU subdivision: {0}")]
    GpuLimit(String),
    /// A Vulkan failure (including validation errors) in the GPU fragment path.
    #[error(transparent)]
    Gpu(#[from] crate::gpu::GpuError),
    /// A refined mesh could not be assembled or a mesh file could not be read or written.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// The OpenSubdiv helper binary is missing.
    #[error("OpenSubdiv helper not found at {}: run tools/setup to build it (or set TEXGEO_OSD_REFINE)", path.display())]
    HelperMissing { path: PathBuf },
    /// The OpenSubdiv helper ran but failed or printed something unexpected.
    #[error("OpenSubdiv helper {}: {message}", path.display())]
    Helper { path: PathBuf, message: String },
    /// A temporary file or the helper process could not be created.
    #[error("{}: {error}", path.display())]
    Io { path: PathBuf, error: std::io::Error },
}

impl From<crate::output::Error> for SubdivError {
    fn from(e: crate::output::Error) -> SubdivError {
        SubdivError::Io { path: e.path, error: e.error }
    }
}

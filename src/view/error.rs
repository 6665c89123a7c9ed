pub type Result<T, E = ViewError> = std::result::Result<T, E>;

#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// No display to open a window on.
    #[error(
        "no display: {0}. The viewer needs an X server (DISPLAY); without one, write pictures with \
         `texgeo render MESH -o OUT.png` (same camera and colour options) or the figures of `texgeo reproduce`"
    )]
    NoDisplay(String),
    #[error("window: {0}")]
    Window(String),
    #[error("{0}")]
    Usage(String),
    /// GPU memory still allocated after every resource of the viewer was dropped.
    #[error("gpu-allocator reports {0} allocation(s) leaked by the viewer")]
    Leak(usize),
    /// Writing `--save-mesh` failed (the error names the file).
    #[error(transparent)]
    Mesh(#[from] crate::mesh::MeshError),
    #[error(transparent)]
    Gpu(#[from] crate::gpu::GpuError),
    #[error(transparent)]
    Render(#[from] crate::render::RenderError),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_save_names_the_file_once() {
        let io = std::io::Error::other("No space left on device");
        let e = ViewError::from(crate::mesh::MeshError::Io { path: "out/shown.obj".into(), error: io });
        assert_eq!(e.to_string(), "out/shown.obj: No space left on device");
    }
}

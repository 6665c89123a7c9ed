use std::path::PathBuf;

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
    #[error("{}: {message}", path.display())]
    Output { path: PathBuf, message: String },
    #[error(transparent)]
    Gpu(#[from] crate::gpu::GpuError),
    #[error(transparent)]
    Render(#[from] crate::render::RenderError),
}

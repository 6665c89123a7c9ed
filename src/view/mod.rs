//! `texgeo view`: an interactive window on the device the algorithms use (winit +
//! ash-window, swapchain from `gpu::Swapchain`). It shows a mesh at a live subdivision
//! level (each level change reruns the GPU fragment passes, `subdiv::gpu::Subdivider`),
//! a voxel volume (its boundary faces, optionally in Perlin aspect colours), or several
//! meshes in distinct colours with polylines (operands and results of Booleans).
//!
//! Every frame is the offscreen [`crate::render`] picture of the current camera, copied
//! onto the swapchain image: a screenshot equals `texgeo render` of the same view.
//! Presentation lives here only; the algorithms know nothing of windows.

mod app;
mod error;
mod script;

pub use crate::render::Content;
pub use app::{Options, run};
pub use error::{Result, ViewError};
pub use script::{Step, parse_script};

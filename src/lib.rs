//! texgeo: geometry algorithms of the GPGPU texture era on raw Vulkan.
//!
//! `gpu` owns every Vulkan object; `mesh` is the polygon mesh and its formats;
//! the algorithms (`inclusion`, `voxel`, `subdiv`) are short drivers on top.

pub mod boolean;
pub mod gpu;
pub mod host;
pub mod inclusion;
pub mod mesh;
pub mod random;
pub mod report;
pub mod subdiv;
pub mod voxel;

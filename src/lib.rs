//! texgeo: geometry algorithms of the GPGPU texture era on raw Vulkan.
//!
//! `gpu` owns every Vulkan object; `mesh` is the polygon mesh and its formats;
//! the algorithms (`inclusion`, `voxel`, `subdiv`) are short drivers on top; `sweep`
//! runs one of them over a whole mesh collection; `output` writes every file atomically;
//! `terminal` is how every message reaches a person.

pub mod boolean;
pub mod cache;
pub mod exact;
pub mod gpu;
pub mod host;
pub mod inclusion;
pub mod mesh;
pub mod output;
pub mod random;
pub mod render;
pub mod report;
pub mod scratch;
pub mod subdiv;
pub mod sweep;
pub mod terminal;
pub mod tetragrid;
pub mod view;
pub mod voxel;

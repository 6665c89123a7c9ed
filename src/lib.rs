//! texgeo: geometry algorithms of the GPGPU texture era on raw Vulkan.
//!
//! The modules, roughly from the bottom up, one line each:
//!
//! - [`output`]: every file written atomically (fsync on request), writability checks.
//! - [`json`]: the commands' `--json` output.
//! - [`cache`]: the user's cache folder: checked entries under blake3 keys.
//! - [`scratch`]: private temporary folders for helper processes.
//! - [`host`]: the machine texgeo runs on (memory, CPU, load).
//! - [`random`]: seeded random numbers.
//! - [`terminal`]: every message for a person.
//! - [`choice`]: `auto` or one method, the one way every algorithm's method is named.
//! - [`exact`]: exact predicates and arithmetic on f64 inputs, one sign convention.
//! - [`gpu`]: every Vulkan object: device, textures, render targets, passes, pipelines.
//! - [`mesh`]: the polygon mesh, its names and file formats, validation and solidity.
//! - [`inclusion`]: point in solid (Feito-Torres on the simplicial covering, and its peers).
//! - [`voxel`]: solid voxelization by slicing tetras with XOR.
//! - [`subdiv`]: Catmull-Clark subdivision with fragment meshes, checked against OpenSubdiv.
//! - [`boolean`]: Boolean operations on triangle-mesh solids.
//! - [`render`]: offscreen pictures of meshes.
//! - [`view`]: the interactive viewer.
//! - [`check`]: every shader and pass against its CPU reference (`texgeo check`).
//! - [`report`]: benchmarks and the reproduction report.
//! - [`sweep`]: one task over a mesh collection, in worker processes.

// Nothing a user can influence may panic through an unwrap: the library returns errors
// (tests may unwrap).
#![cfg_attr(not(test), deny(clippy::unwrap_used))]

pub mod boolean;
pub mod cache;
pub mod check;
pub mod choice;
pub mod exact;
pub mod gpu;
pub mod host;
pub mod inclusion;
pub mod json;
pub mod mesh;
pub mod output;
pub mod random;
pub mod render;
pub mod report;
pub mod scratch;
pub mod subdiv;
pub mod sweep;
pub mod terminal;
pub mod view;
pub mod voxel;

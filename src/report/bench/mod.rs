//! Benchmark suites behind `texgeo bench …` and `cargo bench`.

pub mod boolean;
pub mod inclusion;
pub mod reduce;
pub mod scale;
pub mod subdiv;
pub mod voxelize;
pub mod xor;

//! Benchmark suites behind `texgeo bench …` and `cargo bench`.

pub mod reduce;
pub mod subdiv;

//! The tasks a sweep can run, one module each (see [`super::task::Task`]).

pub mod boolean;
pub mod inclusion;
pub mod subdivide;
pub mod voxelize;

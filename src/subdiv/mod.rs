//! Catmull-Clark subdivision (2010 thesis, Ch. 3; SPEC §5): the CPU reference
//! ([`cpu`]), the half-edge queries the fragment-mesh path builds on ([`topology`]),
//! the OpenSubdiv helper as independent reference ([`osd`]) and the mesh comparison
//! both are judged with ([`compare`]).

pub mod compare;
pub mod cpu;
pub mod error;
pub mod osd;
pub mod topology;

pub use error::{Result, SubdivError};

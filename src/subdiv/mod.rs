//! Catmull-Clark subdivision (2010 thesis, Ch. 3; SPEC §5): the CPU reference
//! ([`cpu`]), the half-edge queries the fragment-mesh path builds on ([`topology`]), the
//! fragment meshes ([`fragment`]), their GPU passes ([`gpu`]) and the welding of the
//! result ([`assemble`]), the OpenSubdiv helper as independent reference ([`osd`]) and
//! the mesh comparison all are judged with ([`compare`]).

pub mod assemble;
pub mod compare;
pub mod cpu;
pub mod error;
pub mod fragment;
pub mod gpu;
pub mod osd;
pub mod topology;

pub use error::{Result, SubdivError};

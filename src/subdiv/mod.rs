//! Catmull-Clark subdivision (2010 thesis, Ch. 3; SPEC §5): the sharp features
//! and scheme options a control mesh carries ([`features`], interpreted from OBJ tags by
//! [`tags`]) and their sharpness arithmetic ([`crease`]), the CPU reference ([`cpu`]), the
//! topology (OpenSubdiv's, non-manifold included) the fragment-mesh path builds on
//! ([`topology`]), the fragment meshes ([`fragment`]), their GPU passes ([`gpu`]) and the
//! welding of the result ([`assemble`]), the OpenSubdiv helper as independent reference
//! ([`osd`]) and the mesh comparison all are judged with ([`compare`]).

pub mod assemble;
pub mod compare;
pub mod cpu;
pub mod crease;
pub mod error;
pub mod features;
pub mod fragment;
pub mod gpu;
pub mod osd;
pub mod tags;
pub mod topology;

pub use error::{Result, SubdivError};
pub use features::{Boundary, CreaseMethod, Features, Options, Surface, Triangles};

/// How a mesh is refined (`texgeo subdivide --method`, a sweep's `subdivide` task, Python's
/// `Mesh.subdivide`), named by its clap name ([`crate::choice`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Method {
    /// Base level on the CPU, then one fragment pass per level on the GPU.
    #[default]
    Gpu,
    /// The f64 CPU reference (same vertex order as OpenSubdiv).
    Cpu,
}

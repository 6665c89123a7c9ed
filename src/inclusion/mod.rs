//! Point in solid (SPEC §3, thesis Ch. 4): the exact Feito-Torres test on the simplicial
//! covering, its optimizers, and the baselines it is compared with.
//!
//! Every method answers the same question the same way, so their outputs can be compared
//! point by point:
//!
//! - **Inside** iff the winding number w of the surface around P is non-zero. For a
//!   valid solid ([`crate::mesh::solidity`]) w ∈ {0, 1} and this is the thesis'
//!   `acc == 2`. The commands refuse meshes that are not valid solids; with
//!   `--allow-open` only the `winding` method runs, and it answers w ≥ ½ for the
//!   generalized winding number of the open surface.
//! - **OnBoundary** iff P is within ε of some face polygon ([`surface::Surface::on_face`]).
//!
//! ## The tolerance rule (one rule, used everywhere)
//!
//! ε = [`surface::REL_TOL`] · D with `REL_TOL = 1e-9` and D the length of the mesh's
//! bounding-box diagonal. Distances are Euclidean, computed in f64 with unit normals:
//!
//! - *on the boundary*: distance from P to a face polygon ≤ ε. For an n-gon that means
//!   within ε of one of its edges, or of a covering triangle at a point the polygon winds
//!   around — the parts of the fan that a non-convex face's negative triangles cancel are
//!   not boundary ([`surface::Surface::on_face`]). Every method calls this one predicate
//!   for every face that may be within ε of P, so they agree on OnBoundary;
//! - *on a tetra's face* (Feito-Torres): distance from P to that face's plane ≤ ε; *on an
//!   apex edge*: on two faces through the apex; *at the apex*: on all three, or within
//!   `1e-4·D` (max-norm) of it;
//! - a tetra is *flat* when its apex is within ε of its base plane or nearly collinear with
//!   a base edge (sine < 1e-6, [`tetra::SIN_MIN`]), and *degenerate* when its base
//!   triangle's smallest height is ≤ ε;
//! - points outside the mesh's bounding box grown by ε are Outside without further work.
//!
//! "Within ε of a face" is decided **exactly** ([`crate::exact`]: a filtered f64 distance,
//! recomputed in exact arithmetic when it is within the filter's margin of ε), on the
//! covering points as they are. So every method gives a point the same OnBoundary label,
//! and a solid translated by any amount that keeps its coordinates exact (1e7, 1e12: a
//! shift by a multiple of the coordinates' unit in the last place) labels the translated
//! points as at the origin (`tests/inclusion_placement.rs`). (For an n-gon whose centroid
//! rounds differently after the translation, the covering itself moves by that rounding.)
//!
//! The other decisions are taken on coordinates relative to the apex or to a triangle's
//! corner, whose differences are exact far from the origin, and ε is far above f64
//! rounding at the scale D (≈1e-16·D): a decision taken with a margin larger than ε is
//! geometrically right; a decision within ε is either shared bit for bit by the two tetras
//! it concerns or sends the point to an exact fallback (see [`cpu`]). The Jordan baselines
//! add their own re-cast triggers (barycentric 1e-9, grazing 1e-7, [`jordan`]); they only
//! choose when to cast another ray, never a class.
//!
//! Which meshes count as solids, and what the commands do with the others, is
//! [`crate::mesh::solidity`]'s: on a valid solid the winding number is 0 or 1, so the
//! non-zero rule here, the parity of the voxelizers and "w ≥ ½" agree.

use std::fmt;
use std::str::FromStr;
use std::time::Duration;

use glam::DVec3;

use crate::mesh::Mesh;
use crate::mesh::covering::UnbalancedEdge;

pub mod bvh;
pub mod cpu;
pub mod gpu;
pub mod gpu_grid;
pub mod jordan;
pub mod octants;
pub mod octree;
pub mod points;
pub mod solver;
pub mod surface;
pub mod tetra;
pub mod tetragrid;
pub mod winding;

pub use cpu::{EdgeRule, FeitoTorres, Trace};
pub use surface::Surface;

/// Where a point lies relative to a solid. The numbers are what the CLI writes.
#[repr(u8)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Class {
    #[default]
    Outside = 0,
    Inside = 1,
    OnBoundary = 2,
}

#[derive(Debug, thiserror::Error)]
pub enum InclusionError {
    /// The covering methods need a closed, consistently oriented boundary (SPEC §1).
    #[error(
        "the mesh is not closed and consistently oriented: edge {a}–{b} is used {forward} time(s) as {a}→{b} \
         but {backward} time(s) as {b}→{a}"
    )]
    NotClosed { a: u32, b: u32, forward: u32, backward: u32 },
    #[error("unknown inclusion method '{0}' (expected one of: {list})", list = Method::names().join(", "))]
    UnknownMethod(String),
    #[error("tetragrid resolution {0} is outside 2..=64")]
    Resolution(usize),
    #[error("octree depth {0} is outside 1..=10")]
    OctreeDepth(u32),
    #[error("GPU: {0}")]
    Gpu(crate::gpu::GpuError),
    #[error("too large for the GPU path: {0}")]
    TooLarge(String),
    #[error("invalid options: {0}")]
    Options(String),
    #[error("method '{0}' runs on the GPU: build it with inclusion::solver::Solver")]
    NeedsGpu(Method),
}

impl From<crate::gpu::GpuError> for InclusionError {
    fn from(e: crate::gpu::GpuError) -> InclusionError {
        InclusionError::Gpu(e)
    }
}

impl From<UnbalancedEdge> for InclusionError {
    fn from(e: UnbalancedEdge) -> InclusionError {
        InclusionError::NotClosed { a: e.a, b: e.b, forward: e.forward, backward: e.backward }
    }
}

pub type Result<T, E = InclusionError> = std::result::Result<T, E>;

/// Preprocessing cost of a classifier (Tables 4-4, 4-7, 4-8): wall time to build it and
/// the heap bytes it holds (covering, per-tetra data and any index).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BuildStats {
    pub build_time: Duration,
    pub bytes: usize,
}

/// A point-in-solid test built for one mesh.
pub trait Classifier: Send + Sync {
    /// The method's name as the CLI spells it.
    fn name(&self) -> &str;
    fn classify(&self, p: DVec3) -> Class;
    fn classify_all(&self, ps: &[DVec3]) -> Vec<Class> {
        ps.iter().map(|&p| self.classify(p)).collect()
    }
    fn build_stats(&self) -> BuildStats;
}

/// The inclusion methods. GPU methods are added next to these; [`Method::is_cpu`] says
/// which ones [`build`] can make.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// Alg. 4-1 with basic preprocessing, every tetra tested.
    Cpu,
    /// Alg. 4-1 over a bounding-box hierarchy of the tetras (§4.3.2.2).
    Bvh,
    /// Alg. 4-1 over the tetras of the point's octant (§4.3.2.3).
    Octants,
    /// Alg. 4-1 over the tetras of the point's grid cell (§4.3.2.4).
    TetraGrid,
    /// Ray crossings over every covering triangle (§4.2.2).
    Jordan,
    /// Ray crossings over the triangles of the octree leaves the ray passes (§4.2.2).
    JordanOctree,
    /// Generalized winding number: the independent oracle.
    Winding,
    /// Alg. 4-2 + 4-3 on the GPU: phase 1 draws, 2×2 reduction passes (§4.3.3).
    Gpu,
    /// Phase 1 on the GPU, phase 2 summed on the host (the thesis' CPU+GPU).
    CpuGpu,
    /// The GPU method over TetraGrid cells: each cell's points against its tetras.
    GpuTetraGrid,
}

impl Method {
    pub const ALL: [Method; 10] = [
        Method::Cpu,
        Method::Bvh,
        Method::Octants,
        Method::TetraGrid,
        Method::Jordan,
        Method::JordanOctree,
        Method::Winding,
        Method::Gpu,
        Method::CpuGpu,
        Method::GpuTetraGrid,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Method::Cpu => "cpu",
            Method::Bvh => "bvh",
            Method::Octants => "octants",
            Method::TetraGrid => "tetragrid",
            Method::Jordan => "jordan",
            Method::JordanOctree => "jordan-octree",
            Method::Winding => "winding",
            Method::Gpu => "gpu",
            Method::CpuGpu => "cpu+gpu",
            Method::GpuTetraGrid => "gpu+tetragrid",
        }
    }

    pub fn names() -> Vec<&'static str> {
        Method::ALL.iter().map(|m| m.name()).collect()
    }

    /// True for methods that run on the CPU alone ([`build`] makes them; the GPU ones
    /// are made by [`solver::Solver::new`]).
    pub fn is_cpu(self) -> bool {
        !matches!(self, Method::Gpu | Method::CpuGpu | Method::GpuTetraGrid)
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Method {
    type Err = InclusionError;
    fn from_str(s: &str) -> Result<Method> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| InclusionError::UnknownMethod(s.to_string()))
    }
}

/// Knobs shared by the builders; `Default` gives the thesis' settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Feito-Torres apex; `None` = [`cpu::default_apex`] (near the bounding-box centre).
    pub apex: Option<DVec3>,
    /// TetraGrid resolution n (n³ cells), 2..=64.
    pub tetragrid_resolution: usize,
    /// Jordan octree depth (the thesis' "Octree-6").
    pub octree_depth: u32,
    /// Accept a surface that is not closed and consistently oriented (answers are then
    /// those of the covering's generalized winding number, not of a solid).
    pub allow_open: bool,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            apex: None,
            tetragrid_resolution: tetragrid::DEFAULT_RESOLUTION,
            octree_depth: 6,
            allow_open: false,
        }
    }
}

/// Builds the CPU classifier `method` for `mesh`.
pub fn build(method: Method, mesh: &Mesh, options: &Options) -> Result<Box<dyn Classifier>> {
    let ft = || FeitoTorres::with_policy(mesh, options.apex, EdgeRule::Rerun, options.allow_open);
    Ok(match method {
        Method::Cpu => Box::new(ft()?),
        Method::Bvh => Box::new(bvh::Bvh::new(ft()?)),
        Method::Octants => Box::new(octants::Octants::new(ft()?)),
        Method::TetraGrid => Box::new(tetragrid::TetraGrid::new(ft()?, options.tetragrid_resolution)?),
        Method::Jordan => Box::new(jordan::Jordan::with_policy(mesh, options.allow_open)?),
        Method::JordanOctree => {
            Box::new(octree::JordanOctree::with_policy(mesh, options.octree_depth, options.allow_open)?)
        }
        Method::Winding => Box::new(winding::WindingNumber::with_policy(mesh, options.allow_open)?),
        Method::Gpu | Method::CpuGpu | Method::GpuTetraGrid => return Err(InclusionError::NeedsGpu(method)),
    })
}

/// Heap bytes of a vector's buffer.
pub(crate) fn vec_bytes<T>(v: &Vec<T>) -> usize {
    v.capacity() * std::mem::size_of::<T>()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn method_names_round_trip() {
        for m in Method::ALL {
            assert_eq!(m.name().parse::<Method>().unwrap(), m);
        }
        let e = "gpu+magic".parse::<Method>().unwrap_err().to_string();
        assert!(e.contains("gpu+magic") && e.contains("jordan-octree"), "{e}");
        assert_eq!(Class::OnBoundary as u8, 2);
    }
}

//! The inclusion methods and their options, as the command line names them.

use std::fmt;

use glam::DVec3;

/// The inclusion methods (`--method`, with `auto`: [`Choice`]). [`super::solver::Solver::new`]
/// builds any of them; [`Method::is_cpu`] says which ones [`super::solver::build`] can make
/// without a device. A new method is one variant here and one arm in the factory.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Method {
    /// Alg. 4-1 with basic preprocessing, every tetra tested.
    Cpu,
    /// Alg. 4-1 over a bounding-box hierarchy of the tetras (§4.3.2.2).
    Bvh,
    /// Alg. 4-1 over the tetras of the point's octant (§4.3.2.3).
    Octants,
    /// Alg. 4-1 over the tetras of the point's grid cell (§4.3.2.4).
    #[value(name = "tetragrid")]
    TetraGrid,
    /// Ray crossings over every covering triangle (§4.2.2).
    Jordan,
    /// Ray crossings over the triangles of the octree leaves the ray passes (§4.2.2).
    #[value(name = "jordan-octree")]
    JordanOctree,
    /// Generalized winding number: the independent oracle.
    Winding,
    /// Alg. 4-2 + 4-3 on the GPU: phase 1 draws, 2×2 reduction passes (§4.3.3).
    Gpu,
    /// Phase 1 on the GPU, phase 2 summed on the host (the thesis' CPU+GPU).
    #[value(name = "cpu+gpu")]
    CpuGpu,
    /// The GPU method over TetraGrid cells: each cell's points against its tetras.
    #[value(name = "gpu+tetragrid")]
    GpuTetraGrid,
    /// Voxel space (§4.2.1.1, exact): cells labelled inside/outside once, points in
    /// surface cells tested exactly on their cell's triangles.
    #[value(name = "voxel-space")]
    VoxelSpace,
}

/// `--method`: one method, or `auto`, which the factory replaces by the one [`super::auto`]
/// picks.
pub type Choice = crate::choice::Choice<Method>;

/// What `--help` says of `auto`.
pub const AUTO: &str = "The fastest exact method for the mesh, the number of points and the device, from \
                        measured cost models (says which on stderr)";

impl Method {
    /// Every method.
    pub const ALL: [Method; 11] = [
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
        Method::VoxelSpace,
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
            Method::VoxelSpace => "voxel-space",
        }
    }

    /// True for methods that run on the CPU alone (`auto` only picks those).
    pub fn is_cpu(self) -> bool {
        !matches!(self, Method::Gpu | Method::CpuGpu | Method::GpuTetraGrid)
    }
}

impl Choice {
    /// True unless a GPU method is asked for (`auto` picks CPU methods only).
    pub fn is_cpu(self) -> bool {
        self.fixed().is_none_or(Method::is_cpu)
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Knobs shared by the builders; `Default` gives the thesis' settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Feito-Torres apex; `None` = [`super::cpu::default_apex`] (near the bounding-box centre).
    pub apex: Option<DVec3>,
    /// TetraGrid resolution n (n³ cells), 2..=64.
    pub tetragrid_resolution: usize,
    /// Voxel-space resolution n; `None` = from the mesh and [`Self::points`].
    pub voxel_space_resolution: Option<usize>,
    /// How many points will be classified (0 = unknown): `auto` and the voxel space size
    /// themselves by it.
    pub points: usize,
    /// Jordan octree depth (the thesis' "Octree-6").
    pub octree_depth: u32,
    /// Accept a mesh that is not a solid (`--allow-open`): it is classified by its
    /// generalized winding number (inside iff w ≥ ½) whichever CPU method is asked for; the
    /// GPU methods refuse it.
    pub allow_open: bool,
    /// The caller found the mesh not to be a solid ([`crate::mesh::solidity::check`]: a
    /// closed mesh may still self-intersect, nest or be inverted); under `allow_open` the
    /// winding-number rule then applies even though the surface is closed.
    pub non_solid: bool,
    /// The caller has already found the surface closed and consistently oriented (the
    /// command line's [`crate::mesh::solidity::require_solid`], whose verdicts are cached),
    /// so it is not checked again (the default method's closure check and the exact tests').
    pub known_closed: bool,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            apex: None,
            tetragrid_resolution: super::tetragrid::DEFAULT_RESOLUTION,
            voxel_space_resolution: None,
            points: 0,
            octree_depth: 6,
            allow_open: false,
            non_solid: false,
            known_closed: false,
        }
    }
}

#[cfg(test)]
mod tests {
    use clap::ValueEnum;

    use super::*;
    use crate::inclusion::Class;

    #[test]
    fn method_names_round_trip() {
        for m in Method::ALL {
            assert_eq!(m.to_possible_value().unwrap().get_name(), m.name());
        }
        assert_eq!(Method::value_variants(), Method::ALL);
        assert_eq!(crate::choice::parse::<Method>("auto"), None);
        assert_eq!("auto".parse::<Choice>(), Ok(Choice::Auto));
        assert_eq!("cpu+gpu".parse::<Choice>(), Ok(Choice::Fixed(Method::CpuGpu)));
        assert_eq!(Class::OnBoundary as u8, 2);
    }
}

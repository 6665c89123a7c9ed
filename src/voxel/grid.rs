//! The voxel grid (SPEC §4.1): N×N×N voxels over the bounding cube of the
//! solid. The cube's side s is the largest extent of the mesh's bounding box, centred on
//! the box's centre; h = s/N; voxel (i, j, k) has its centre at
//! `min + ((i+½)h, (j+½)h, (k+½)h)`, i along x, j along y (the slicing axis), k along z.
//!
//! Every exact decision in `voxel` is about that centre as computed by [`Grid::centre`]
//! (one f64 rounding per coordinate). The rasterizers work in *grid units*
//! (u = (p − min)/h, voxel centres at i + ½), see [`Grid::to_grid`].

use glam::DVec3;

use super::error::{Result, VoxelError};
use crate::mesh::Mesh;
use crate::mesh::frame::Frame;

/// Largest resolution texgeo voxelizes.
pub const MAX_RES: usize = 1024;

/// N×N×N voxels over a cube.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// Voxels along each axis.
    pub n: usize,
    /// The cube's minimum corner (binvox `translate`).
    pub min: DVec3,
    /// The cube's side (binvox `scale`).
    pub side: f64,
    /// The frame `min` and `side` are in (the mesh's, [`crate::mesh::frame`]); binvox
    /// headers give them back in the input's units.
    pub frame: Frame,
}

impl Grid {
    /// The grid over the bounding cube of `mesh`. A mesh without faces (an empty solid)
    /// gets the unit cube at its lowest corner: every cube holds none of it.
    pub fn for_mesh(mesh: &Mesh, n: usize) -> Result<Grid> {
        check_resolution(n)?;
        let (lo, hi) = mesh.bounds();
        if mesh.num_faces() == 0 {
            return Ok(Grid { n, min: lo, side: 1.0, frame: Frame::IDENTITY });
        }
        let side = (hi - lo).max_element();
        if side.is_nan() || side <= 0.0 || !side.is_finite() {
            return Err(VoxelError::Mesh(format!("its bounding box {lo} .. {hi} has no extent")));
        }
        let min = (lo + hi) * 0.5 - DVec3::splat(side * 0.5);
        Ok(Grid { n, min, side, frame: Frame::IDENTITY })
    }

    /// A grid with an explicit cube (e.g. from a binvox header).
    pub fn new(n: usize, min: DVec3, side: f64) -> Result<Grid> {
        check_resolution(n)?;
        if side.is_nan() || side <= 0.0 || !side.is_finite() || !min.is_finite() {
            return Err(VoxelError::Usage(format!("bad grid cube: min {min}, side {side}")));
        }
        Ok(Grid { n, min, side, frame: Frame::IDENTITY })
    }

    /// This grid, its cube being in `frame` (that of the mesh it was made for).
    pub fn in_frame(self, frame: Frame) -> Grid {
        Grid { frame, ..self }
    }

    /// The cube's minimum corner and side in the input's units (the binvox header).
    pub fn cube_out(&self) -> (DVec3, f64) {
        (self.frame.point_out(self.min), self.frame.length_out(self.side))
    }

    /// Voxel size h = s/N.
    pub fn h(&self) -> f64 {
        self.side / self.n as f64
    }

    /// Centre coordinate of voxel index `i` along the axis whose cube minimum is `min`:
    /// `min + (i + ½)·h`, the one formula every exact test uses.
    pub fn centre_coord(&self, min: f64, i: usize) -> f64 {
        min + (i as f64 + 0.5) * self.h()
    }

    /// The centre of voxel (i, j, k) in world coordinates.
    pub fn centre(&self, i: usize, j: usize, k: usize) -> DVec3 {
        DVec3::new(
            self.centre_coord(self.min.x, i),
            self.centre_coord(self.min.y, j),
            self.centre_coord(self.min.z, k),
        )
    }

    /// World → grid units: the cube becomes [0, N]³ and voxel centres sit at i + ½.
    pub fn to_grid(&self, p: DVec3) -> DVec3 {
        (p - self.min) / self.h()
    }

    /// Number of voxels, N³.
    pub fn voxels(&self) -> u64 {
        (self.n as u64).pow(3)
    }
}

/// Checks 1 ≤ N ≤ [`MAX_RES`].
pub fn check_resolution(n: usize) -> Result<()> {
    if n == 0 || n > MAX_RES {
        return Err(VoxelError::Resolution {
            res: n,
            max: MAX_RES,
            why: if n > MAX_RES {
                // n³ / 8 bytes, saturated: n can be as large as usize::MAX.
                let bytes = (n as u128).saturating_mul(n as u128).saturating_mul(n as u128) / 8;
                format!(" (a {n}³ bit volume alone would take {} MiB)", crate::host::Mib::of_wide(bytes))
            } else {
                String::new()
            },
        });
    }
    Ok(())
}

/// Fails with a clear error, before anything is allocated, when `bytes` for `what` at
/// resolution `n` exceed the available memory.
pub fn check_memory(what: &str, n: usize, bytes: u64) -> Result<()> {
    crate::host::check_available(bytes).map_err(|(need_mib, have_mib)| VoxelError::Memory {
        what: what.to_string(),
        res: n,
        need_mib,
        have_mib,
    })
}

//! CPU voxelization (§5.3.2, SPEC §4.3 "CPU"): every tetra of the covering is sliced
//! (Table 5-1) and each cross-section is scanline-rasterized with XOR into the bit
//! volume; then the centres within τ of the surface get their exact value (`band`).

use super::band::{self, BandReport};
use super::error::Result;
use super::grid::Grid;
use super::raster::xor_triangle;
use super::slicing::{section, slice_range};
use super::solid::Solid;
use super::volume::Volume;

/// Slices and rasterizes every tetra; returns the raw parity volume (before the fallback).
pub fn rasterize(solid: &Solid, grid: &Grid) -> Result<Volume> {
    let mut volume = Volume::new(grid.n)?;
    for t in solid.sorted_tetras(grid) {
        for j in slice_range(&t, grid.n) {
            if let Some(sec) = section(&t, j as f64 + 0.5) {
                for tri in sec.triangles() {
                    xor_triangle(&mut volume, j, tri);
                }
            }
        }
    }
    Ok(volume)
}

/// The CPU method: rasterize, then fix the centres near the surface exactly.
pub fn voxelize(solid: &Solid, grid: &Grid) -> Result<(Volume, BandReport)> {
    let mut volume = rasterize(solid, grid)?;
    let report = band::fix(&mut volume, solid, grid, band::tolerance_f64(grid.n))?;
    Ok((volume, report))
}

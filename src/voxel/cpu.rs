//! CPU voxelization (§5.3.2, SPEC §4.3 "CPU"): every tetra of the covering is sliced
//! (Table 5-1) and each cross-section is scanline-rasterized with XOR into the bit
//! volume; then the centres within τ of the surface get their exact value (`band`).

use super::band::{self, BandReport};
use super::error::Result;
use super::grid::Grid;
use super::raster::triangle_spans;
use super::slicing::{section, slice_range};
use super::solid::Solid;
use super::volume::{Volume, slab_height, slab_lists};

/// Slices and rasterizes every tetra; returns the raw parity volume (before the fallback).
pub fn rasterize(solid: &Solid, grid: &Grid) -> Result<Volume> {
    let n = grid.n;
    let mut volume = Volume::new(n)?;
    let tetras = solid.sorted_tetras(grid);
    // Slabs of slices in parallel, each from the tetras that reach it: XOR commutes, so
    // the volume is the same whatever the number of threads.
    let slab = slab_height(n);
    let lists = slab_lists(n, slab, tetras.iter().map(|t| slice_range(t, n)));
    volume.par_slabs(slab, |mut s| {
        let slices = s.slices();
        for &t in &lists[s.j0 / slab] {
            let t = &tetras[t as usize];
            let r = slice_range(t, n);
            for j in r.start.max(slices.start)..r.end.min(slices.end) {
                if let Some(sec) = section(t, j as f64 + 0.5) {
                    for tri in sec.triangles() {
                        triangle_spans(tri, n, |k, a, b| s.xor_span(j, k, a, b));
                    }
                }
            }
        }
    });
    Ok(volume)
}

pub fn voxelize(solid: &Solid, grid: &Grid) -> Result<(Volume, BandReport)> {
    let mut volume = rasterize(solid, grid)?;
    let report = band::fix(&mut volume, solid, grid, band::tolerance_f64(grid.n))?;
    Ok((volume, report))
}

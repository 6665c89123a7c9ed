//! Volumes as NumPy `.npy` files: an (N, N, N) bool array indexed `[x, y, z]` (C order,
//! one byte per voxel), with the grid in a JSON file beside it (same stem, `.json`):
//! `{"resolution": N, "origin": [x, y, z], "pitch": h, "side": s}` — voxel (i, j, k)'s
//! centre is `origin + (i + ½, j + ½, k + ½) · pitch`. NumPy's reader refuses extra keys in
//! the `.npy` header, hence the second file.

use std::io::Write;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::error::{Result, VoxelError};
use super::grid::Grid;
use super::volume::Volume;

/// The grid file of the volume at `path`: the same name with the extension `.json`.
pub fn sidecar(path: &Path) -> PathBuf {
    path.with_extension("json")
}

/// The grid as the sidecar holds it.
pub fn grid_json(grid: &Grid) -> serde_json::Value {
    let (origin, side) = grid.cube_out();
    serde_json::json!({
        "resolution": grid.n,
        "origin": origin.to_array(),
        "pitch": side / grid.n as f64,
        "side": side,
    })
}

/// The voxels of x-plane `i` in `[y, z]` order, one byte (0 or 1) each.
fn plane(volume: &Volume, i: usize) -> Vec<u8> {
    let n = volume.n();
    let mut out = vec![0u8; n * n];
    for (j, row) in out.chunks_mut(n).enumerate() {
        for (k, v) in row.iter_mut().enumerate() {
            *v = u8::from(volume.get(i, j, k));
        }
    }
    out
}

/// Every voxel in `[x, y, z]` order, one byte (0 or 1) each: the `.npy` file's data
/// (Python's `Voxels.occupied`).
pub fn bytes_xyz(volume: &Volume) -> Vec<u8> {
    let n = volume.n();
    let planes: Vec<Vec<u8>> = (0..n).into_par_iter().map(|i| plane(volume, i)).collect();
    planes.concat()
}

/// Streams the `.npy` encoding of `volume` to `out`, a few x planes at a time.
pub fn write_to(out: &mut impl Write, volume: &Volume) -> std::io::Result<()> {
    let n = volume.n();
    crate::inclusion::points::write_npy_header(out, "|b1", &format!("({n}, {n}, {n})"))?;
    let xs: Vec<usize> = (0..n).collect();
    for group in xs.chunks(rayon::current_num_threads().max(1)) {
        let planes: Vec<Vec<u8>> = group.par_iter().map(|&i| plane(volume, i)).collect();
        for p in &planes {
            out.write_all(p)?;
        }
    }
    out.flush()
}

/// Writes `volume` to `path` (`.npy`) and its grid beside it ([`sidecar`]), each
/// atomically.
pub fn write(path: impl AsRef<Path>, grid: &Grid, volume: &Volume) -> Result<()> {
    let path = path.as_ref();
    if grid.n != volume.n() {
        return Err(VoxelError::Usage(format!("a {}³ grid with a {}³ volume", grid.n, volume.n())));
    }
    crate::output::write_with(path, |w| write_to(w, volume))?;
    let text = serde_json::to_string_pretty(&grid_json(grid)).map_err(std::io::Error::other);
    crate::output::write_with(sidecar(path), |w| {
        w.write_all(text?.as_bytes())?;
        w.write_all(b"\n")
    })?;
    Ok(())
}

/// Writes `volume` as its path's extension says: `.npy` (with its grid file) or binvox.
pub fn write_by_extension(path: impl AsRef<Path>, grid: &Grid, volume: &Volume) -> Result<()> {
    let path = path.as_ref();
    if is_npy(path) { write(path, grid, volume) } else { super::binvox::write(path, grid, volume) }
}

/// Whether `path` names a `.npy` file.
pub fn is_npy(path: &Path) -> bool {
    crate::inclusion::points::is_npy(path)
}

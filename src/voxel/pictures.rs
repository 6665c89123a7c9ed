//! PNG slice stacks (SPEC §4.1): one picture per y slice, x to the right and z down
//! (texel (i, k) of the slice, as the GPU renders it).

use std::path::{Path, PathBuf};

use super::error::{Result, VoxelError};
use super::volume::Volume;

/// File name of slice j in a stack of n slices: `slice_0007.png`.
pub fn slice_name(j: usize, n: usize) -> String {
    let digits = n.saturating_sub(1).max(1).to_string().len().max(4);
    format!("slice_{j:0digits$}.png")
}

/// Writes one grey PNG per slice (white = occupied) into `dir`.
pub fn write_slices(volume: &Volume, dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|e| VoxelError::io(dir, e))?;
    let n = volume.n();
    (0..n)
        .map(|j| {
            let path = dir.join(slice_name(j, n));
            let image = image::GrayImage::from_raw(n as u32, n as u32, volume.slice_pixels(j))
                .ok_or_else(|| VoxelError::Usage("slice image size".into()))?;
            image.save(&path).map_err(|e| VoxelError::io(&path, std::io::Error::other(e)))?;
            Ok(path)
        })
        .collect()
}

/// Writes RGBA slices (`pixels[j]` is slice j, n×n RGBA8) into `dir`.
pub fn write_rgba_slices(n: usize, slices: &[Vec<u8>], dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|e| VoxelError::io(dir, e))?;
    slices
        .iter()
        .enumerate()
        .map(|(j, pixels)| {
            let path = dir.join(slice_name(j, n));
            let image = image::RgbaImage::from_raw(n as u32, n as u32, pixels.clone())
                .ok_or_else(|| VoxelError::Usage("slice image size".into()))?;
            image.save(&path).map_err(|e| VoxelError::io(&path, std::io::Error::other(e)))?;
            Ok(path)
        })
        .collect()
}

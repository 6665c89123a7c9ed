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
    crate::output::check_dir(dir)?;
    let n = volume.n();
    (0..n)
        .map(|j| {
            let path = dir.join(slice_name(j, n));
            let image = image::GrayImage::from_raw(n as u32, n as u32, volume.slice_pixels(j))
                .ok_or_else(|| VoxelError::Usage("slice image size".into()))?;
            crate::output::write_png(&path, &image)?;
            Ok(path)
        })
        .collect()
}

/// Writes RGBA slice j (n×n RGBA8) into `dir` under its stack name.
pub fn write_rgba_slice(n: usize, j: usize, pixels: &[u8], dir: &Path) -> Result<PathBuf> {
    let path = dir.join(slice_name(j, n));
    let image = image::RgbaImage::from_raw(n as u32, n as u32, pixels.to_vec())
        .ok_or_else(|| VoxelError::Usage("slice image size".into()))?;
    crate::output::write_png(&path, &image)?;
    Ok(path)
}

/// Writes RGBA slices (`slices[j]` is slice j, n×n RGBA8) into `dir`.
pub fn write_rgba_slices(n: usize, slices: &[Vec<u8>], dir: &Path) -> Result<Vec<PathBuf>> {
    crate::output::check_dir(dir)?;
    slices.iter().enumerate().map(|(j, pixels)| write_rgba_slice(n, j, pixels, dir)).collect()
}

/// A rendered picture of the volume (SPEC §4.1): the solid seen from −z, each pixel the
/// first occupied voxel along +z, shaded by depth; coloured by `aspect` slices (as from
/// `aspect::render`) when given, grey otherwise. y points up.
pub fn render_front(volume: &Volume, aspect: Option<&[Vec<u8>]>) -> image::RgbaImage {
    let n = volume.n();
    let mut img = front_canvas(n);
    for j in 0..n {
        front_row(volume, j, aspect.and_then(|a| a.get(j)).map(Vec::as_slice), &mut img);
    }
    img
}

/// An empty picture for [`front_row`].
pub fn front_canvas(n: usize) -> image::RgbaImage {
    image::RgbaImage::from_pixel(n as u32, n as u32, image::Rgba([24, 26, 32, 255]))
}

/// Draws row j of the front view (see [`render_front`]) from slice j and its aspect
/// colours, so the picture can be built while slices stream by.
pub fn front_row(volume: &Volume, j: usize, aspect: Option<&[u8]>, img: &mut image::RgbaImage) {
    let n = volume.n();
    for i in 0..n {
        let Some(k) = (0..n).find(|&k| volume.get(i, j, k)) else { continue };
        let shade = 1.0 - 0.65 * k as f32 / n as f32;
        let base = match aspect {
            Some(s) if s.len() >= n * n * 4 => {
                let o = (k * n + i) * 4;
                [s[o], s[o + 1], s[o + 2]]
            }
            _ => [210, 210, 210],
        };
        let c = base.map(|v| (v as f32 * shade) as u8);
        img.put_pixel(i as u32, (n - 1 - j) as u32, image::Rgba([c[0], c[1], c[2], 255]));
    }
}

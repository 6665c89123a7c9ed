//! A rendered picture: RGBA8 pixels, top row first, and its PNG file.

use std::path::Path;

use super::colour::Rgba;
use super::error::{RenderError, Result};

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Picture {
    pub width: u32,
    pub height: u32,
    /// `width × height` RGBA8 pixels, row by row from the top.
    pub rgba: Vec<u8>,
}

impl Picture {
    pub fn new(width: u32, height: u32, rgba: Vec<u8>) -> Result<Picture> {
        if rgba.len() as u64 != u64::from(width) * u64::from(height) * 4 {
            return Err(RenderError::Usage(format!(
                "{} bytes for a {width}×{height} RGBA8 picture",
                rgba.len()
            )));
        }
        Ok(Picture { width, height, rgba })
    }

    /// The pixel in column `x`, row `y` (from the top).
    pub fn pixel(&self, x: u32, y: u32) -> Rgba {
        let o = ((y as usize) * self.width as usize + x as usize) * 4;
        [self.rgba[o], self.rgba[o + 1], self.rgba[o + 2], self.rgba[o + 3]]
    }

    /// Pixels where some channel differs by more than `tolerance` from `other`'s
    /// (`None` if the sizes differ).
    pub fn pixels_differing(&self, other: &Picture, tolerance: u8) -> Option<usize> {
        if (self.width, self.height) != (other.width, other.height) {
            return None;
        }
        Some(
            self.rgba
                .chunks_exact(4)
                .zip(other.rgba.chunks_exact(4))
                .filter(|(a, b)| a.iter().zip(b.iter()).any(|(x, y)| x.abs_diff(*y) > tolerance))
                .count(),
        )
    }

    /// The largest difference of any channel of any pixel (`None` if the sizes differ).
    pub fn max_difference(&self, other: &Picture) -> Option<u8> {
        if (self.width, self.height) != (other.width, other.height) {
            return None;
        }
        Some(self.rgba.iter().zip(&other.rgba).map(|(a, b)| a.abs_diff(*b)).max().unwrap_or(0))
    }

    /// Writes the picture as a PNG atomically ([`crate::output`]): `path` never holds
    /// half a picture.
    pub fn save_png(&self, path: impl AsRef<Path>) -> Result<()> {
        let image = image::RgbaImage::from_raw(self.width, self.height, self.rgba.clone())
            .ok_or_else(|| RenderError::Usage("picture size".into()))?;
        crate::output::write_png(path, &image).map_err(|e| RenderError::Io { path: e.path, source: e.error })
    }

    /// Reads a PNG (any colour type) as RGBA8.
    pub fn load_png(path: impl AsRef<Path>) -> Result<Picture> {
        let path = path.as_ref();
        let image = image::open(path)
            .map_err(|e| RenderError::Io { path: path.to_path_buf(), source: std::io::Error::other(e) })?
            .to_rgba8();
        let (w, h) = image.dimensions();
        Picture::new(w, h, image.into_raw())
    }
}

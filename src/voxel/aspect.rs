//! The aspect function (Alg. 5-1 step 3, §5.3.4, Fig. 5-9): after the presence buffer is
//! complete, a fragment shader gives every occupied voxel the colour of a material
//! defined by 3D Perlin noise at its centre. One full-target pass per slice reads the
//! packed presence layers and a permutation texture and writes an RGBA8 layer.

use super::error::{Result, VoxelError};
use super::grid::check_memory;
use super::layers::SLICES_PER_LAYER;
use super::volume::Volume;
use crate::gpu::{Attachment, Blend, Context, Load, Pipeline, TexFormat, Texture, shaders};
use crate::random::Rng;

/// The materials of the noise palette (`--material`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Material {
    Marble,
    Wood,
    Granite,
}

impl Material {
    pub const ALL: [Material; 3] = [Material::Marble, Material::Wood, Material::Granite];

    pub fn name(self) -> &'static str {
        match self {
            Material::Marble => "marble",
            Material::Wood => "wood",
            Material::Granite => "granite",
        }
    }

    pub fn parse(s: &str) -> Option<Material> {
        Material::ALL.into_iter().find(|m| m.name() == s)
    }
}

/// Parameters of the Perlin aspect function.
#[derive(Clone, Copy, Debug)]
pub struct Aspect {
    pub material: Material,
    /// Noise periods across the grid.
    pub frequency: f32,
    /// Seed of the permutation table.
    pub seed: u64,
}

impl Default for Aspect {
    fn default() -> Aspect {
        Aspect { material: Material::Marble, frequency: 4.0, seed: 2006 }
    }
}

/// Bytes of RGBA8 slices rendered per submission, at most.
const GROUP_BYTES: u64 = 64 << 20;

/// Colours `volume` with `aspect`: one N×N RGBA8 image per slice (x right, z down).
pub fn render(ctx: &Context, volume: &Volume, aspect: &Aspect) -> Result<Vec<Vec<u8>>> {
    check_memory("the aspect slices", volume.n(), (volume.n() as u64).pow(3) * 4)?;
    let mut slices = Vec::with_capacity(volume.n());
    render_each(ctx, volume, aspect, |_, pixels| {
        slices.push(pixels.to_vec());
        Ok(())
    })?;
    Ok(slices)
}

/// Like [`render`], but hands each slice j to `sink(j, pixels)` as soon as its group is
/// read back, so only a group of slices is ever in memory.
pub fn render_each(
    ctx: &Context,
    volume: &Volume,
    aspect: &Aspect,
    mut sink: impl FnMut(usize, &[u8]) -> Result<()>,
) -> Result<()> {
    let n = volume.n();
    let side = n as u32;
    if side > ctx.info().max_image_2d {
        return Err(VoxelError::Resolution {
            res: n,
            max: ctx.info().max_image_2d as usize,
            why: " for the aspect pass on this device".into(),
        });
    }
    let slice_bytes = (n * n * 4) as u64;
    check_memory("the aspect pass", n, 2 * GROUP_BYTES.min(slice_bytes * n as u64))?;
    let layers = n.div_ceil(SLICES_PER_LAYER);
    let occupancy =
        Texture::new_layered(ctx, TexFormat::R32Ui, side, side, layers as u32, "presence layers")?;
    let mut rng = Rng::new(aspect.seed);
    let mut table: Vec<u32> = (0..256).collect();
    for i in (1..256).rev() {
        table.swap(i, rng.below(i as u64 + 1) as usize);
    }
    let perm = Texture::new(ctx, TexFormat::R32Ui, 256, 1, "permutation")?;
    let pipeline = Pipeline::quad(ctx, &shaders::voxel::ASPECT_FRAG, &[TexFormat::Rgba8], Blend::Replace)?;
    ctx.submit(|rec| {
        for l in 0..layers {
            rec.upload(&occupancy, l as u32, &volume.packed_layer(l))?;
        }
        rec.upload(&perm, 0, &table)
    })?;
    let group = ((GROUP_BYTES / slice_bytes) as usize).clamp(1, n).min(ctx.info().max_array_layers as usize);
    let target = Texture::new_layered(ctx, TexFormat::Rgba8, side, side, group as u32, "aspect slices")?;
    let material = Material::ALL.iter().position(|&m| m == aspect.material).unwrap_or(0) as u32;
    for first in (0..n).step_by(group) {
        let count = group.min(n - first);
        let reads = [&occupancy, &perm];
        let buffer = ctx.submit(|rec| {
            for j in first..first + count {
                let out = [Attachment::layer(&target, (j - first) as u32, Load::Discard)];
                rec.render(&out, None, &reads, |pass| {
                    pass.bind(&pipeline)?;
                    pass.textures(&[(0, &occupancy), (1, &perm)])?;
                    pass.push(&[j as u32, side, material, aspect.frequency.to_bits()])?;
                    pass.quad()
                })?;
            }
            rec.readback_region(&target, 0..count as u32, [0, 0, side, side])
        })?;
        let bytes = buffer.bytes()?;
        for (j, pixels) in bytes.chunks_exact(slice_bytes as usize).enumerate() {
            sink(first + j, pixels)?;
        }
    }
    Ok(())
}

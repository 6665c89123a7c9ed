//! Scatter: the point-list pass in its plainest form — one point per datum, each written
//! to its own texel of an RGBA32F target (texel `i` is `(i % width, i / width)`). With
//! additive blending, data landing on the same texel are summed.

use super::context::Context;
use super::error::{GpuError, Result};
use super::memory::{Buffer, Pod};
use super::pass::{Attachment, Load};
use super::pipeline::{Blend, Pipeline, PipelineDesc, Topology};
use super::shaders;
use super::texture::{TexFormat, Texture};

/// One datum: its texel index and value (the layout of `scatter.vert`'s inputs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Datum {
    pub texel: u32,
    pub value: [f32; 4],
}

// SAFETY: #[repr(C)] u32 followed by four f32: no padding, every bit pattern valid.
unsafe impl Pod for Datum {}

pub struct Scatter {
    pipeline: Pipeline,
}

impl Scatter {
    /// `blend`: `Replace` (the last datum on a texel wins) or `Add` (data are summed).
    pub fn new(ctx: &Context, blend: Blend) -> Result<Scatter> {
        let pipeline = Pipeline::new(
            ctx,
            &PipelineDesc::new(
                &shaders::gpu::SCATTER_VERT,
                &shaders::gpu::SCATTER_FRAG,
                Topology::Points,
                &[TexFormat::Rgba32F],
                blend,
            ),
        )?;
        Ok(Scatter { pipeline })
    }

    /// Draws `data` into a fresh zeroed `width`×`height` target and reads it back.
    pub fn scatter(&self, ctx: &Context, width: u32, height: u32, data: &[Datum]) -> Result<Vec<[f32; 4]>> {
        if let Some(d) = data.iter().find(|d| u64::from(d.texel) >= u64::from(width) * u64::from(height)) {
            return Err(GpuError::Usage(format!("texel {} outside a {width}×{height} target", d.texel)));
        }
        let count = u32::try_from(data.len()).map_err(|_| GpuError::Usage("too many data".into()))?;
        let target = Texture::new(ctx, TexFormat::Rgba32F, width, height, "scatter target")?;
        let vertices = Buffer::with_data(ctx, data, "scatter data")?;
        let size = [(width as f32).to_bits(), (height as f32).to_bits()];
        let out = ctx.submit(|rec| {
            rec.render(&[Attachment::new(&target, Load::Zero)], None, &[], |pass| {
                pass.bind(&self.pipeline)?;
                pass.vertex_buffers(&vertices, None)?;
                pass.push(&size)?;
                pass.draw(0..count, 0..1)
            })?;
            rec.readback(&target)
        })?;
        out.to_vec()
    }
}

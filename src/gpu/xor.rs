//! XOR rasterization: triangles drawn with logic op XOR into an integer target, so a
//! texel covered an even number of times is unchanged (parity accumulation, Ch. 5).

use super::context::Context;
use super::error::{GpuError, Result};
use super::memory::Buffer;
use super::pass::{Attachment, Load, RenderScope};
use super::pipeline::{Blend, Pipeline, PipelineDesc, Topology};
use super::shaders;
use super::texture::{TexFormat, Texture};

/// The XOR triangle pipeline for one integer format.
pub struct XorRaster {
    pipeline: Pipeline,
}

impl XorRaster {
    pub fn new(ctx: &Context, format: TexFormat) -> Result<XorRaster> {
        let pipeline = Pipeline::new(
            ctx,
            &PipelineDesc::new(
                &shaders::gpu::XOR_VERT,
                &shaders::gpu::XOR_FRAG,
                Topology::Triangles,
                &[format],
                Blend::Xor,
            ),
        )?;
        Ok(XorRaster { pipeline })
    }

    /// Inside a pass into a `size` target: XORs `value` into every texel whose centre
    /// the triangles of `vertices` (texel units, 3 per triangle) cover.
    pub fn draw<'p>(
        &'p self,
        pass: &mut RenderScope<'_, 'p>,
        vertices: &Buffer,
        count: u32,
        size: [u32; 2],
        value: u32,
    ) -> Result<()> {
        pass.bind(&self.pipeline)?;
        pass.vertex_buffers(vertices, None)?;
        // Matches `Params` in xor_params.glsl: vec2 size, uint value.
        let p = [(size[0] as f32).to_bits(), (size[1] as f32).to_bits(), value];
        pass.push(&p)?;
        pass.draw(0..count, 0..1)
    }

    /// XOR-rasterizes `triangles` (texel units) into a fresh zeroed `width`×`height`
    /// target and reads it back (one u32 per texel, row-major).
    pub fn rasterize(
        &self,
        ctx: &Context,
        width: u32,
        height: u32,
        triangles: &[[[f32; 2]; 3]],
        value: u32,
    ) -> Result<Vec<u32>> {
        let format = self.pipeline.targets[0];
        let target = Texture::new(ctx, format, width, height, "xor target")?;
        let flat: Vec<[f32; 2]> = triangles.iter().flatten().copied().collect();
        let vertices = Buffer::with_data(ctx, &flat, "xor triangles")?;
        let count = u32::try_from(flat.len()).map_err(|_| GpuError::Usage("too many triangles".into()))?;
        let out = ctx.submit(|rec| {
            rec.render(&[Attachment::new(&target, Load::Zero)], None, &[], |pass| {
                self.draw(pass, &vertices, count, [width, height], value)
            })?;
            rec.readback(&target)
        })?;
        Ok(match format {
            TexFormat::R8Ui => out.to_vec::<u8>()?.into_iter().map(u32::from).collect(),
            _ => out.to_vec::<u32>()?,
        })
    }
}

//! `reduce_sum`: the texture era's parallel reduction (Alg. 4-3). Each pass renders a
//! full-target quad over a quarter of the previous size, every texel summing a 2×2
//! block, ping-ponging between two targets until one texel holds the sum.
//! Integer-valued data is summed exactly while every partial sum stays below 2²⁴.

use super::context::Context;
use super::error::{GpuError, Result};
use super::pass::{Attachment, Load, PingPong, Recorder};
use super::pipeline::{Blend, Pipeline};
use super::shaders;
use super::texture::{TexFormat, Texture};

/// The reduction pipeline and its ping-pong targets, sized once for inputs up to
/// `max_width`×`max_height` and reused.
pub struct Reducer {
    pipeline: Pipeline,
    pair: PingPong,
}

impl Reducer {
    pub fn new(ctx: &Context, max_width: u32, max_height: u32) -> Result<Reducer> {
        let pipeline =
            Pipeline::quad(ctx, &shaders::gpu::REDUCE_FRAG, &[TexFormat::Rgba32F], Blend::Replace)?;
        let (w, h) = (max_width.div_ceil(2).max(1), max_height.div_ceil(2).max(1));
        Ok(Reducer { pipeline, pair: PingPong::new(ctx, TexFormat::Rgba32F, w, h, "reduce")? })
    }

    /// Records the passes that sum the `width`×`height` corner of `src` (RGBA32F) into
    /// one texel; returns the texture whose texel (0, 0) holds the four channel sums.
    pub fn record<'a>(
        &'a mut self,
        rec: &mut Recorder,
        src: &'a Texture,
        width: u32,
        height: u32,
    ) -> Result<&'a Texture> {
        if src.format() != TexFormat::Rgba32F {
            return Err(GpuError::Usage(format!(
                "reduce_sum needs an RGBA32F texture, not {:?}",
                src.format()
            )));
        }
        if width == 0 || height == 0 || width > src.width() || height > src.height() {
            return Err(GpuError::Usage(format!(
                "cannot reduce {width}×{height} texels of a {}×{} texture",
                src.width(),
                src.height()
            )));
        }
        if width.div_ceil(2) > self.pair.width() || height.div_ceil(2) > self.pair.height() {
            return Err(GpuError::Usage(format!(
                "reducer sized for {}×{} inputs, asked for {width}×{height}",
                self.pair.width() * 2,
                self.pair.height() * 2
            )));
        }
        let (mut w, mut h) = (width, height);
        let mut first = true;
        while w > 1 || h > 1 {
            let (ow, oh) = (w.div_ceil(2), h.div_ceil(2));
            let input = if first { src } else { self.pair.src() };
            let reads = [input];
            let size = [w as i32, h as i32];
            rec.render(
                &[Attachment::new(self.pair.dst(), Load::Discard)],
                Some([0, 0, ow, oh]),
                &reads,
                |pass| {
                    pass.bind(&self.pipeline)?;
                    pass.textures(&[(0, input)])?;
                    pass.push(&size)?;
                    pass.quad()
                },
            )?;
            self.pair.swap();
            (w, h, first) = (ow, oh, false);
        }
        Ok(if first { src } else { self.pair.src() })
    }

    /// Sums the `width`×`height` corner of `src` and reads the result back.
    pub fn sum(&mut self, ctx: &Context, src: &Texture, width: u32, height: u32) -> Result<[f32; 4]> {
        let buffer = ctx.submit(|rec| {
            let out = self.record(rec, src, width, height)?;
            rec.readback_region(out, 0..1, [0, 0, 1, 1])
        })?;
        let v = buffer.to_vec::<[f32; 4]>()?;
        v.first().copied().ok_or_else(|| GpuError::Usage("empty readback".into()))
    }
}

/// Uploads `data` (`width`×`height` RGBA texels, row-major), reduces it on the GPU and
/// returns the four channel sums.
pub fn reduce_sum(ctx: &Context, data: &[[f32; 4]], width: u32, height: u32) -> Result<[f32; 4]> {
    if data.len() as u64 != width as u64 * height as u64 {
        return Err(GpuError::Usage(format!("{} texels given for a {width}×{height} texture", data.len())));
    }
    let tex = Texture::new(ctx, TexFormat::Rgba32F, width, height, "reduce input")?;
    let mut reducer = Reducer::new(ctx, width, height)?;
    ctx.submit(|rec| rec.upload(&tex, 0, data))?;
    reducer.sum(ctx, &tex, width, height)
}

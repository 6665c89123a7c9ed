//! `reduce_sum`: the texture era's parallel reduction (Alg. 4-3). Each pass renders a
//! full-target quad over a quarter of the previous size, every texel summing a 2×2
//! block, ping-ponging between two targets until one texel holds the sum.
//!
//! Two generalizations keep the pass structure but batch more work per pass: a texture
//! may be cut into equal power-of-two *tiles*, each reduced to its own texel (many
//! independent sums at once), and up to 8 layers are reduced together, one colour
//! attachment per layer. Integer-valued data is summed exactly while every partial sum
//! stays below 2²⁴.

use super::context::Context;
use super::error::{GpuError, Result};
use super::pass::{Attachment, Load, PingPong, Recorder};
use super::pipeline::{Blend, Pipeline};
use super::shaders;
use super::texture::{TexFormat, Texture};

/// Most layers reduced in one pass (one attachment each; the `reduce.frag` outputs).
pub const MAX_LAYERS: u32 = 8;

/// The reduction pipeline and its ping-pong targets, sized once and reused.
pub struct Reducer {
    pipeline: Pipeline,
    pair: PingPong,
    layers: u32,
}

impl Reducer {
    /// A reducer for RGBA32F inputs up to `max_width`×`max_height` with `layers` layers,
    /// reduced as one tile (any size).
    pub fn new(ctx: &Context, max_width: u32, max_height: u32, layers: u32) -> Result<Reducer> {
        Reducer::for_tiles(ctx, [max_width, max_height], [max_width, max_height], layers)
    }

    /// A reducer for inputs up to `max_size` cut into tiles of `tile` texels (the ping-pong
    /// targets hold the first pass's output, which halves only the axes tiles span).
    pub fn for_tiles(ctx: &Context, max_size: [u32; 2], tile: [u32; 2], layers: u32) -> Result<Reducer> {
        if layers == 0 || layers > MAX_LAYERS {
            return Err(GpuError::Usage(format!(
                "the reducer handles 1..={MAX_LAYERS} layers, not {layers}"
            )));
        }
        let targets = vec![TexFormat::Rgba32F; layers as usize];
        let pipeline = Pipeline::quad(ctx, &shaders::gpu::REDUCE_FRAG, &targets, Blend::Replace)?;
        let half = |n: u32, t: u32| if t > 1 { n.div_ceil(2) } else { n }.max(1);
        let (w, h) = (half(max_size[0], tile[0]), half(max_size[1], tile[1]));
        let pair = PingPong::new_layered(ctx, TexFormat::Rgba32F, w, h, layers, "reduce")?;
        Ok(Reducer { pipeline, pair, layers })
    }

    /// Records the passes that sum the `width`×`height` corner of `src` into one texel
    /// (per layer); returns the texture whose texel (0, 0) holds the four channel sums.
    /// Any size works (missing texels count as zero).
    pub fn record<'a>(
        &'a mut self,
        rec: &mut Recorder,
        src: &'a Texture,
        width: u32,
        height: u32,
    ) -> Result<&'a Texture> {
        self.record_tiles(rec, src, [width, height], [width, height])
    }

    /// Records the passes that sum each `tile[0]`×`tile[1]` tile of the `size` corner of
    /// `src` into one texel: tile (i, j) ends at texel (i, j) of the returned texture.
    /// With more than one tile along an axis, the tile side must be a power of two
    /// dividing the size, so 2×2 blocks never straddle two tiles.
    pub fn record_tiles<'a>(
        &'a mut self,
        rec: &mut Recorder,
        src: &'a Texture,
        size: [u32; 2],
        tile: [u32; 2],
    ) -> Result<&'a Texture> {
        if src.format() != TexFormat::Rgba32F || src.layers() != self.layers {
            return Err(GpuError::Usage(format!(
                "this reducer takes RGBA32F textures with {} layers, not {:?} with {}",
                self.layers,
                src.format(),
                src.layers()
            )));
        }
        let [w, h] = size;
        if w == 0 || h == 0 || w > src.width() || h > src.height() {
            return Err(GpuError::Usage(format!(
                "cannot reduce {w}×{h} texels of a {}×{} texture",
                src.width(),
                src.height()
            )));
        }
        for axis in 0..2 {
            let (n, t) = (size[axis], tile[axis]);
            if t == 0 || (t != n && (!t.is_power_of_two() || n % t != 0)) {
                return Err(GpuError::Usage(format!(
                    "tile side {t} must be the whole side {n} or a power of two dividing it"
                )));
            }
        }
        let first =
            [if tile[0] > 1 { w.div_ceil(2) } else { w }, if tile[1] > 1 { h.div_ceil(2) } else { h }];
        if (tile[0] > 1 || tile[1] > 1) && (first[0] > self.pair.width() || first[1] > self.pair.height()) {
            return Err(GpuError::Usage(format!(
                "reducer targets are {}×{}, the first pass of {w}×{h} in {}×{} tiles needs {}×{}",
                self.pair.width(),
                self.pair.height(),
                tile[0],
                tile[1],
                first[0],
                first[1]
            )));
        }
        let (mut cur, mut t) = (size, tile);
        let mut first = true;
        while t[0] > 1 || t[1] > 1 {
            let step = [if t[0] > 1 { 2 } else { 1 }, if t[1] > 1 { 2 } else { 1 }];
            let out = [cur[0].div_ceil(step[0]), cur[1].div_ceil(step[1])];
            let input = if first { src } else { self.pair.src() };
            let dst = self.pair.dst();
            let attachments = Attachment::each_layer(dst, Load::Discard);
            let reads = [input];
            let params = [cur[0] as i32, cur[1] as i32, step[0] as i32, step[1] as i32, self.layers as i32];
            rec.render(&attachments, Some([0, 0, out[0], out[1]]), &reads, |pass| {
                pass.bind(&self.pipeline)?;
                pass.textures(&[(0, input)])?;
                pass.push(&params)?;
                pass.quad()
            })?;
            self.pair.swap();
            cur = out;
            t = [t[0].div_ceil(step[0]), t[1].div_ceil(step[1])];
            first = false;
        }
        Ok(if first { src } else { self.pair.src() })
    }

    /// Sums the `width`×`height` corner of `src` and reads the result back (one RGBA
    /// sum per layer).
    pub fn sum(&mut self, ctx: &Context, src: &Texture, width: u32, height: u32) -> Result<Vec<[f32; 4]>> {
        let layers = self.layers;
        let buffer = ctx.submit(|rec| {
            let out = self.record(rec, src, width, height)?;
            rec.readback_region(out, 0..layers, [0, 0, 1, 1])
        })?;
        buffer.to_vec::<[f32; 4]>()
    }
}

/// Uploads `data` (`width`×`height` RGBA texels, row-major), reduces it on the GPU and
/// returns the four channel sums.
pub fn reduce_sum(ctx: &Context, data: &[[f32; 4]], width: u32, height: u32) -> Result<[f32; 4]> {
    if data.len() as u64 != width as u64 * height as u64 {
        return Err(GpuError::Usage(format!("{} texels given for a {width}×{height} texture", data.len())));
    }
    let tex = Texture::new(ctx, TexFormat::Rgba32F, width, height, "reduce input")?;
    let mut reducer = Reducer::new(ctx, width, height, 1)?;
    ctx.submit(|rec| rec.upload(&tex, 0, data))?;
    let sums = reducer.sum(ctx, &tex, width, height)?;
    sums.first().copied().ok_or(GpuError::Internal("empty readback"))
}

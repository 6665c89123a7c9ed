//! The presence buffer on the GPU (§5.3.1, Fig. 5-7/5-8): slices are rendered into the
//! layers of one R32UI array texture, 32 slices per texel (slice j is bit j mod 32 of
//! layer j / 32), a group of layers per submission; each group is copied to the host and
//! its bits moved into the volume. Every GPU method is a [`LayerPainter`].

use std::ops::Range;
use std::time::{Duration, Instant};

use super::Timings;
use super::error::{Result, VoxelError};
use super::grid::check_memory;
use super::volume::Volume;
use crate::gpu::{
    Attachment, Context, Load, Pipeline, PipelineDesc, RenderScope, TexFormat, Texture, Timestamps,
};
use crate::gpu::{Blend, Shader, Topology};

/// Slices per R32UI texel.
pub const SLICES_PER_LAYER: usize = 32;

/// Bytes of layers (texture plus readback) per submission, at most.
const GROUP_BYTES: u64 = 64 << 20;

/// What a GPU method draws into the layers.
pub(crate) trait LayerPainter {
    /// CPU work before the layers `layers` are recorded (e.g. building their triangles).
    fn prepare(&mut self, _layers: Range<usize>) -> Result<()> {
        Ok(())
    }

    /// Records the draws of layer `layer` (slices 32·layer …) inside its render pass.
    fn draw<'p>(&'p self, pass: &mut RenderScope<'_, 'p>, layer: usize) -> crate::gpu::Result<()>;

    /// Fixes up a layer's texels after readback (layers arrive top-down when
    /// [`top_down`](Self::top_down), else bottom-up).
    fn finish(&mut self, _layer: usize, _texels: &mut [u32]) {}

    fn top_down(&self) -> bool {
        false
    }
}

/// An XOR pipeline into R32UI layers with the slicing push constants.
pub(crate) fn xor_pipeline(ctx: &Context, vertex: &Shader) -> Result<Pipeline> {
    Ok(Pipeline::new(
        ctx,
        &PipelineDesc::new(
            vertex,
            &crate::gpu::shaders::voxel::SLICE_FRAG,
            Topology::Triangles,
            &[TexFormat::R32Ui],
            Blend::Xor,
        ),
    )?)
}

/// Texels of margin around the N×N voxels in each layer: grid units [0, N]² land on
/// texels 1..=N, so a vertex that rounding pushes a hair outside the grid still lies
/// inside the viewport and is never clipped (clipping would compute new vertices per
/// triangle and break the bit-identical shared edges). Culled vertices go to the corner.
pub const MARGIN: usize = 1;

/// Side of a layer in texels.
pub(crate) fn side(n: usize) -> usize {
    n + 2 * MARGIN
}

/// The push constants of `glsl/voxel/slice_params.glsl`, field for field (std430 push
/// constant layout: two vec2, a float and a uint, 24 bytes, no padding).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct SliceParams {
    /// clip = p · clip_scale + clip_offset, p in grid units (x, z).
    pub clip_scale: [f32; 2],
    pub clip_offset: [f32; 2],
    /// y of the slice plane in grid units (j + ½).
    pub slice: f32,
    /// 1 << (j mod 32) for a slice; a mask for a Fang slab.
    pub bits: u32,
}

// SAFETY: four-byte fields only, `repr(C)`, no padding; any bit pattern is valid.
unsafe impl crate::gpu::Pod for SliceParams {}

/// The slicing push constants for slice `slice` of an N³ grid.
pub(crate) fn params(n: usize, slice: f32, bits: u32) -> SliceParams {
    // clip = (u + MARGIN)·2/side − 1
    let scale = 2.0 / side(n) as f32;
    let offset = MARGIN as f32 * scale - 1.0;
    SliceParams { clip_scale: [scale; 2], clip_offset: [offset; 2], slice, bits }
}

/// Checks that the device can draw an (N + 2)² presence buffer (N voxels and the margin)
/// with logic op XOR.
pub(crate) fn check_device(ctx: &Context, n: usize) -> Result<()> {
    let info = ctx.info();
    let max = (info.max_image_2d.min(info.max_viewport[0]).min(info.max_viewport[1]) as usize)
        .saturating_sub(2 * MARGIN);
    if n > max {
        return Err(VoxelError::Resolution {
            res: n,
            max,
            why: format!(" on {} (image or viewport size)", info.name),
        });
    }
    if !info.logic_op {
        return Err(VoxelError::Gpu(crate::gpu::GpuError::Unsupported(format!(
            "device {} has no logic op XOR",
            info.name
        ))));
    }
    Ok(())
}

/// Renders every layer with `painter` and returns the volume.
pub(crate) fn render(
    ctx: &Context,
    n: usize,
    painter: &mut impl LayerPainter,
    timings: &mut Timings,
) -> Result<Volume> {
    check_device(ctx, n)?;
    let layers = n.div_ceil(SLICES_PER_LAYER);
    let s = side(n) as u32;
    let layer_bytes = s as u64 * s as u64 * 4;
    let group =
        ((GROUP_BYTES / layer_bytes) as usize).clamp(1, layers).min(ctx.info().max_array_layers as usize);
    check_memory("the GPU presence buffer and its readback", n, 2 * group as u64 * layer_bytes)?;
    let mut volume = Volume::new(n)?;
    let tex = Texture::new_layered(ctx, TexFormat::R32Ui, s, s, group as u32, "presence buffer")?;
    let timer = if ctx.info().timestamps { Some(Timestamps::new(ctx, 3)?) } else { None };
    let mut starts: Vec<usize> = (0..layers).step_by(group).collect();
    if painter.top_down() {
        starts.reverse();
    }
    for first in starts {
        let range = first..(first + group).min(layers);
        let t = Instant::now();
        painter.prepare(range.clone())?;
        timings.prepare += t.elapsed();
        let t = Instant::now();
        let count = range.len() as u32;
        let buffer = ctx.submit(|rec| {
            if let Some(timer) = &timer {
                rec.reset_timestamps(timer);
                rec.timestamp(timer, 0)?;
            }
            for layer in range.clone() {
                let target = [Attachment::layer(&tex, (layer - first) as u32, Load::Zero)];
                rec.render(&target, None, &[], |pass| painter.draw(pass, layer))?;
            }
            if let Some(timer) = &timer {
                rec.timestamp(timer, 1)?;
            }
            let m = MARGIN as u32;
            let buffer = rec.readback_region(&tex, 0..count, [m, m, n as u32, n as u32])?;
            if let Some(timer) = &timer {
                rec.timestamp(timer, 2)?;
            }
            Ok(buffer)
        })?;
        match &timer {
            Some(timer) => {
                let ms = timer.read_ms(3)?;
                timings.draw += Duration::from_secs_f64(ms[1] / 1e3);
                timings.copy += Duration::from_secs_f64((ms[2] - ms[1]).max(0.0) / 1e3);
            }
            None => timings.draw += t.elapsed(),
        }
        let t = Instant::now();
        let mut texels = buffer.to_vec::<u32>()?;
        let mut order: Vec<usize> = range.clone().collect();
        if painter.top_down() {
            order.reverse();
        }
        for layer in order {
            let local = layer - first;
            let words = &mut texels[local * n * n..(local + 1) * n * n];
            painter.finish(layer, words);
            volume.xor_packed_slices(layer * SLICES_PER_LAYER, words)?;
        }
        timings.readback += t.elapsed();
    }
    Ok(volume)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slice_params_mirror_the_shader_block() {
        // slice_params.glsl: vec2 clip_scale, vec2 clip_offset, float slice, uint bits.
        assert_eq!(std::mem::offset_of!(SliceParams, clip_offset), 8);
        assert_eq!(std::mem::offset_of!(SliceParams, slice), 16);
        assert_eq!(std::mem::offset_of!(SliceParams, bits), 20);
        let ctx = Context::from_env().expect("a Vulkan device (tools/setup installs lavapipe)");
        let size = std::mem::size_of::<SliceParams>() as u32;
        for pipeline in
            [super::super::pgpu::pipeline(&ctx).unwrap(), super::super::fgpu::pipeline(&ctx).unwrap()]
        {
            assert_eq!(
                pipeline.push.map(|(_, offset, bytes)| (offset, bytes)),
                Some((0, size)),
                "{}",
                pipeline.name
            );
        }
        let p = params(30, 4.5, 1 << 4);
        assert_eq!((p.clip_scale, p.slice, p.bits), ([2.0 / 32.0; 2], 4.5, 16));
    }
}

//! The fixed-function version (§5.3.3, SPEC §4.3 "FGPU"): the CPU slices every tetra
//! (Table 5-1, the same `slicing` as the CPU method) and hands each slice's triangles to
//! the GPU, which only rasterizes them with logic op XOR (a pass-through vertex shader).
//! The triangles change with every slice, so they are rebuilt and uploaded per group of
//! layers, the way the thesis re-sent them per slice.

use std::ops::Range;

use glam::DVec3;

use super::error::{Result, VoxelError};
use super::grid::{Grid, check_memory};
use super::layers::{LayerPainter, SLICES_PER_LAYER, params};
use super::slicing::{section, slice_range};
use super::solid::Solid;
use crate::gpu::{Buffer, Context, Pipeline, RenderScope, shaders};

/// The pass-through XOR pipeline for 2D triangles in grid units.
pub(crate) fn pipeline(ctx: &Context) -> Result<Pipeline> {
    super::layers::xor_pipeline(ctx, &shaders::voxel::SECTION_VERT)
}

/// Triangles of some slices, uploaded, with each slice's vertex range.
pub(crate) struct SliceTriangles<'a> {
    pub pipeline: &'a Pipeline,
    pub ctx: Context,
    pub n: usize,
    pub buffer: Option<Buffer>,
    /// Vertex range of slice j − first slice of the group.
    pub ranges: Vec<Range<u32>>,
    pub first_slice: usize,
    /// Push-constant bits of each slice of the group.
    pub bits: Vec<u32>,
}

impl<'a> SliceTriangles<'a> {
    pub fn new(ctx: &Context, pipeline: &'a Pipeline, n: usize) -> SliceTriangles<'a> {
        SliceTriangles {
            pipeline,
            ctx: ctx.clone(),
            n,
            buffer: None,
            ranges: Vec::new(),
            first_slice: 0,
            bits: Vec::new(),
        }
    }

    /// Uploads per-slice triangle lists for slices `first..first + lists.len()`.
    pub fn upload(&mut self, first: usize, lists: Vec<Vec<[f32; 2]>>, bits: Vec<u32>) -> Result<()> {
        let total: usize = lists.iter().map(Vec::len).sum();
        check_memory("the slice triangles of a group of layers", self.n, total as u64 * 8 * 2)?;
        if total > u32::MAX as usize {
            return Err(VoxelError::Mesh("too many slice triangles for one vertex buffer".into()));
        }
        let mut flat = Vec::with_capacity(total);
        self.ranges.clear();
        for list in &lists {
            let start = flat.len() as u32;
            flat.extend_from_slice(list);
            self.ranges.push(start..flat.len() as u32);
        }
        // Drop the previous group's buffer first: only one group is resident at a time.
        self.buffer = None;
        self.buffer = if flat.is_empty() {
            None
        } else {
            Some(Buffer::with_data(&self.ctx, &flat, "slice triangles")?)
        };
        self.first_slice = first;
        self.bits = bits;
        Ok(())
    }

    /// Draws the slices of layer `layer` that this group holds.
    pub fn draw_layer<'p>(&'p self, pass: &mut RenderScope<'_, 'p>, layer: usize) -> crate::gpu::Result<()> {
        let Some(buffer) = &self.buffer else { return Ok(()) };
        pass.bind(self.pipeline)?;
        pass.vertex_buffers(buffer, None)?;
        let first = layer * SLICES_PER_LAYER;
        for j in first..(first + SLICES_PER_LAYER).min(self.n) {
            let local = j - self.first_slice;
            let range = self.ranges[local].clone();
            if !range.is_empty() {
                pass.push(&[params(self.n, j as f32 + 0.5, self.bits[local])])?;
                pass.draw(range, 0..1)?;
            }
        }
        Ok(())
    }
}

/// FGPU: the sorted tetras and the per-group triangle lists.
pub(crate) struct Fgpu<'a> {
    tetras: Vec<[DVec3; 4]>,
    triangles: SliceTriangles<'a>,
}

impl<'a> Fgpu<'a> {
    pub fn new(ctx: &Context, pipeline: &'a Pipeline, solid: &Solid, grid: &Grid) -> Fgpu<'a> {
        Fgpu { tetras: solid.sorted_tetras(grid), triangles: SliceTriangles::new(ctx, pipeline, grid.n) }
    }
}

impl LayerPainter for Fgpu<'_> {
    fn prepare(&mut self, layers: Range<usize>) -> Result<()> {
        let n = self.triangles.n;
        let slices = layers.start * SLICES_PER_LAYER..(layers.end * SLICES_PER_LAYER).min(n);
        let mut lists: Vec<Vec<[f32; 2]>> = vec![Vec::new(); slices.len()];
        for t in &self.tetras {
            let range = slice_range(t, n);
            for j in range.start.max(slices.start)..range.end.min(slices.end) {
                if let Some(sec) = section(t, j as f64 + 0.5) {
                    for tri in sec.triangles() {
                        lists[j - slices.start].extend(tri.map(|p| [p[0] as f32, p[1] as f32]));
                    }
                }
            }
        }
        let bits = slices.clone().map(|j| 1u32 << (j % SLICES_PER_LAYER)).collect();
        self.triangles.upload(slices.start, lists, bits)
    }

    fn draw<'p>(&'p self, pass: &mut RenderScope<'_, 'p>, layer: usize) -> crate::gpu::Result<()> {
        self.triangles.draw_layer(pass, layer)
    }
}

//! The programmable-pipeline versions (§5.3.4, SPEC §4.3): Alg. 5-2 and its zoned,
//! multi-pass form.
//!
//! - `pgpu`: one static vertex buffer, two triangles (six vertices) per tetra, each
//!   vertex carrying the tetra's four vertices sorted by y and its cross-section point;
//!   the slice is a push constant and every slice draws the whole buffer (the vertex
//!   shader culls the tetras the slice misses).
//! - `zoned` (PGPU-MP, §5.4.2): the slices are cut into zones of Z consecutive slices and
//!   each zone gets its own display list: a contiguous copy of the tetras that reach it
//!   (a tetra spanning several zones is copied into each, the memory the thesis trades
//!   for speed); a slice draws only its zone's list. Z defaults to [`default_zone`]:
//!   N/8 slices, between 4 and 32 (one R32UI layer). Measured on lavapipe (armadillo,
//!   128³–512³), zones of 4, 8, 16 and 32 slices draw within ±10 % of each other while
//!   small zones cost more copies to prepare; at least 8 zones keep small grids from
//!   drawing most tetras in most slices. (Index lists into one shared buffer would avoid the copies, but
//!   lavapipe shades every vertex between a draw's lowest and highest index.)

use std::ops::Range;

use glam::DVec3;

use super::error::{Result, VoxelError};
use super::grid::{Grid, check_memory};
use super::layers::{LayerPainter, SLICES_PER_LAYER, params};
use super::solid::Solid;
use crate::gpu::{Buffer, Context, Pipeline, RenderScope, shaders};

/// The six vertices of a tetra: triangle (a, b, c) and triangle (c, b, d); the second
/// triangle's ids carry bit 2 so the shader can send it out of view outside the middle
/// interval (Alg. 5-2's "IS_MAIN_TRIANGLE || IN_INTERVAL(slice, B.y, C.y)").
const POINTS: [u32; 6] = [0, 1, 2, 6, 5, 3];

/// One vertex of the static buffer: point id, then A, B, C, D as f32 (grid units).
type Vertex = [u32; 13];

const VERTEX_BYTES: u64 = std::mem::size_of::<Vertex>() as u64;

/// Zone height used when none is asked for: N/8 slices, between 4 and 32.
pub fn default_zone(n: usize) -> usize {
    (n / 8).clamp(4, SLICES_PER_LAYER)
}

/// The static vertex buffer of Alg. 5-2, one display list per zone (one zone for pgpu).
pub(crate) struct Tetras<'a> {
    pipeline: &'a Pipeline,
    vertices: Buffer,
    /// Zone height in slices, and each zone's vertex range.
    zone: usize,
    ranges: Vec<Range<u32>>,
    n: usize,
}

/// The PGPU pipeline (Alg. 5-2 vertex shader, XOR into R32UI).
pub(crate) fn pipeline(ctx: &Context) -> Result<Pipeline> {
    super::layers::xor_pipeline(ctx, &shaders::voxel::SLICE_VERT)
}

/// The six vertices of tetra `t` (f32, grid units).
fn tetra_vertices(t: &[DVec3; 4]) -> [Vertex; 6] {
    let mut v: Vertex = [0; 13];
    for (q, p) in t.iter().enumerate() {
        v[1 + 3 * q] = (p.x as f32).to_bits();
        v[2 + 3 * q] = (p.y as f32).to_bits();
        v[3 + 3 * q] = (p.z as f32).to_bits();
    }
    POINTS.map(|point| {
        v[0] = point;
        v
    })
}

/// Slices the vertex shader may draw tetra `t` in: hi > j + ½ ≥ lo for the f32 y of its
/// highest and lowest vertex (the values the shader compares), widened by one slice.
fn f32_slices(t: &[DVec3; 4], n: usize) -> Range<usize> {
    let (lo, hi) = (t[3].y as f32 as f64, t[0].y as f32 as f64);
    let first = ((lo - 0.5).ceil() - 1.0).max(0.0) as usize;
    let end = (((hi - 0.5).ceil() + 1.0).max(0.0) as usize).min(n);
    first..end.max(first)
}

impl<'a> Tetras<'a> {
    /// Builds the display lists: one with every tetra (`zone` None), or one per zone of
    /// `zone` slices.
    pub fn new(
        ctx: &Context,
        pipeline: &'a Pipeline,
        solid: &Solid,
        grid: &Grid,
        zone: Option<usize>,
    ) -> Result<Tetras<'a>> {
        let n = grid.n;
        let tetras = solid.sorted_tetras(grid);
        let zone = zone.unwrap_or(n).max(1);
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); n.div_ceil(zone)];
        for (i, t) in tetras.iter().enumerate() {
            let r = f32_slices(t, n);
            if !r.is_empty() {
                for list in &mut lists[r.start / zone..=(r.end - 1) / zone] {
                    list.push(i as u32);
                }
            }
        }
        let copies: usize = lists.iter().map(Vec::len).sum();
        let bytes = copies as u64 * 6 * VERTEX_BYTES;
        check_memory("the tetras' display lists", n, 2 * bytes)?;
        if copies * 6 > u32::MAX as usize {
            return Err(VoxelError::Mesh(format!(
                "{copies} tetra copies are too many for one vertex buffer"
            )));
        }
        // Each tetra's six vertices once, then copied into every zone's list.
        let all: Vec<[Vertex; 6]> = tetras.iter().map(tetra_vertices).collect();
        let mut vertices = Buffer::host(ctx, bytes.max(VERTEX_BYTES), "tetra display lists")?;
        let mut ranges = Vec::with_capacity(lists.len());
        let mut list_vertices: Vec<[Vertex; 6]> = Vec::new();
        let mut at = 0usize;
        for list in &lists {
            list_vertices.clear();
            list_vertices.extend(list.iter().map(|&t| all[t as usize]));
            vertices.write_slice(at, &list_vertices)?;
            ranges.push(at as u32 * 6..(at + list.len()) as u32 * 6);
            at += list.len();
        }
        Ok(Tetras { pipeline, vertices, zone, ranges, n })
    }
}

impl LayerPainter for Tetras<'_> {
    fn draw<'p>(&'p self, pass: &mut RenderScope<'_, 'p>, layer: usize) -> crate::gpu::Result<()> {
        pass.bind(self.pipeline)?;
        pass.vertex_buffers(&self.vertices, None)?;
        let first = layer * SLICES_PER_LAYER;
        for j in first..(first + SLICES_PER_LAYER).min(self.n) {
            pass.push(&[params(self.n, j as f32 + 0.5, 1 << (j - first))])?;
            pass.draw(self.ranges[j / self.zone].clone(), 0..1)?;
        }
        Ok(())
    }
}

//! Fang & Chen's voxelization (§5.2.6, SPEC §4.3 baseline): the surface triangles are
//! cut into slabs between consecutive slice planes and drawn seen along y with XOR, so a
//! texel counts the surface crossings of its column; a voxel is inside iff an odd number
//! of crossings lie above its centre ("XOR accumulation along y").
//!
//! Slab j is (y_j, y_{j+1}] (the top one reaches +∞); its pieces flip bits 0..=j mod 32
//! of layer j/32 (every slice of the layer at or below j sees them above), and after
//! readback each layer, top-down, is XORed with the parity of everything above it (bit 0
//! of the layer above). Fang clipped with the hardware's clip planes; here the CPU clips,
//! because clipping computes new vertices per triangle and two triangles sharing an edge
//! would then disagree on it. The cut points come from `slicing::edge_point`, so shared
//! edges and the two sides of a slab plane are bit-identical and cancel under XOR.

use std::ops::Range;

use glam::DVec3;

use super::error::Result;
use super::fgpu::SliceTriangles;
use super::grid::Grid;
use super::layers::{LayerPainter, SLICES_PER_LAYER};
use super::slicing::edge_point;
use super::solid::Solid;
use crate::gpu::{Context, Pipeline, RenderScope};

pub(crate) struct Fang<'a> {
    /// Covering triangles in grid units with their y extent.
    triangles: Vec<([DVec3; 3], f64, f64)>,
    pieces: SliceTriangles<'a>,
    /// Per texel: all ones if an odd number of crossings lie above the current layer.
    carry: Vec<u32>,
}

impl<'a> Fang<'a> {
    pub fn new(ctx: &Context, pipeline: &'a Pipeline, solid: &Solid, grid: &Grid) -> Fang<'a> {
        let triangles = solid
            .grid_triangles(grid)
            .into_iter()
            .map(|t| {
                let lo = t[0].y.min(t[1].y).min(t[2].y);
                let hi = t[0].y.max(t[1].y).max(t[2].y);
                (t, lo, hi)
            })
            .collect();
        Fang {
            triangles,
            pieces: SliceTriangles::new(ctx, pipeline, grid.n),
            carry: vec![0; grid.n * grid.n],
        }
    }
}

/// The part of triangle `t` with lo < y ≤ hi (hi = +∞ allowed), as a convex polygon in
/// (x, z), walking the triangle's edges and cutting each at the slab planes it crosses.
fn slab_piece(t: &[DVec3; 3], lo: f64, hi: f64, out: &mut Vec<[f64; 2]>) {
    out.clear();
    let inside = |p: DVec3| p.y > lo && p.y <= hi;
    for e in 0..3 {
        let (p, q) = (t[e], t[(e + 1) % 3]);
        if inside(p) {
            out.push([p.x, p.z]);
        }
        let (upper, lower) = if p.y > q.y { (p, q) } else { (q, p) };
        let cut = |s: f64| (upper.y > s && lower.y <= s).then(|| edge_point(upper, lower, s));
        // Crossings in the order met walking from p to q.
        let (first, second) = if p.y > q.y { (hi, lo) } else { (lo, hi) };
        for s in [first, second] {
            if s.is_finite() {
                if let Some(c) = cut(s) {
                    out.push(c);
                }
            }
        }
    }
}

impl LayerPainter for Fang<'_> {
    fn prepare(&mut self, layers: Range<usize>) -> Result<()> {
        let n = self.pieces.n;
        let slabs = layers.start * SLICES_PER_LAYER..(layers.end * SLICES_PER_LAYER).min(n);
        let mut lists: Vec<Vec<[f32; 2]>> = vec![Vec::new(); slabs.len()];
        let mut poly = Vec::with_capacity(5);
        for (t, ylo, yhi) in &self.triangles {
            // Slabs (j + ½, j + 1½] that meet [ylo, yhi]; the last one is unbounded.
            let first = ((ylo - 1.5).floor().max(0.0) as usize).max(slabs.start);
            let end = (((yhi - 0.5).ceil().max(0.0) as usize) + 1).min(slabs.end);
            for j in first..end {
                let lo = j as f64 + 0.5;
                let hi = if j + 1 == n { f64::INFINITY } else { lo + 1.0 };
                slab_piece(t, lo, hi, &mut poly);
                let list = &mut lists[j - slabs.start];
                for w in 1..poly.len().saturating_sub(1) {
                    for p in [poly[0], poly[w], poly[w + 1]] {
                        list.push([p[0] as f32, p[1] as f32]);
                    }
                }
            }
        }
        let bits = slabs.clone().map(|j| u32::MAX >> (31 - j % SLICES_PER_LAYER)).collect();
        self.pieces.upload(slabs.start, lists, bits)
    }

    fn draw<'p>(&'p self, pass: &mut RenderScope<'_, 'p>, layer: usize) -> crate::gpu::Result<()> {
        self.pieces.draw_layer(pass, layer)
    }

    fn finish(&mut self, _layer: usize, texels: &mut [u32]) {
        for (t, c) in texels.iter_mut().zip(&mut self.carry) {
            *t ^= *c;
            *c = if *t & 1 == 1 { u32::MAX } else { 0 };
        }
    }

    fn top_down(&self) -> bool {
        true
    }
}

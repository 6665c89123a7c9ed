//! Feito-Torres on the GPU (§4.3.3, Alg. 4-2 and 4-3), in the texture era's style:
//! the `gpu` and `cpu+gpu` methods here, `gpu+tetragrid` in [`super::gpu_grid`].
//!
//! Phase 1 draws one point-vertex per batch of covering tetrahedra (batch 1 is the
//! thesis' one point per tetrahedron), each on its own texel of an RGBA32F target with
//! eight attachments; the vertex shader (`glsl/inclusion/classify.vert`) classifies a
//! group of 32 query points (four per attachment, one per channel) against the batch and
//! the fragment shader writes the summed values. Instancing repeats the draw for more
//! point groups, each into its own tile of the target. Phase 2 is the 2×2 `reduce_sum`,
//! tile by tile, down to one texel per group (`Phase2::Gpu`), or a sum on the host over
//! the read-back phase-1 target (`Phase2::Host`, the thesis' CPU+GPU).
//!
//! ## Exactness
//! Coordinates are normalized to the solid's bounding cube ([-1, 1]³) and taken relative
//! to the apex; planes have unit normals, so a plane distance evaluated in f32 is off by
//! less than ~2·10⁻⁶. A term is only trusted when every plane says "inside" by at least
//! [`EPS`] or one says "outside" by at least `EPS`; those terms are exact. Every other
//! term (a point on or near a face, an apex edge or the base) adds `FLAG = 8`. Trusted
//! terms sum to twice the winding number, 0 or 2 for a valid solid, so any other sum
//! sends the point to the exact CPU test. Tetrahedra too flat for trustworthy f32 planes
//! contribute 0 on the GPU; a point within their bounding sphere goes to the exact CPU
//! test directly. Points outside the bounding box (grown by the CPU tolerance) are
//! Outside without a draw, exactly as on the CPU.
//!
//! Integer sums stay exact in f32 while they stay below 2²⁴: at most 8 per tetrahedron,
//! so up to 2 M tetrahedra.

use std::time::{Duration, Instant};

use glam::DVec3;

use crate::gpu::{
    Attachment, Blend, Buffer, Context, Load, Pipeline, PipelineDesc, Reducer, TexFormat, Texture, Topology,
    shaders,
};

use super::classifier::{Class, Classifier};
use super::cpu::FeitoTorres;
use super::error::{InclusionError, Result};
use super::tetragrid::GridClassifier;

/// Plane-distance margin in normalized coordinates (bounding cube = [-1, 1]³). f32
/// evaluation errors stay below 2·10⁻⁶ there; CPU ties are decided at 10⁻⁹ of the
/// diagonal, far inside this band.
pub const EPS: f32 = 1e-5;
/// Query points per group: 8 attachments × 4 channels (`GROUP_POINTS` in the shader).
pub const GROUP_POINTS: usize = 32;
/// Points in the uniform block (`MAX_POINTS` in the shader; 32 KiB).
pub(crate) const MAX_POINTS: usize = 2048;
/// Attachments (layers) of the phase-1 target.
pub(crate) const LAYERS: u32 = 8;
/// Largest tetrahedron count whose flagged sums stay exact in f32.
const MAX_TETRAS: usize = 1 << 21;

/// Where phase 2 runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase2 {
    /// 2×2 reduction passes on the GPU; one texel per group is read back.
    Gpu,
    /// The whole phase-1 target is read back and summed on the host (CPU+GPU).
    Host,
}

/// Tetrahedra per point-vertex by default, measured on lavapipe (`texgeo bench inclusion`
/// reports the thesis' batch of 1 beside it).
pub const DEFAULT_BATCH: u32 = 64;

#[derive(Clone, Copy, Debug)]
pub struct GpuOptions {
    /// Tetrahedra summed per point-vertex (1 = the thesis' layout).
    pub batch: u32,
    /// Point groups per draw (instances), each in its own tile.
    pub groups_per_draw: u32,
    pub phase2: Phase2,
}

impl Default for GpuOptions {
    fn default() -> GpuOptions {
        GpuOptions { batch: DEFAULT_BATCH, groups_per_draw: 32, phase2: Phase2::Gpu }
    }
}

/// Where the time of the last `classify_all` went (`inclusion --json`: times in ms).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct GpuStats {
    /// Points sent to the GPU (the rest were decided on the host).
    pub gpu_points: usize,
    /// Points answered by the exact CPU test (flagged by the GPU or near a flat tetrahedron).
    pub flagged: usize,
    pub draws: u32,
    /// Wall time of the GPU submissions (phase 1, phase 2, readback).
    #[serde(rename = "gpu_ms", serialize_with = "crate::json::ms")]
    pub gpu: Duration,
    /// Host-side phase 2 (`Phase2::Host`) and decoding.
    #[serde(rename = "host_ms", serialize_with = "crate::json::ms")]
    pub host: Duration,
    /// Exact CPU answers for flagged points.
    #[serde(rename = "fallback_ms", serialize_with = "crate::json::ms")]
    pub fallback: Duration,
}

impl GpuStats {
    /// Adds the counts and times of another call.
    pub fn add(&mut self, other: &GpuStats) {
        self.gpu_points += other.gpu_points;
        self.flagged += other.flagged;
        self.draws += other.draws;
        self.gpu += other.gpu;
        self.host += other.host;
        self.fallback += other.fallback;
    }
}

/// Normalization to the bounding cube: `(p - centre) / half`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Frame {
    pub centre: DVec3,
    pub half: f64,
}

impl Frame {
    pub fn of_box(lo: DVec3, hi: DVec3) -> Frame {
        Frame { centre: (lo + hi) * 0.5, half: ((hi - lo).max_element() * 0.5).max(f64::MIN_POSITIVE) }
    }

    pub fn apply(&self, p: DVec3) -> DVec3 {
        (p - self.centre) / self.half
    }
}

/// Unit-normal plane `[n, offset]` through `x, y, z` (distance of q = n·q + offset), or
/// `None` when the triangle is too thin for its f64 normal to be accurate to ~1e-7.
fn plane_through(x: DVec3, y: DVec3, z: DVec3) -> Option<[f64; 4]> {
    let n = (y - x).cross(z - x);
    let len = n.length();
    let scale = (y - x).length_squared().max((z - x).length_squared());
    if len <= 1e-9 * scale || len == 0.0 {
        return None;
    }
    let n = n / len;
    Some([n.x, n.y, n.z, -n.dot(x)])
}

/// The plane through `x, y, z` oriented so `w` is on its positive side; `None` when the
/// plane is untrustworthy or `w` (nearly) lies on it.
fn inward_plane(x: DVec3, y: DVec3, z: DVec3, w: DVec3) -> Option<[f64; 4]> {
    let p = plane_through(x, y, z)?;
    let h = p[0] * w.x + p[1] * w.y + p[2] * w.z + p[3];
    if h.abs() < 1e-7 {
        return None;
    }
    Some(if h < 0.0 { p.map(|v| -v) } else { p })
}

/// The four texels of tetrahedron (O, A, B, C), with `a, b, c` relative to the apex O in
/// normalized coordinates: the three faces through O (unit inward normals, zero offset;
/// the first texel's w holds 2s), then the base plane. `None` when it is too flat.
fn tetra_texels(a: DVec3, b: DVec3, c: DVec3) -> Option<[[f32; 4]; 4]> {
    let o = DVec3::ZERO;
    let [p0, p1, p2, p3] = [
        inward_plane(o, b, c, a)?,
        inward_plane(o, a, c, b)?,
        inward_plane(o, a, b, c)?,
        inward_plane(a, b, c, o)?,
    ];
    let s = (a.dot(b.cross(c))).signum();
    let f = |p: [f64; 4], w: f64| [p[0] as f32, p[1] as f32, p[2] as f32, w as f32];
    Some([f(p0, 2.0 * s), f(p1, 0.0), f(p2, 0.0), f(p3, p3[3])])
}

/// A tetrahedron that can never contain a point: its base plane rejects everything.
const EMPTY_TETRA: [[f32; 4]; 4] = [[0.0; 4], [0.0; 4], [0.0; 4], [0.0, 0.0, 0.0, -1.0]];

/// The covering tetrahedra as the GPU sees them — four RGBA32F layers, tetrahedron `t`
/// at texel `(t % width, t / width)` — and the flat ones it cannot judge.
pub(crate) struct TetraSet {
    pub texture: Texture,
    pub width: u32,
    pub count: u32,
    pub frame: Frame,
    /// The apex in normalized coordinates (query points are uploaded relative to it).
    pub apex: DVec3,
    /// The tetrahedra left out, as regions that may hold their points.
    flat: Vec<FlatTetra>,
}

/// Where the points of a tetrahedron too flat for the GPU may lie (normalized
/// coordinates relative to the apex, grown by a margin): its box and, when its base is a
/// proper triangle, a slab around the base plane as thick as the apex's height over it.
struct FlatTetra {
    lo: DVec3,
    hi: DVec3,
    slab: Option<([f64; 4], f64)>,
}

impl FlatTetra {
    fn new(a: DVec3, b: DVec3, c: DVec3, margin: f64) -> FlatTetra {
        let o = DVec3::ZERO;
        let slab = plane_through(a, b, c).map(|p| (p, p[3].abs() + margin));
        FlatTetra { lo: o.min(a).min(b).min(c) - margin, hi: o.max(a).max(b).max(c) + margin, slab }
    }

    fn may_hold(&self, q: DVec3) -> bool {
        q.cmpge(self.lo).all()
            && q.cmple(self.hi).all()
            && self.slab.is_none_or(|(p, h)| (p[0] * q.x + p[1] * q.y + p[2] * q.z + p[3]).abs() <= h)
    }
}

impl TetraSet {
    /// Uploads the covering tetrahedra of `ft` (its apex, every covering triangle).
    pub fn new(ctx: &Context, ft: &FeitoTorres) -> Result<TetraSet> {
        let n = ft.tetras().len();
        if n > MAX_TETRAS {
            return Err(InclusionError::TooLarge(format!(
                "{n} covering tetrahedra; the GPU path sums exactly up to {MAX_TETRAS}"
            )));
        }
        let (lo, hi) = ft.surface().bounds();
        let frame = Frame::of_box(lo, hi);
        let apex = frame.apply(ft.apex());
        let count = n.max(1) as u32;
        let width = count.min(4096);
        let height = count.div_ceil(width);
        let mut layers = vec![vec![[0.0f32; 4]; (width * height) as usize]; 4];
        let mut flat = Vec::new();
        for t in 0..n {
            let [a, b, c] = ft.tetra_vertices(t).map(|p| frame.apply(p) - apex);
            let texels = tetra_texels(a, b, c).unwrap_or_else(|| {
                flat.push(FlatTetra::new(a, b, c, 2.0 * EPS as f64));
                EMPTY_TETRA
            });
            for (layer, texel) in layers.iter_mut().zip(texels) {
                layer[t] = texel;
            }
        }
        let texture = Texture::new_layered(ctx, TexFormat::Rgba32F, width, height, 4, "tetrahedra")?;
        ctx.submit(|rec| {
            for (l, data) in layers.iter().enumerate() {
                rec.upload(&texture, l as u32, data)?;
            }
            Ok(())
        })?;
        Ok(TetraSet { texture, width, count: n as u32, frame, apex, flat })
    }

    /// True when `p` may lie in a tetrahedron the GPU left out.
    pub fn near_flat(&self, p: DVec3) -> bool {
        if self.flat.is_empty() {
            return false;
        }
        let q = self.frame.apply(p) - self.apex;
        self.flat.iter().any(|f| f.may_hold(q))
    }

    /// Query points as the uniform block holds them: normalized, relative to the apex.
    pub fn point_block(&self, points: &[DVec3]) -> Vec<[f32; 4]> {
        let mut block: Vec<[f32; 4]> = points
            .iter()
            .map(|&p| {
                let q = self.frame.apply(p) - self.apex;
                [q.x as f32, q.y as f32, q.z as f32, 0.0]
            })
            .collect();
        block.resize(MAX_POINTS, [0.0; 4]);
        block
    }

    /// Push constants of `classify_common.glsl`.
    pub fn params(&self, size: [u32; 2], tile_rows: u32, batch: u32, index_width: u32) -> [u32; 8] {
        [
            (size[0] as f32).to_bits(),
            (size[1] as f32).to_bits(),
            EPS.to_bits(),
            tile_rows,
            batch,
            self.count,
            self.width,
            index_width,
        ]
    }
}

/// Side lengths (powers of two) of a tile holding `n` texels, as square as possible.
pub(crate) fn tile_for(n: u32) -> [u32; 2] {
    let n = n.max(1).next_power_of_two();
    let w = 1u32 << n.ilog2().div_ceil(2);
    [w, (n / w).max(1)]
}

/// Decodes a point's phase-2 sum: `Some(class)` when exact, `None` when flagged.
pub(crate) fn decode(sum: f32) -> Option<Class> {
    if sum == 0.0 {
        Some(Class::Outside)
    } else if sum == 2.0 {
        Some(Class::Inside)
    } else {
        None
    }
}

/// The phase-1 pipeline for one vertex shader (all tetrahedra, or a grid cell's).
pub(crate) fn classify_pipeline(ctx: &Context, grid: bool) -> Result<Pipeline> {
    Ok(Pipeline::new(
        ctx,
        &PipelineDesc {
            vertex: if grid {
                &shaders::inclusion::CLASSIFY_GRID_VERT
            } else {
                &shaders::inclusion::CLASSIFY_VERT
            },
            fragment: &shaders::inclusion::CLASSIFY_FRAG,
            topology: Topology::Points,
            targets: &[TexFormat::Rgba32F; LAYERS as usize],
            blend: Blend::Replace,
            per_instance: &[],
        },
    )?)
}

/// The bookkeeping of one GPU classification, shared by every GPU method: each point's
/// class (Outside until decided), those flagged for the exact CPU test, and where the time
/// went.
pub(crate) struct Work {
    out: Vec<Class>,
    flagged: Vec<usize>,
    pub stats: GpuStats,
}

impl Work {
    /// Sorts points into those the GPU must classify (returned) and those decided on the
    /// host: Outside outside the grown bounding box (exactly as on the CPU), flagged near a
    /// flat tetrahedron.
    pub fn triage(ft: &FeitoTorres, set: &TetraSet, points: &[DVec3]) -> (Work, Vec<usize>) {
        let mut todo = Vec::new();
        let mut flagged = Vec::new();
        for (i, &p) in points.iter().enumerate() {
            if !ft.surface().in_bounds(p) {
                continue;
            }
            if set.near_flat(p) { flagged.push(i) } else { todo.push(i) }
        }
        (Work { out: vec![Class::Outside; points.len()], flagged, stats: GpuStats::default() }, todo)
    }

    /// Point `order[k]` takes the class its inclusion sum `sums[k]` decodes to, or is
    /// flagged for the exact test when the sum is not a clear answer.
    pub fn take(&mut self, order: &[usize], sums: &[f32]) {
        for (&i, &sum) in order.iter().zip(sums) {
            match decode(sum) {
                Some(c) => self.out[i] = c,
                None => self.flagged.push(i),
            }
        }
    }

    /// Answers the flagged points exactly (recording the time): every point's class, and
    /// the statistics.
    pub fn finish(mut self, exact: &GridClassifier, points: &[DVec3]) -> (Vec<Class>, GpuStats) {
        let t = Instant::now();
        for &i in &self.flagged {
            self.out[i] = exact.classify(points[i]);
        }
        self.stats.flagged = self.flagged.len();
        self.stats.fallback = t.elapsed();
        (self.out, self.stats)
    }
}

/// The `gpu` and `cpu+gpu` methods: every tetrahedron against every query point.
pub struct GpuInclusion {
    ctx: Context,
    set: TetraSet,
    pipeline: Pipeline,
    options: GpuOptions,
    /// Tile of one point group (holds every batch-vertex).
    tile: [u32; 2],
    target: Texture,
    reducer: Option<Reducer>,
    points: Buffer,
    /// Phase-2 sums (or, for `cpu+gpu`, the whole phase-1 target) copied to the host.
    readback: Buffer,
    /// Exact answers for flagged points (same apex and tolerance as the CPU methods).
    exact: GridClassifier,
    stats: GpuStats,
}

impl GpuInclusion {
    /// `exact` answers the flagged points; its tetrahedra are the ones drawn.
    pub fn new(ctx: &Context, exact: GridClassifier, options: GpuOptions) -> Result<GpuInclusion> {
        if options.batch == 0 || options.groups_per_draw == 0 {
            return Err(InclusionError::Options("batch and groups per draw must be at least 1".into()));
        }
        let set = TetraSet::new(ctx, exact.base())?;
        let tile = tile_for(set.count.div_ceil(options.batch));
        let max = ctx.info().max_image_2d;
        if tile[0] > max || tile[1] > max {
            return Err(InclusionError::TooLarge(format!(
                "a {}×{} phase-1 tile exceeds the device's {max}-texel textures; raise the batch size",
                tile[0], tile[1]
            )));
        }
        let groups =
            options.groups_per_draw.min(max / tile[1]).min((MAX_POINTS / GROUP_POINTS) as u32).max(1);
        let options = GpuOptions { groups_per_draw: groups, ..options };
        let target =
            Texture::new_layered(ctx, TexFormat::Rgba32F, tile[0], tile[1] * groups, LAYERS, "phase 1")?;
        let reducer = match options.phase2 {
            Phase2::Gpu => Some(Reducer::for_tiles(ctx, [tile[0], tile[1] * groups], tile, LAYERS)?),
            Phase2::Host => None,
        };
        let read_texels = match options.phase2 {
            Phase2::Gpu => u64::from(groups),
            Phase2::Host => u64::from(tile[0] * tile[1] * groups),
        };
        Ok(GpuInclusion {
            ctx: ctx.clone(),
            points: Buffer::host(ctx, (MAX_POINTS * 16) as u64, "query points")?,
            readback: Buffer::readback_for(ctx, u64::from(LAYERS) * read_texels * 16)?,
            set,
            pipeline: classify_pipeline(ctx, false)?,
            options,
            tile,
            target,
            reducer,
            exact,
            stats: GpuStats::default(),
        })
    }

    pub fn name(&self) -> &'static str {
        match self.options.phase2 {
            Phase2::Gpu => "gpu",
            Phase2::Host => "cpu+gpu",
        }
    }

    pub fn stats(&self) -> &GpuStats {
        &self.stats
    }

    pub fn options(&self) -> &GpuOptions {
        &self.options
    }

    /// The exact CPU classifier answering flagged points.
    pub fn exact(&self) -> &GridClassifier {
        &self.exact
    }

    /// Classifies every point; where the time went lands in [`Self::stats`].
    pub fn classify_all(&mut self, points: &[DVec3]) -> Result<Vec<Class>> {
        let (mut work, todo) = Work::triage(self.exact.base(), &self.set, points);
        work.stats.gpu_points = todo.len();
        let per_submit = GROUP_POINTS * self.options.groups_per_draw as usize;
        for chunk in todo.chunks(per_submit) {
            let chunk_points: Vec<DVec3> = chunk.iter().map(|&i| points[i]).collect();
            let sums = self.run_chunk(&chunk_points, &mut work.stats)?;
            work.take(chunk, &sums);
        }
        let (out, stats) = work.finish(&self.exact, points);
        self.stats = stats;
        Ok(out)
    }

    /// One submission: up to `groups_per_draw` groups of 32 points; one sum per point.
    fn run_chunk(&mut self, points: &[DVec3], stats: &mut GpuStats) -> Result<Vec<f32>> {
        let groups = points.len().div_ceil(GROUP_POINTS) as u32;
        self.points.write_slice(0, &self.set.point_block(points))?;
        let [tw, th] = self.tile;
        // The viewport is the render area, so texel placement uses the same size.
        let size = [tw, th * groups];
        let vertices = self.set.count.div_ceil(self.options.batch);
        let push = self.set.params(size, th, self.options.batch, 0);
        let t = Instant::now();
        let attachments = Attachment::each_layer(&self.target, Load::Zero);
        let reads = [&self.set.texture];
        let (pipeline, target, tetras, ubo, readback, reducer) = (
            &self.pipeline,
            &self.target,
            &self.set.texture,
            &self.points,
            &self.readback,
            &mut self.reducer,
        );
        self.ctx.submit(|rec| {
            rec.render(&attachments, Some([0, 0, size[0], size[1]]), &reads, |pass| {
                pass.bind(pipeline)?;
                pass.textures(&[(0, tetras)])?;
                pass.uniform(1, ubo)?;
                pass.push(&push)?;
                pass.draw(0..vertices, 0..groups)
            })?;
            match reducer {
                Some(r) => {
                    let sums = r.record_tiles(rec, target, size, [tw, th])?;
                    rec.readback_into(sums, 0..LAYERS, [0, 0, 1, groups], readback, 0)
                }
                None => rec.readback_into(target, 0..LAYERS, [0, 0, tw, th * groups], readback, 0),
            }
        })?;
        stats.gpu += t.elapsed();
        stats.draws += 1;
        let t = Instant::now();
        let texels = self.readback.view::<[f32; 4]>()?;
        let tile_texels = (tw * th) as usize;
        let per_layer = match self.options.phase2 {
            Phase2::Gpu => groups as usize,
            Phase2::Host => tile_texels * groups as usize,
        };
        let sums = (0..points.len())
            .map(|k| {
                let (g, slot) = (k / GROUP_POINTS, k % GROUP_POINTS);
                let (layer, channel) = (slot / 4, slot % 4);
                let base = layer * per_layer;
                match self.options.phase2 {
                    Phase2::Gpu => texels[base + g][channel],
                    // The thesis' CPU+GPU: phase 2 as a plain loop over the group's tile.
                    Phase2::Host => texels[base + g * tile_texels..base + (g + 1) * tile_texels]
                        .iter()
                        .map(|t| t[channel])
                        .sum(),
                }
            })
            .collect();
        stats.host += t.elapsed();
        Ok(sums)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::procedural;

    /// The uploaded tetra data, evaluated on the host in f64, sums to 2 inside and 0 outside.
    #[test]
    fn tetra_texels_cover_the_cube() {
        let mesh = procedural::cube();
        let ft = FeitoTorres::new(&mesh).unwrap();
        let (lo, hi) = ft.surface().bounds();
        let frame = Frame::of_box(lo, hi);
        let o = frame.apply(ft.apex());
        let texels: Vec<[[f32; 4]; 4]> =
            (0..ft.tetras().len()).map(|t| tetra_texels_of(&ft, &frame, o, t)).collect();
        for (q, want) in [(DVec3::new(0.3, -0.2, 0.1), 2.0), (DVec3::new(1.5, 0.2, 0.1), 0.0)] {
            let q = frame.apply(q) - o;
            let sum: f64 = texels
                .iter()
                .map(|t| {
                    let d = (0..4)
                        .map(|k| {
                            let w = if k == 3 { t[3][3] as f64 } else { 0.0 };
                            t[k][0] as f64 * q.x + t[k][1] as f64 * q.y + t[k][2] as f64 * q.z + w
                        })
                        .fold(f64::INFINITY, f64::min);
                    if d > 0.0 { t[0][3] as f64 } else { 0.0 }
                })
                .sum();
            assert_eq!(sum, want, "{q}");
        }
    }

    fn tetra_texels_of(ft: &FeitoTorres, frame: &Frame, o: DVec3, t: usize) -> [[f32; 4]; 4] {
        let [a, b, c] = ft.tetra_vertices(t).map(|p| frame.apply(p) - o);
        tetra_texels(a, b, c).unwrap_or(EMPTY_TETRA)
    }

    #[test]
    fn flat_tetras_are_left_out() {
        // Apex in the base plane, and a sliver base: both too flat for f32 planes.
        let (a, b, c) = (DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0), DVec3::new(-1.0, -1.0, 0.0));
        assert!(tetra_texels(a, b, c).is_none());
        assert!(tetra_texels(a + DVec3::Z, b + DVec3::Z, (a + b) * 0.5 + DVec3::Z).is_none());
        assert!(tetra_texels(a + DVec3::Z, b + DVec3::Z, c + DVec3::Z).is_some());
    }
}

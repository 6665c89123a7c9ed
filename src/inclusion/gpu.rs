//! Feito-Torres on the GPU (§4.3.3, Alg. 4-2 and 4-3), in the texture era's style.
//!
//! Phase 1 draws one point-vertex per batch of covering tetrahedra (batch 1 is the
//! thesis' one point per tetrahedron), each on its own texel of an RGBA32F target with
//! eight attachments; the vertex shader (`glsl/inclusion/classify.vert`) classifies a
//! group of 32 query points (four per attachment, one per channel) and the fragment
//! shader writes the summed values. Instancing repeats the draw for more point groups,
//! each into its own tile of the target. Phase 2 is the 2×2 `reduce_sum`, tile by tile,
//! down to one texel per group (`Phase2::Gpu`), or a sum on the host over the read-back
//! phase-1 target (`Phase2::Host`, the thesis' CPU+GPU).
//!
//! ## Exactness
//! Coordinates are normalized to the solid's bounding cube ([-1, 1]³) and planes are
//! unit-normal, so a plane distance evaluated in f32 is off by less than ~2·10⁻⁶. A term
//! is only trusted when every plane says "inside" by at least [`EPS`] or one says
//! "outside" by at least `EPS`; those terms are exact. Every other term (a point on or
//! near a face, an apex edge, the base, or a flat tetrahedron) adds `FLAG = 8`. Trusted
//! terms sum to twice the winding number, which is 0 or 2 for a valid solid, so a sum
//! other than 0 or 2 means "something was flagged or the solid is unusual": that point
//! is answered by the exact CPU test instead. Points outside the bounding box (grown by
//! the CPU tolerance) are Outside without a draw, exactly as on the CPU.
//!
//! Integer sums stay exact in f32 while they stay below 2²⁴: at most 8 per tetrahedron,
//! so up to 2 M tetrahedra.

use std::time::{Duration, Instant};

use glam::DVec3;

use crate::gpu::{
    Attachment, Blend, Buffer, Context, Load, Pipeline, PipelineDesc, Reducer, TexFormat, Texture, Topology,
    shaders,
};

use super::tetragrid::TetraGrid;
use super::{Class, Classifier, FeitoTorres, InclusionError, Result};

/// Plane-distance margin in normalized coordinates (bounding cube = [-1, 1]³). f32
/// evaluation errors are below 2·10⁻⁶ there; CPU ties are decided at 10⁻⁹ of the
/// diagonal, far inside this band.
pub const EPS: f32 = 1e-5;
/// Query points per group: 8 attachments × 4 channels (`GROUP_POINTS` in the shader).
pub const GROUP_POINTS: usize = 32;
/// Points in the uniform block (`MAX_POINTS` in the shader; 32 KiB).
const MAX_POINTS: usize = 2048;
/// Attachments (layers) of the phase-1 target.
const LAYERS: u32 = 8;
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
        GpuOptions { batch: super::solver::GPU_BATCH, groups_per_draw: 32, phase2: Phase2::Gpu }
    }
}

/// Where the time of the last `classify_all` went.
#[derive(Clone, Debug, Default)]
pub struct GpuStats {
    /// Points sent to the GPU (the rest were outside the bounding box).
    pub gpu_points: usize,
    /// Points the GPU flagged, answered by the exact CPU test.
    pub flagged: usize,
    pub draws: u32,
    /// Wall time of the GPU submissions (phase 1, phase 2, readback).
    pub gpu: Duration,
    /// Host-side phase 2 (`Phase2::Host`) and decoding.
    pub host: Duration,
    /// Exact CPU answers for flagged points.
    pub fallback: Duration,
}

/// Tetrahedra as the GPU sees them: five RGBA32F layers (four planes and `(2s, kind)`),
/// tetrahedron `t` at texel `(t % width, t / width)`.
pub(crate) struct TetraTexture {
    pub texture: Texture,
    pub width: u32,
    pub count: u32,
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

/// The five texels of one tetrahedron (apex `o`, base `a b c`, normalized coordinates).
fn tetra_texels(o: DVec3, a: DVec3, b: DVec3, c: DVec3) -> [[f32; 4]; 5] {
    let f = |p: [f64; 4]| p.map(|v| v as f32);
    let zero = [0.0f32; 4];
    let planes = [
        inward_plane(o, b, c, a),
        inward_plane(o, a, c, b),
        inward_plane(o, a, b, c),
        inward_plane(a, b, c, o),
    ];
    if let [Some(p0), Some(p1), Some(p2), Some(p3)] = planes {
        let det = (a - o).dot((b - o).cross(c - o));
        return [f(p0), f(p1), f(p2), f(p3), [(2.0 * det.signum()) as f32, 0.0, 0.0, 0.0]];
    }
    // Too flat for the f32 test: flag every point that may touch it. A proper base with
    // the apex (nearly) in its plane: the whole tetra lies within 1e-7 of that plane, a
    // slab test (kind 1). Anything else: its bounding sphere (kind 2).
    if let Some(base) = plane_through(a, b, c) {
        if (base[0] * o.x + base[1] * o.y + base[2] * o.z + base[3]).abs() < 1e-7 {
            return [f(base), zero, zero, zero, [0.0, 1.0, 0.0, 0.0]];
        }
    }
    let centre = (o + a + b + c) * 0.25;
    let radius = [o, a, b, c].iter().map(|p| (*p - centre).length()).fold(0.0, f64::max);
    let sphere = [centre.x as f32, centre.y as f32, centre.z as f32, (radius * (1.0 + 1e-6) + 1e-6) as f32];
    [sphere, zero, zero, zero, [0.0, 2.0, 0.0, 0.0]]
}

impl TetraTexture {
    /// Uploads the covering tetrahedra of `ft` (its apex, each covering triangle) in the
    /// frame's coordinates.
    pub fn new(ctx: &Context, frame: &Frame, ft: &FeitoTorres) -> Result<TetraTexture> {
        let n = ft.tetras().len();
        if n > MAX_TETRAS {
            return Err(InclusionError::TooLarge(format!(
                "{n} covering tetrahedra; the GPU path sums exactly up to {MAX_TETRAS}"
            )));
        }
        let count = n.max(1) as u32;
        let width = count.min(4096);
        let height = count.div_ceil(width);
        let texels = (width * height) as usize;
        let mut layers = vec![vec![[0.0f32; 4]; texels]; 5];
        let o = frame.apply(ft.apex());
        for t in 0..n {
            let [a, b, c] = ft.tetra_vertices(t).map(|p| frame.apply(p));
            for (layer, texel) in layers.iter_mut().zip(tetra_texels(o, a, b, c)) {
                layer[t] = texel;
            }
        }
        let texture = Texture::new_layered(ctx, TexFormat::Rgba32F, width, height, 5, "tetrahedra")?;
        ctx.submit(|rec| {
            for (l, data) in layers.iter().enumerate() {
                rec.upload(&texture, l as u32, data)?;
            }
            Ok(())
        })?;
        Ok(TetraTexture { texture, width, count: n as u32 })
    }
}

/// Side lengths (powers of two) of a tile holding `n` texels, as square as possible.
pub(crate) fn tile_for(n: u32) -> [u32; 2] {
    let n = n.max(1).next_power_of_two();
    let w = 1u32 << n.ilog2().div_ceil(2);
    [w, (n / w).max(1)]
}

/// Push constants of `classify_common.glsl`.
pub(crate) fn params(
    size: [u32; 2],
    tile_rows: u32,
    first_group: u32,
    batch: u32,
    tetras: &TetraTexture,
    index_width: u32,
) -> [u32; 9] {
    [
        (size[0] as f32).to_bits(),
        (size[1] as f32).to_bits(),
        EPS.to_bits(),
        tile_rows,
        first_group,
        batch,
        tetras.count,
        tetras.width,
        index_width,
    ]
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

/// Query points in the frame's coordinates, as the uniform block holds them.
pub(crate) fn point_block(frame: &Frame, points: &[DVec3]) -> Vec<[f32; 4]> {
    let mut block: Vec<[f32; 4]> = points
        .iter()
        .map(|&p| {
            let q = frame.apply(p);
            [q.x as f32, q.y as f32, q.z as f32, 0.0]
        })
        .collect();
    block.resize(MAX_POINTS, [0.0; 4]);
    block
}

/// The phase-1 pipeline for one vertex shader (all tetrahedra, or a grid cell's).
fn classify_pipeline(ctx: &Context, grid: bool) -> Result<Pipeline> {
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

/// Splits `points` into those the GPU must classify (inside the grown bounding box)
/// and the rest, which are Outside exactly as on the CPU.
fn in_bounds(ft: &FeitoTorres, points: &[DVec3]) -> Vec<usize> {
    (0..points.len()).filter(|&i| ft.surface().in_bounds(points[i])).collect()
}

/// The `gpu` and `cpu+gpu` methods: every tetrahedron against every query point.
pub struct GpuInclusion {
    ctx: Context,
    frame: Frame,
    tetras: TetraTexture,
    pipeline: Pipeline,
    options: GpuOptions,
    /// Tile of one point group (holds every batch-vertex).
    tile: [u32; 2],
    target: Texture,
    reducer: Option<Reducer>,
    /// Exact answers for flagged points (same apex and tolerance as the CPU methods).
    exact: TetraGrid,
    stats: GpuStats,
}

impl GpuInclusion {
    /// `exact` answers the flagged points; its tetrahedra are the ones drawn.
    pub fn new(ctx: &Context, exact: TetraGrid, options: GpuOptions) -> Result<GpuInclusion> {
        if options.batch == 0 || options.groups_per_draw == 0 {
            return Err(InclusionError::Options("batch and groups per draw must be at least 1".into()));
        }
        let ft = exact.base();
        let (lo, hi) = ft.surface().bounds();
        let frame = Frame::of_box(lo, hi);
        let tetras = TetraTexture::new(ctx, &frame, ft)?;
        let tile = tile_for(tetras.count.div_ceil(options.batch));
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
        Ok(GpuInclusion {
            ctx: ctx.clone(),
            frame,
            tetras,
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
    pub fn exact(&self) -> &TetraGrid {
        &self.exact
    }

    /// Classifies every point; where the time went lands in [`Self::stats`].
    pub fn classify_all(&mut self, points: &[DVec3]) -> Result<Vec<Class>> {
        let mut stats = GpuStats::default();
        let mut out = vec![Class::Outside; points.len()];
        let todo = in_bounds(self.exact.base(), points);
        stats.gpu_points = todo.len();
        let per_submit = GROUP_POINTS * self.options.groups_per_draw as usize;
        let mut flagged = Vec::new();
        for chunk in todo.chunks(per_submit) {
            let chunk_points: Vec<DVec3> = chunk.iter().map(|&i| points[i]).collect();
            let sums = self.run_chunk(&chunk_points, &mut stats)?;
            for (k, &i) in chunk.iter().enumerate() {
                match decode(sums[k]) {
                    Some(c) => out[i] = c,
                    None => flagged.push(i),
                }
            }
        }
        let t = Instant::now();
        stats.flagged = flagged.len();
        for i in flagged {
            out[i] = self.exact.classify(points[i]);
        }
        stats.fallback = t.elapsed();
        self.stats = stats;
        Ok(out)
    }

    /// One submission: up to `groups_per_draw` groups of 32 points; one sum per point.
    fn run_chunk(&mut self, points: &[DVec3], stats: &mut GpuStats) -> Result<Vec<f32>> {
        let groups = points.len().div_ceil(GROUP_POINTS) as u32;
        let ubo = Buffer::with_data(&self.ctx, &point_block(&self.frame, points), "query points")?;
        let [tw, th] = self.tile;
        // The viewport is the render area, so texel placement uses the same size.
        let size = [tw, th * groups];
        let vertices = self.tetras.count.div_ceil(self.options.batch);
        let push = params(size, th, 0, self.options.batch, &self.tetras, 0);
        let t = Instant::now();
        let attachments: Vec<Attachment> =
            (0..LAYERS).map(|l| Attachment::layer(&self.target, l, Load::Zero)).collect();
        let reads = [&self.tetras.texture];
        let (pipeline, target, tetras, reducer) =
            (&self.pipeline, &self.target, &self.tetras.texture, &mut self.reducer);
        let readback = self.ctx.submit(|rec| {
            rec.render(&attachments, Some([0, 0, size[0], size[1]]), &reads, |pass| {
                pass.bind(pipeline)?;
                pass.textures(&[(0, tetras)])?;
                pass.uniform(1, &ubo)?;
                pass.push(&push)?;
                pass.draw(0..vertices, 0..groups)
            })?;
            match reducer {
                Some(r) => {
                    let sums = r.record_tiles(rec, target, [tw, th * groups], [tw, th])?;
                    rec.readback_region(sums, 0..LAYERS, [0, 0, 1, groups])
                }
                None => rec.readback_region(target, 0..LAYERS, [0, 0, tw, th * groups]),
            }
        })?;
        stats.gpu += t.elapsed();
        stats.draws += 1;
        let t = Instant::now();
        let texels = readback.to_vec::<[f32; 4]>()?;
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

/// One TetraGrid job: up to 32 query points of one cell against that cell's list.
#[derive(Clone, Copy, Debug)]
struct Job {
    /// `[list start, list length, first point, point count]` (the shader's `job`).
    raw: [u32; 4],
    /// Index of the job's first point in the submission's point order.
    first: usize,
}

/// The `gpu+tetragrid` method (Table 4-6): query points grouped by TetraGrid cell, each
/// group drawn against its cell's tetrahedra only.
pub struct GpuGridInclusion {
    ctx: Context,
    frame: Frame,
    grid: TetraGrid,
    tetras: TetraTexture,
    /// The grid's CSR tetrahedron lists, as an R32UI texture `lists_width` wide.
    lists: Texture,
    lists_width: u32,
    pipeline: Pipeline,
    batch: u32,
    target: Texture,
    reducer: Reducer,
    stats: GpuStats,
}

/// Phase-1 target of the grid method: wide enough for the longest list's tile.
const GRID_TARGET_HEIGHT: u32 = 2048;

impl GpuGridInclusion {
    pub fn new(ctx: &Context, grid: TetraGrid, batch: u32) -> Result<GpuGridInclusion> {
        if batch == 0 {
            return Err(InclusionError::Options("batch must be at least 1".into()));
        }
        let ft = grid.base();
        let (lo, hi) = ft.surface().bounds();
        let frame = Frame::of_box(lo, hi);
        let tetras = TetraTexture::new(ctx, &frame, ft)?;
        let (start, ids) = grid.cell_lists();
        let longest = start.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0);
        let tile = tile_for(longest.div_ceil(batch));
        let max = ctx.info().max_image_2d;
        let height = GRID_TARGET_HEIGHT.max(tile[1]).min(max);
        if tile[0] > max || tile[1] > height {
            return Err(InclusionError::TooLarge(format!(
                "a grid cell lists {longest} tetrahedra: its {}×{} tile exceeds the device; raise the batch size",
                tile[0], tile[1]
            )));
        }
        let lists_width = 4096u32;
        let rows = (ids.len().max(1) as u32).div_ceil(lists_width);
        if rows > max {
            return Err(InclusionError::TooLarge(format!(
                "{} grid entries do not fit one texture",
                ids.len()
            )));
        }
        let lists = Texture::new(ctx, TexFormat::R32Ui, lists_width, rows, "tetragrid lists")?;
        let mut padded = ids.to_vec();
        padded.resize((lists_width * rows) as usize, 0);
        ctx.submit(|rec| rec.upload(&lists, 0, &padded))?;
        let target =
            Texture::new_layered(ctx, TexFormat::Rgba32F, tile[0], height, LAYERS, "phase 1 (grid)")?;
        Ok(GpuGridInclusion {
            ctx: ctx.clone(),
            frame,
            // Tiles vary per draw; the worst first pass halves x only ([2, 1] tiles).
            reducer: Reducer::for_tiles(ctx, [tile[0], height], [2, 1], LAYERS)?,
            grid,
            tetras,
            lists,
            lists_width,
            pipeline: classify_pipeline(ctx, true)?,
            batch,
            target,
            stats: GpuStats::default(),
        })
    }

    pub fn stats(&self) -> &GpuStats {
        &self.stats
    }

    pub fn grid(&self) -> &TetraGrid {
        &self.grid
    }

    /// Classifies every point; where the time went lands in [`Self::stats`].
    pub fn classify_all(&mut self, points: &[DVec3]) -> Result<Vec<Class>> {
        let mut stats = GpuStats::default();
        let mut out = vec![Class::Outside; points.len()];
        // Points by cell; points outside the grid's cube, or in cells no tetrahedron
        // reaches, are Outside (their inclusion sum is 0).
        let mut by_cell: Vec<(u32, usize)> = in_bounds(self.grid.base(), points)
            .into_iter()
            .filter_map(|i| {
                let c = self.grid.cell_of(points[i])?;
                (!self.grid.cell_tetras(c).is_empty()).then_some((c as u32, i))
            })
            .collect();
        by_cell.sort_unstable();
        stats.gpu_points = by_cell.len();
        let start = self.grid.cell_lists().0.to_vec();
        // Jobs: up to 32 points of one cell, packed into submissions of MAX_POINTS points
        // (minus one group, so a job's 32-point window stays inside the uniform block).
        let mut flagged = Vec::new();
        let mut k = 0;
        while k < by_cell.len() {
            let mut jobs = Vec::new();
            let mut order = Vec::new();
            while k < by_cell.len() && order.len() + GROUP_POINTS <= MAX_POINTS {
                let cell = by_cell[k].0;
                let first = order.len();
                while k < by_cell.len() && by_cell[k].0 == cell && order.len() - first < GROUP_POINTS {
                    order.push(by_cell[k].1);
                    k += 1;
                }
                let (s, e) = (start[cell as usize], start[cell as usize + 1]);
                jobs.push(Job { raw: [s, e - s, first as u32, (order.len() - first) as u32], first });
            }
            let sums = self.run_jobs(points, &order, &mut jobs, &mut stats)?;
            for (slot, &i) in order.iter().enumerate() {
                match decode(sums[slot]) {
                    Some(c) => out[i] = c,
                    None => flagged.push(i),
                }
            }
        }
        let t = Instant::now();
        stats.flagged = flagged.len();
        for i in flagged {
            out[i] = self.grid.classify(points[i]);
        }
        stats.fallback = t.elapsed();
        self.stats = stats;
        Ok(out)
    }

    /// One submission: jobs grouped by the power-of-two tile their list needs, one draw
    /// (instances = jobs) and one tiled reduction per group. Returns a sum per point of
    /// `order`.
    fn run_jobs(
        &mut self,
        points: &[DVec3],
        order: &[usize],
        jobs: &mut [Job],
        stats: &mut GpuStats,
    ) -> Result<Vec<f32>> {
        let chunk: Vec<DVec3> = order.iter().map(|&i| points[i]).collect();
        let ubo = Buffer::with_data(&self.ctx, &point_block(&self.frame, &chunk), "query points")?;
        let batch = self.batch;
        jobs.sort_by_key(|j| j.raw[1]);
        // Draws: runs of jobs sharing a tile size, cut to the target's height.
        let height = self.target.height();
        let mut draws: Vec<(std::ops::Range<usize>, [u32; 2])> = Vec::new();
        let mut i = 0;
        while i < jobs.len() {
            let tile = tile_for(jobs[i].raw[1].div_ceil(batch));
            let per_draw = (height / tile[1]) as usize;
            let mut j = i;
            while j < jobs.len() && j - i < per_draw && tile_for(jobs[j].raw[1].div_ceil(batch)) == tile {
                j += 1;
            }
            draws.push((i..j, tile));
            i = j;
        }
        let mut job_data: Vec<[u32; 4]> = jobs.iter().map(|j| j.raw).collect();
        job_data.resize(MAX_POINTS, [0; 4]);
        let job_buffer = Buffer::with_data(&self.ctx, &job_data, "grid jobs")?;
        let total: u64 = draws.iter().map(|(r, _)| r.len() as u64).sum::<u64>() * LAYERS as u64 * 16;
        let readback = Buffer::readback_for(&self.ctx, total)?;
        let t = Instant::now();
        let (pipeline, target, tetras, lists, reducer) =
            (&self.pipeline, &self.target, &self.tetras, &self.lists, &mut self.reducer);
        let lists_width = self.lists_width;
        self.ctx.submit(|rec| {
            let mut offset = 0u64;
            for (range, tile) in &draws {
                let n = range.len() as u32;
                // The viewport is the render area, so texel placement uses the same size.
                let size = [tile[0], tile[1] * n];
                let vertices = tile[0] * tile[1];
                let push = params(size, tile[1], range.start as u32, batch, tetras, lists_width);
                let attachments: Vec<Attachment> =
                    (0..LAYERS).map(|l| Attachment::layer(target, l, Load::Zero)).collect();
                let reads = [&tetras.texture, lists];
                rec.render(&attachments, Some([0, 0, size[0], size[1]]), &reads, |pass| {
                    pass.bind(pipeline)?;
                    pass.textures(&[(0, &tetras.texture), (2, lists)])?;
                    pass.uniform(1, &ubo)?;
                    pass.uniform(3, &job_buffer)?;
                    pass.push(&push)?;
                    pass.draw(0..vertices, 0..n)
                })?;
                let sums = reducer.record_tiles(rec, target, [tile[0], tile[1] * n], *tile)?;
                rec.readback_into(sums, 0..LAYERS, [0, 0, 1, n], &readback, offset)?;
                offset += n as u64 * LAYERS as u64 * 16;
            }
            Ok(())
        })?;
        stats.gpu += t.elapsed();
        stats.draws += draws.len() as u32;
        let t = Instant::now();
        let texels = readback.to_vec::<[f32; 4]>()?;
        let mut sums = vec![0.0f32; order.len()];
        let mut base = 0;
        for (range, _) in &draws {
            let n = range.len();
            for (g, job) in jobs[range.clone()].iter().enumerate() {
                for slot in 0..job.raw[3] as usize {
                    let (layer, channel) = (slot / 4, slot % 4);
                    sums[job.first + slot] = texels[base + layer * n + g][channel];
                }
            }
            base += n * LAYERS as usize;
        }
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
        let texels: Vec<[[f32; 4]; 5]> = (0..ft.tetras().len())
            .map(|t| {
                let [a, b, c] = ft.tetra_vertices(t).map(|p| frame.apply(p));
                tetra_texels(o, a, b, c)
            })
            .collect();
        for (q, want) in [(DVec3::new(0.3, -0.2, 0.1), 2.0), (DVec3::new(1.5, 0.2, 0.1), 0.0)] {
            let q = frame.apply(q);
            let sum: f64 = texels
                .iter()
                .map(|t| {
                    let d = (0..4)
                        .map(|k| {
                            t[k][0] as f64 * q.x
                                + t[k][1] as f64 * q.y
                                + t[k][2] as f64 * q.z
                                + t[k][3] as f64
                        })
                        .fold(f64::INFINITY, f64::min);
                    if d > 0.0 { t[4][0] as f64 } else { 0.0 }
                })
                .sum();
            assert_eq!(sum, want, "{q}");
        }
    }
}

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

use super::{Class, Classifier, InclusionError, Result};

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
        GpuOptions { batch: 16, groups_per_draw: 16, phase2: Phase2::Gpu }
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

/// Plane through `x, y, z` with unit normal pointing at `w`, as (n, offset): distance
/// of q = n·q + offset. `None` when the face is too thin to have a trustworthy plane or
/// `w` is (nearly) on it.
fn inward_plane(x: DVec3, y: DVec3, z: DVec3, w: DVec3) -> Option<[f64; 4]> {
    let n = (y - x).cross(z - x);
    let len = n.length();
    // sin of the face's smallest angle times its edge lengths: below 1e-9 the f64
    // normal itself is no longer accurate to the 1e-7 we need.
    if !(len > 1e-9 * (y - x).length().max((z - x).length()).powi(2)) || len == 0.0 {
        return None;
    }
    let mut n = n / len;
    let mut d = -n.dot(x);
    let h = n.dot(w) + d;
    if h.abs() < 1e-7 {
        return None;
    }
    if h < 0.0 {
        n = -n;
        d = -d;
    }
    Some([n.x, n.y, n.z, d])
}

/// The five texels of one tetrahedron (apex `o`, base `a b c`, normalized coordinates).
fn tetra_texels(o: DVec3, a: DVec3, b: DVec3, c: DVec3) -> [[f32; 4]; 5] {
    let f = |p: [f64; 4]| p.map(|v| v as f32);
    let det = (a - o).dot((b - o).cross(c - o));
    let planes = [
        inward_plane(o, b, c, a),
        inward_plane(o, a, c, b),
        inward_plane(o, a, b, c),
        inward_plane(a, b, c, o),
    ];
    if let [Some(p0), Some(p1), Some(p2), Some(p3)] = planes {
        return [f(p0), f(p1), f(p2), f(p3), [(2.0 * det.signum()) as f32, 0.0, 0.0, 0.0]];
    }
    // Flat or degenerate: flag every point that may touch it. A flat tetra whose base
    // is a proper triangle lies within the apex's height of the base plane (kind 1,
    // slab); anything else gets a bounding sphere (kind 2).
    let zero = [0.0f32; 4];
    if let Some(base) = inward_plane(a, b, c, a + (b - a).cross(c - a)) {
        let h = (base[0] * o.x + base[1] * o.y + base[2] * o.z + base[3]).abs();
        let slab = [base[0], base[1], base[2], base[3]];
        // The slab test is |n·q + w| < eps; widen it by h through a second copy of the
        // plane isn't possible in one texel, so fall back to the sphere when h matters.
        if h < 1e-7 {
            return [f(slab), zero, zero, zero, [0.0, 1.0, 0.0, 0.0]];
        }
    }
    let centre = (o + a + b + c) * 0.25;
    let radius = [o, a, b, c].iter().map(|p| (*p - centre).length()).fold(0.0, f64::max);
    [[centre.x as f32, centre.y as f32, centre.z as f32, (radius * (1.0 + 1e-6) + 1e-6) as f32], zero, zero, zero, [
        0.0, 2.0, 0.0, 0.0,
    ]]
}

impl TetraTexture {
    /// Uploads the tetrahedra (apex, each covering triangle) in the frame's coordinates.
    pub fn new(ctx: &Context, frame: &Frame, apex: DVec3, triangles: &[[DVec3; 3]]) -> Result<TetraTexture> {
        if triangles.len() > MAX_TETRAS {
            return Err(InclusionError::TooLarge(format!(
                "{} covering tetrahedra; the GPU path sums exactly up to {MAX_TETRAS}",
                triangles.len()
            )));
        }
        let count = triangles.len().max(1) as u32;
        let width = count.min(4096);
        let height = count.div_ceil(width);
        let texels = (width * height) as usize;
        let mut layers = vec![vec![[0.0f32; 4]; texels]; 5];
        let o = frame.apply(apex);
        for (t, tri) in triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|p| frame.apply(p));
            for (l, texel) in tetra_texels(o, a, b, c).into_iter().enumerate() {
                layers[l][t] = texel;
            }
        }
        let texture = Texture::new_layered(ctx, TexFormat::Rgba32F, width, height, 5, "tetrahedra")?;
        ctx.submit(|rec| {
            for (l, data) in layers.iter().enumerate() {
                rec.upload(&texture, l as u32, data)?;
            }
            Ok(())
        })?;
        Ok(TetraTexture { texture, width, count: triangles.len() as u32 })
    }
}

/// Side lengths (powers of two) of a tile holding `n` texels, as square as possible.
pub(crate) fn tile_for(n: u32) -> [u32; 2] {
    let n = n.max(1).next_power_of_two();
    let w = 1u32 << n.ilog2().div_ceil(2);
    [w, (n / w).max(1)]
}

/// Push constants of `classify_common.glsl`.
pub(crate) fn params(size: [u32; 2], tile_rows: u32, first_group: u32, batch: u32, tetras: &TetraTexture, index_width: u32) -> [u32; 9] {
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

/// The `gpu` and `cpu+gpu` methods: every tetrahedron against every query point.
pub struct GpuInclusion {
    ctx: Context,
    frame: Frame,
    /// Bounding box grown by the CPU tolerance: points outside are Outside.
    lo: DVec3,
    hi: DVec3,
    tetras: TetraTexture,
    pipeline: Pipeline,
    options: GpuOptions,
    /// Tile of one point group (holds every batch-vertex).
    tile: [u32; 2],
    target: Texture,
    reducer: Option<Reducer>,
    exact: Box<dyn Classifier>,
    name: &'static str,
    pub stats: std::sync::Mutex<GpuStats>,
}

impl GpuInclusion {
    /// `exact` answers flagged points; `triangles` are the covering triangles joined to
    /// `apex`; `lo, hi` is the mesh's bounding box grown by the CPU tolerance.
    pub fn new(
        ctx: &Context,
        apex: DVec3,
        triangles: &[[DVec3; 3]],
        bounds: (DVec3, DVec3),
        exact: Box<dyn Classifier>,
        options: GpuOptions,
    ) -> Result<GpuInclusion> {
        let (lo, hi) = bounds;
        let frame = Frame::of_box(lo, hi);
        let tetras = TetraTexture::new(ctx, &frame, apex, triangles)?;
        if options.batch == 0 || options.groups_per_draw == 0 {
            return Err(InclusionError::Options("batch and groups per draw must be at least 1".into()));
        }
        let vertices = tetras.count.div_ceil(options.batch);
        let tile = tile_for(vertices);
        let max = ctx.info().max_image_2d;
        let groups = options.groups_per_draw.min((max / tile[1]).max(1)).min((MAX_POINTS / GROUP_POINTS) as u32);
        if tile[0] > max || tile[1] > max {
            return Err(InclusionError::TooLarge(format!(
                "a {}×{} phase-1 tile exceeds the device's {max}-texel textures; raise the batch size",
                tile[0], tile[1]
            )));
        }
        let options = GpuOptions { groups_per_draw: groups, ..options };
        let target = Texture::new_layered(ctx, TexFormat::Rgba32F, tile[0], tile[1] * groups, LAYERS, "phase 1")?;
        let reducer = match options.phase2 {
            Phase2::Gpu => Some(Reducer::new(ctx, tile[0], tile[1] * groups, LAYERS)?),
            Phase2::Host => None,
        };
        let pipeline = Pipeline::new(
            ctx,
            &PipelineDesc {
                vertex: &shaders::inclusion::CLASSIFY_VERT,
                fragment: &shaders::inclusion::CLASSIFY_FRAG,
                topology: Topology::Points,
                targets: &[TexFormat::Rgba32F; LAYERS as usize],
                blend: Blend::Replace,
                per_instance: &[],
            },
        )?;
        let name = match options.phase2 {
            Phase2::Gpu => "gpu",
            Phase2::Host => "cpu+gpu",
        };
        Ok(GpuInclusion {
            ctx: ctx.clone(),
            frame,
            lo,
            hi,
            tetras,
            pipeline,
            options,
            tile,
            target,
            reducer,
            exact,
            name,
            stats: Default::default(),
        })
    }

    /// Classifies every point; statistics of the call land in `stats`.
    pub fn try_classify_all(&mut self, points: &[DVec3]) -> Result<Vec<Class>> {
        let mut stats = GpuStats::default();
        let mut out = vec![Class::Outside; points.len()];
        let inside_box: Vec<usize> = (0..points.len())
            .filter(|&i| {
                let p = points[i];
                p.cmpge(self.lo).all() && p.cmple(self.hi).all()
            })
            .collect();
        stats.gpu_points = inside_box.len();
        let per_submit = MAX_POINTS.min(GROUP_POINTS * self.options.groups_per_draw as usize);
        let mut flagged = Vec::new();
        for chunk in inside_box.chunks(per_submit) {
            let chunk_points: Vec<DVec3> = chunk.iter().map(|&i| points[i]).collect();
            let sums = self.run_chunk(&chunk_points, &mut stats)?;
            let t = Instant::now();
            for (k, &i) in chunk.iter().enumerate() {
                match decode(sums[k]) {
                    Some(c) => out[i] = c,
                    None => flagged.push(i),
                }
            }
            stats.host += t.elapsed();
        }
        let t = Instant::now();
        stats.flagged = flagged.len();
        for i in flagged {
            out[i] = self.exact.classify(points[i]);
        }
        stats.fallback = t.elapsed();
        if let Ok(mut s) = self.stats.lock() {
            *s = stats;
        }
        Ok(out)
    }

    /// One submission: up to `groups_per_draw` groups of 32 points; returns one sum per point.
    fn run_chunk(&mut self, points: &[DVec3], stats: &mut GpuStats) -> Result<Vec<f32>> {
        let groups = points.len().div_ceil(GROUP_POINTS) as u32;
        let ubo = Buffer::with_data(&self.ctx, &point_block(&self.frame, points), "query points")?;
        let [tw, th] = self.tile;
        let size = [tw, th * self.options.groups_per_draw];
        let vertices = self.tetras.count.div_ceil(self.options.batch);
        let push = params(size, th, 0, self.options.batch, &self.tetras, 0);
        let t = Instant::now();
        let attachments: Vec<Attachment> = (0..LAYERS).map(|l| Attachment::layer(&self.target, l, Load::Zero)).collect();
        let reads = [&self.tetras.texture];
        let (pipeline, target, tetras) = (&self.pipeline, &self.target, &self.tetras.texture);
        let reducer = &mut self.reducer;
        let readback = self.ctx.submit(|rec| {
            rec.render(&attachments, Some([0, 0, size[0], th * groups]), &reads, |pass| {
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
        let per_layer = match self.options.phase2 {
            Phase2::Gpu => groups as usize,
            Phase2::Host => (tw * th * groups) as usize,
        };
        let tile_texels = (tw * th) as usize;
        let mut sums = vec![0.0f32; points.len()];
        for (k, sum) in sums.iter_mut().enumerate() {
            let (g, slot) = (k / GROUP_POINTS, k % GROUP_POINTS);
            let (layer, channel) = (slot / 4, slot % 4);
            let base = layer * per_layer;
            *sum = match self.options.phase2 {
                Phase2::Gpu => texels[base + g][channel],
                // The thesis' CPU+GPU: phase 2 as a plain loop over the group's tile.
                Phase2::Host => texels[base + g * tile_texels..base + (g + 1) * tile_texels].iter().map(|t| t[channel]).sum(),
            };
        }
        stats.host += t.elapsed();
        Ok(sums)
    }
}

impl Classifier for GpuInclusion {
    fn name(&self) -> &str {
        self.name
    }

    fn classify(&self, p: DVec3) -> Class {
        self.exact.classify(p)
    }
}

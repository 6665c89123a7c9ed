//! Catmull-Clark on the GPU with fragment meshes (2010 thesis §3.3, SPEC §5.3): the base
//! level and the fragments on the CPU, then one full-target fragment pass per level,
//! ping-ponging between two RGBA32F render targets, one readback, and the topological
//! assembly on the CPU. Sharp features run in the same pass: a sharp
//! fragment's vertex entries each have a data texel (its sharpness and that of its edges,
//! `fragment`), which the pass reads to apply OpenSubdiv's crease rules and writes,
//! decayed, for the next level — one target, one shader source, one pass per level.
//!
//! # Shader variants
//!
//! lavapipe executes every branch of a shader for every texel (its SIMD lanes run under
//! masks), so rules a texel does not need would still cost it: with one shader, sharp
//! rules made smooth fragments 3× slower. `glsl/subdiv/refine.glsl` is therefore compiled
//! into variants — smooth positions, sharp positions (uniform or Chaikin creasing), data
//! texels (uniform or Chaikin) — and each pass draws, in one render pass, the row ranges of
//! its output stream that need each: runs without input data (first in the stream), the
//! other runs' positions, and the data block (which starts on a row of its own). Every
//! sharp variant also computes smooth texels exactly ([`Options::single_shader`] draws all
//! positions with it).
//!
//! # Packing rule
//!
//! The thesis stores one fragment per texture row. Here fragments are sorted into runs
//! of one class (valence k, closed or half-fan) and stored back to back, each in the
//! thesis' order (centre, then ring by ring), as one 1D stream of texels; the stream is
//! wrapped into rows of W = 2^n texels (W ≈ √texels, at most the device's 2D limit), so
//! a fragment may continue on the next row. Each level has its own stream (fragments
//! grow from ring radius 2 to 3, 5, 9, …; the last level keeps only the 2^j owned rings);
//! the pass finds a texel's run by binary search in a uniform table of run starts and its
//! fragment by division. Runs also group fragments by how many levels they carry
//! sharpness data (their *horizon*), smallest horizon first; after all positions, from
//! the next row on, come the data texels of the runs that carry them, in the same order.
//!
//! # Limits
//!
//! No limit on valence from the row width: a fragment of any valence spans as many rows
//! as it needs (the "row split"). What does limit the path, each with a clear
//! [`SubdivError::GpuLimit`] (use the CPU method then):
//!
//! - at most [`MAX_RUNS`] classes (distinct valence, half-fan and horizon) per mesh;
//! - one fragment at most 2^24 texels at the last level (the shader's exact float
//!   division), i.e. k·R(R+1) < 2^24 at the last radius R = 2^j: valence below 61 680 at
//!   level 5 of a quad mesh (R = 16), below 4 032 at level 7 (R = 64);
//! - every stream at most W × H texels with W, H ≤ `maxImageDimension2D` and
//!   below 2^28 texels (16384² on lavapipe, 4 GiB per target).

use std::time::{Duration, Instant};

use glam::DVec3;

use crate::gpu::{
    Attachment, Blend, Buffer, Context, Load, PingPong, Pipeline, TexFormat, Timestamps, shaders,
};
use crate::mesh::Mesh;

use super::assemble::assemble;
use super::cpu::SharpEdge;
use super::crease::Method;
use super::fragment::{self, Built, FragmentMesh, StreamLayout};
use super::{Result, SubdivError, Surface, cpu};

/// Entries of the run table (`MAX_RUNS` in `glsl/subdiv/refine.frag`).
pub const MAX_RUNS: usize = 256;
/// Largest fragment, in texels (the shader's float division is exact below 2^24).
pub const MAX_FRAGMENT_TEXELS: u64 = 1 << 24;
/// Largest stream, in texels (texel indices stay far from `i32` overflow).
pub const MAX_STREAM_TEXELS: u64 = 1 << 28;

/// Where every level's stream lies in the two textures (see the module docs).
#[derive(Clone, Debug)]
pub struct Packing {
    /// Row width, a power of two.
    pub width: u32,
    pub log2_width: u32,
    /// Rows of the two targets (enough for the largest stream).
    pub height: u32,
    /// One layout per level, base level first.
    pub layouts: Vec<StreamLayout>,
}

impl Packing {
    /// Packs the streams of `fragments` for `gpu_levels` passes on a device whose 2D
    /// textures are at most `max_side` texels wide and high. `row_width` forces the row
    /// width (a power of two), e.g. to make fragments span rows.
    pub fn new(
        fragments: &FragmentMesh,
        gpu_levels: u32,
        max_side: u32,
        row_width: Option<u32>,
    ) -> Result<Packing> {
        if fragments.runs().len() > MAX_RUNS {
            return Err(SubdivError::GpuLimit(format!(
                "{} fragment classes (distinct valences); the pass handles at most {MAX_RUNS}",
                fragments.runs().len()
            )));
        }
        let unaligned: Vec<StreamLayout> =
            (0..=gpu_levels).map(|j| fragments.layout(j, gpu_levels, 1)).collect();
        let texels = unaligned.iter().map(|l| l.total).max().unwrap_or(0).max(1);
        // The largest fragment of any stream.
        let widest = unaligned
            .iter()
            .flat_map(|l| fragments.runs().iter().map(move |run| (run, l.radius, run.class.len(l.radius))))
            .max_by_key(|&(_, _, texels)| texels);
        if let Some((run, radius, texels)) = widest
            && texels >= MAX_FRAGMENT_TEXELS
        {
            return Err(SubdivError::GpuLimit(format!(
                "a fragment of valence {} at ring radius {radius} ({gpu_levels} fragment levels) needs {texels} \
                 texels, over the pass's {MAX_FRAGMENT_TEXELS}; use fewer levels or the CPU method",
                run.class.valence
            )));
        }
        let max_width = if max_side == 0 { 1 } else { 1u32 << max_side.ilog2() };
        let width = match row_width {
            Some(w) if w.is_power_of_two() && w <= max_width => w,
            Some(w) => {
                return Err(SubdivError::GpuLimit(format!(
                    "row width {w} is not a power of two up to {max_width}"
                )));
            }
            None => {
                ((texels as f64).sqrt().ceil() as u64).next_power_of_two().clamp(64, u64::from(max_width))
                    as u32
            }
        };
        // Data blocks start on a row of their own (one draw each, see the module docs).
        let layouts: Vec<StreamLayout> =
            (0..=gpu_levels).map(|j| fragments.layout(j, gpu_levels, u64::from(width))).collect();
        let texels = layouts.iter().map(|l| l.total).max().unwrap_or(0).max(1);
        let height = texels.div_ceil(u64::from(width));
        if texels > MAX_STREAM_TEXELS || height > u64::from(max_side) {
            return Err(SubdivError::GpuLimit(format!(
                "{texels} texels per level do not fit a {width}-wide texture of at most {max_side} rows \
                 (nor {MAX_STREAM_TEXELS} texels); use fewer levels or the CPU method"
            )));
        }
        Ok(Packing { width, log2_width: width.ilog2(), height: height as u32, layouts })
    }

    /// Rows holding the stream of level `j`.
    pub fn rows(&self, j: usize) -> u32 {
        self.layouts[j].total.div_ceil(u64::from(self.width)).max(1) as u32
    }
}

/// Options of the GPU path.
#[derive(Clone, Copy, Debug, Default)]
pub struct Options {
    /// Force the texture row width (a power of two); default ≈ √texels.
    pub row_width: Option<u32>,
    /// Draw every run with the sharp shader variant, not only the runs with sharpness
    /// data (what a GPU that skips untaken branches would do; slower on lavapipe).
    pub single_shader: bool,
}

/// Where the time of one GPU subdivision went.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Times {
    /// CPU levels up to the base level (one or two Catmull-Clark levels).
    #[serde(rename = "base_ms", serialize_with = "crate::json::ms")]
    pub base: Duration,
    /// Cutting the base level into fragments and writing their texel stream.
    #[serde(rename = "fragments_ms", serialize_with = "crate::json::ms")]
    pub fragments: Duration,
    /// GPU: copying the base stream into the first target (timestamps).
    #[serde(rename = "upload_ms", serialize_with = "crate::json::ms")]
    pub upload: Duration,
    /// GPU: each fragment pass (timestamps).
    #[serde(rename = "passes_ms", serialize_with = "crate::json::ms_list")]
    pub passes: Vec<Duration>,
    /// GPU: copying the last stream into host memory (timestamps).
    #[serde(rename = "readback_ms", serialize_with = "crate::json::ms")]
    pub readback: Duration,
    /// Wall time of the one submission (staging, upload, passes, readback, waiting).
    #[serde(rename = "submit_ms", serialize_with = "crate::json::ms")]
    pub submit: Duration,
    /// Discarding support rings and welding the result (CPU).
    #[serde(rename = "assembly_ms", serialize_with = "crate::json::ms")]
    pub assembly: Duration,
    /// Everything, wall clock.
    #[serde(rename = "total_ms", serialize_with = "crate::json::ms")]
    pub total: Duration,
}

impl Times {
    pub fn passes_total(&self) -> Duration {
        self.passes.iter().sum()
    }
}

/// What one GPU subdivision did (`subdivide --json`: the counts and times, ms).
#[derive(Debug, serde::Serialize)]
pub struct Run {
    #[serde(skip)]
    pub mesh: Mesh,
    /// The refined edges on sharp control edges (creases, boundary, non-manifold edges),
    /// numbered as `mesh`'s vertices: what a renderer draws over the surface.
    #[serde(skip)]
    pub sharp_edges: Vec<SharpEdge>,
    /// Catmull-Clark levels done on the CPU and by fragment passes on the GPU.
    pub cpu_levels: u32,
    pub gpu_levels: u32,
    pub fragments: usize,
    /// Fragments carrying sharpness data (sharp features in reach, or a border).
    pub sharp_fragments: usize,
    /// Distinct fragment runs (valence, half-fan, horizon).
    pub classes: usize,
    /// Why the CPU did more levels than the minimum the fragments need (see
    /// [`FragmentMesh::reasons`]); empty when it did not.
    pub cpu_reasons: Vec<String>,
    /// Size of each of the two targets, texels.
    pub texture: [u32; 2],
    pub times: Times,
}

/// The fragment pass (`glsl/subdiv/refine.glsl`: its sharp and smooth variants) with its
/// two render targets and its readback buffer, built once and reused: like a texture-era
/// application, which allocates its FBO textures once, not per frame. Targets grow when a
/// mesh needs more.
pub struct Subdivider {
    smooth: Pipeline,
    /// The sharp variants, positions and data: uniform, then Chaikin creasing.
    sharp: [Pipeline; 2],
    data: [Pipeline; 2],
    targets: Option<PingPong>,
    readback: Option<Buffer>,
}

impl Subdivider {
    pub fn new(ctx: &Context) -> Result<Subdivider> {
        let quad = |shader| Pipeline::quad(ctx, shader, &[TexFormat::Rgba32F], Blend::Replace);
        let smooth = quad(&shaders::subdiv::REFINE_SMOOTH_FRAG)?;
        let sharp = [quad(&shaders::subdiv::REFINE_FRAG)?, quad(&shaders::subdiv::REFINE_CHAIKIN_FRAG)?];
        let data =
            [quad(&shaders::subdiv::REFINE_DATA_FRAG)?, quad(&shaders::subdiv::REFINE_DATA_CHAIKIN_FRAG)?];
        Ok(Subdivider { smooth, sharp, data, targets: None, readback: None })
    }

    /// Refines `mesh` (smooth, default options) `level` times; see
    /// [`Subdivider::refine_surface`].
    pub fn refine(&mut self, ctx: &Context, mesh: &Mesh, level: u32, options: &Options) -> Result<Run> {
        self.refine_surface(ctx, &Surface::smooth(mesh.clone()), level, options)
    }

    /// Refines `surface` `level` times: the base level on the CPU, the rest as fragment
    /// passes on the GPU. Levels below the base level (level 0, or level 1 of a mesh with
    /// non-quads) have no fragments and are computed on the CPU (`gpu_levels` = 0), and so
    /// are levels the fragments cannot express ([`Run::cpu_reasons`]).
    pub fn refine_surface(
        &mut self,
        ctx: &Context,
        surface: &Surface,
        level: u32,
        options: &Options,
    ) -> Result<Run> {
        let start = Instant::now();
        let fragments = match FragmentMesh::build(surface, level)? {
            Built::Fragments(f) => f,
            Built::Cpu(cpu_reasons) => {
                let refined = cpu::refine_surface(surface, level)?;
                let total = start.elapsed();
                let times = Times { base: total, total, ..Times::default() };
                return Ok(Run {
                    mesh: refined.mesh,
                    sharp_edges: refined.sharp_edges,
                    cpu_levels: level,
                    gpu_levels: 0,
                    fragments: 0,
                    sharp_fragments: 0,
                    classes: 0,
                    cpu_reasons,
                    texture: [0, 0],
                    times,
                });
            }
        };
        // The base level and the fragments are built together; the fragment build is
        // timed again (stream and tables) in `refine_fragments`.
        let base_time = start.elapsed();
        let t = Instant::now();
        let mut run = self.refine_fragments(ctx, &fragments, level - fragments.cpu_levels(), options, t)?;
        run.times.base = base_time;
        run.times.total = start.elapsed();
        Ok(run)
    }

    /// Render targets of at least `width` × `height` texels and a readback buffer of at
    /// least `readback_bytes`, kept from earlier runs when they are large enough.
    fn reserve(&mut self, ctx: &Context, width: u32, height: u32, readback_bytes: u64) -> Result<()> {
        if !self.targets.as_ref().is_some_and(|t| t.width() == width && t.height() >= height) {
            self.targets = None;
            self.targets = Some(PingPong::new(ctx, TexFormat::Rgba32F, width, height, "subdiv")?);
        }
        if self.readback.as_ref().is_none_or(|b| b.size() < readback_bytes) {
            self.readback = None;
            self.readback = Some(Buffer::readback_for(ctx, readback_bytes)?);
        }
        Ok(())
    }

    /// Runs `gpu_levels` fragment passes over `fragments` and assembles the result.
    /// `fragments_started` is when fragment building began (for [`Times::fragments`]).
    pub fn refine_fragments(
        &mut self,
        ctx: &Context,
        fragments: &FragmentMesh,
        gpu_levels: u32,
        options: &Options,
        fragments_started: Instant,
    ) -> Result<Run> {
        let packing = Packing::new(fragments, gpu_levels, ctx.info().max_image_2d, options.row_width)?;
        let width = packing.width;
        let mut stream = fragments.base_stream(
            gpu_levels,
            u64::from(width),
            |p| [p.x as f32, p.y as f32, p.z as f32, 1.0],
            |d| d,
        );
        let rows0 = packing.rows(0);
        stream.resize((rows0 * width) as usize, [0.0; 4]);
        let tables = run_tables(ctx, fragments, &packing)?;
        let fragments_time = fragments_started.elapsed();

        let last = packing.layouts.len() - 1;
        let readback_bytes = u64::from(width) * u64::from(packing.rows(last)) * 16;
        self.reserve(ctx, width, packing.height, readback_bytes)?;
        let (Some(targets), Some(readback)) = (self.targets.as_mut(), self.readback.as_ref()) else {
            return Err(SubdivError::GpuLimit("render targets were not created".into()));
        };
        let chaikin = usize::from(fragments.crease_method() == Method::Chaikin);
        let (smooth, sharp, data) = (&self.smooth, &self.sharp[chaikin], &self.data[chaikin]);
        let timer = Timestamps::new(ctx, gpu_levels + 3)?;
        let draws = draw_ranges(&packing, gpu_levels, options, [smooth, sharp, data]);
        let t = Instant::now();
        ctx.submit(|rec| {
            rec.reset_timestamps(&timer);
            rec.timestamp(&timer, 0)?;
            rec.upload_region(targets.src(), 0, [0, 0, width, rows0], &stream)?;
            rec.timestamp(&timer, 1)?;
            for (j, table) in tables.iter().enumerate() {
                let (lin, lout) = (&packing.layouts[j], &packing.layouts[j + 1]);
                let params = [
                    lin.radius as i32,
                    lout.radius as i32,
                    fragments.runs().len() as i32,
                    lout.positions as i32,
                    lout.total as i32,
                    packing.log2_width as i32,
                ];
                let input = targets.src();
                let reads = [input];
                let area = [0, 0, width, packing.rows(j + 1)];
                rec.render(&[Attachment::new(targets.dst(), Load::Discard)], Some(area), &reads, |pass| {
                    for &(pipeline, first, count) in &draws[j] {
                        if count == 0 {
                            continue;
                        }
                        pass.bind(pipeline)?;
                        pass.viewport([0, first, width, count]);
                        pass.textures(&[(0, input)])?;
                        pass.uniform(1, table)?;
                        pass.push(&params)?;
                        pass.quad()?;
                    }
                    Ok(())
                })?;
                targets.swap();
                rec.timestamp(&timer, 2 + j as u32)?;
            }
            rec.readback_into(targets.src(), 0..1, [0, 0, width, packing.rows(last)], readback, 0)?;
            rec.timestamp(&timer, gpu_levels + 2)?;
            Ok(())
        })?;
        let submit = t.elapsed();
        let stamps = timer.read_ms(gpu_levels + 3)?;
        let ms = |a: usize, b: usize| Duration::from_secs_f64(((stamps[b] - stamps[a]) / 1e3).max(0.0));

        let t = Instant::now();
        let texels = readback.view::<[f32; 4]>()?;
        let mesh = assemble(fragments, texels, gpu_levels, |p| {
            DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
        })?;
        let sharp_edges = fragment::sharp_edges(fragments, gpu_levels);
        let times = Times {
            fragments: fragments_time,
            upload: ms(0, 1),
            passes: (0..gpu_levels as usize).map(|j| ms(1 + j, 2 + j)).collect(),
            readback: ms(1 + gpu_levels as usize, 2 + gpu_levels as usize),
            submit,
            assembly: t.elapsed(),
            ..Times::default()
        };
        Ok(Run {
            mesh,
            sharp_edges,
            cpu_levels: fragments.cpu_levels(),
            gpu_levels,
            fragments: fragments.fragments().len(),
            sharp_fragments: fragments.sharp_fragments(),
            classes: fragments.runs().len(),
            cpu_reasons: fragments.reasons().to_vec(),
            texture: [width, packing.height],
            times,
        })
    }
}

/// One run table per pass: (valence, flags, first input texel, first output texel),
/// flags 1 half-fan, 2 data in the input, 4 in the output; then (first input data texel,
/// first output data texel or -1, 0, 0).
fn run_tables(ctx: &Context, fragments: &FragmentMesh, packing: &Packing) -> Result<Vec<Buffer>> {
    let tables = packing
        .layouts
        .windows(2)
        .map(|pair| {
            let (lin, lout) = (&pair[0], &pair[1]);
            let mut table = vec![[0i32; 4]; 2 * MAX_RUNS];
            for (r, run) in fragments.runs().iter().enumerate() {
                let c = run.class;
                let flags =
                    i32::from(c.boundary) | i32::from(lin.data[r]) << 1 | i32::from(lout.data[r]) << 2;
                table[r] = [c.valence as i32, flags, lin.starts[r] as i32, lout.starts[r] as i32];
                table[MAX_RUNS + r] = [
                    if lin.data[r] { lin.data_starts[r] as i32 } else { 0 },
                    if lout.data[r] { lout.data_starts[r] as i32 } else { -1 },
                    0,
                    0,
                ];
            }
            Buffer::with_data(ctx, &table, "subdiv runs")
        })
        .collect::<std::result::Result<Vec<_>, _>>()?;
    Ok(tables)
}

/// The row ranges of each output stream and the variant (`[smooth, sharp, data]`) that
/// draws each: the runs without input data (first: runs are sorted by horizon,
/// `fragment`) with the smooth variant, the other positions with the sharp one, the data
/// block with the data one.
fn draw_ranges<'p>(
    packing: &Packing,
    gpu_levels: u32,
    options: &Options,
    [smooth, sharp, data]: [&'p Pipeline; 3],
) -> Vec<[(&'p Pipeline, u32, u32); 3]> {
    let w = u64::from(packing.width);
    (0..gpu_levels as usize)
        .map(|j| {
            let (lin, lout) = (&packing.layouts[j], &packing.layouts[j + 1]);
            let position_rows = lout.positions.div_ceil(w) as u32;
            let first_sharp = lin.data.iter().position(|&d| d);
            let split = match first_sharp {
                _ if options.single_shader => 0,
                Some(r) => (lout.starts[r] / w) as u32,
                None => position_rows,
            };
            let data_row = (lout.data_start / w) as u32;
            let data_rows = if lout.data.contains(&true) { packing.rows(j + 1) - data_row } else { 0 };
            [(smooth, 0, split), (sharp, split, position_rows - split), (data, data_row, data_rows)]
        })
        .collect()
}

/// Refines `mesh` `level` times on the GPU with a fresh pipeline and targets (see
/// [`Subdivider`]).
pub fn refine(ctx: &Context, mesh: &Mesh, level: u32) -> Result<Mesh> {
    Ok(Subdivider::new(ctx)?.refine(ctx, mesh, level, &Options::default())?.mesh)
}

/// Refines `surface` `level` times on the GPU with a fresh pipeline and targets.
pub fn refine_surface(ctx: &Context, surface: &Surface, level: u32) -> Result<Run> {
    Subdivider::new(ctx)?.refine_surface(ctx, surface, level, &Options::default())
}

//! `texgeo bench subdivide`: the 2010 thesis' Table 5 (§3.4) on today's machine — every
//! model to level 5: the CPU base level (TCPU¹), the GPU fragment levels (TGPU), the
//! whole refinement on the CPU (TCPU²) — plus OpenSubdiv's own refine + interpolate time,
//! where the GPU path's time goes, and the thesis' numbers (`reference/subdiv/table5.csv`).

use std::path::Path;
use std::time::{Duration, Instant};

use crate::gpu::Context;
use crate::mesh::spec::MeshSpec;
use crate::mesh::{Mesh, formats, procedural};
use crate::report::{Environment, Log, Progress, Report, Samples, Table, interleave};
use crate::subdiv::compare::Comparison;
use crate::subdiv::gpu::{Options, Run, Subdivider, Times};
use crate::subdiv::{Result, cpu, osd};

/// The thesis' Table 5 (see `reference/subdiv/README.md`).
pub const THESIS_TABLE5: &str = include_str!("../../../reference/subdiv/table5.csv");

/// Built-in models measured by default (closed, manifold ones).
pub const BUILTINS: &[&str] = &["cube", "tetrahedron", "pyramid", "sphere", "torus", "knot"];

/// Fetched models measured when present in the models folder (`tools/fetch-models`).
pub const FETCHED: &[&str] = &["knot1.off"];

/// A model to measure: a name for the table and its mesh.
pub struct Model {
    pub name: String,
    pub mesh: Mesh,
}

/// The default models: [`BUILTINS`], then [`FETCHED`] found in `models_dir`.
pub fn default_models(models_dir: &Path) -> Result<Vec<Model>> {
    let mut models: Vec<Model> = BUILTINS
        .iter()
        .filter_map(|&n| procedural::by_name(n).map(|mesh| Model { name: format!("builtin:{n}"), mesh }))
        .collect();
    for file in FETCHED {
        let path = models_dir.join(file);
        if path.is_file() {
            models.push(Model { name: path.display().to_string(), mesh: formats::read(&path)? });
        }
    }
    Ok(models)
}

/// What to measure.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// Subdivision level (Table 5: 5).
    pub level: u32,
    /// Timed runs per measurement; medians are reported.
    pub runs: usize,
    /// Also compare each GPU result with OpenSubdiv's (slow on millions of faces).
    pub validate: bool,
}

/// Median of each component of the GPU path's times.
fn median_times(all: &[Times]) -> Times {
    let median = |f: &dyn Fn(&Times) -> Duration| Samples(all.iter().map(f).collect()).median();
    let passes = all.first().map_or(0, |t| t.passes.len());
    Times {
        base: median(&|t| t.base),
        fragments: median(&|t| t.fragments),
        upload: median(&|t| t.upload),
        passes: (0..passes).map(|j| median(&|t| t.passes[j])).collect(),
        readback: median(&|t| t.readback),
        submit: median(&|t| t.submit),
        assembly: median(&|t| t.assembly),
        total: median(&|t| t.total),
    }
}

/// Milliseconds with about three significant digits.
pub fn ms(d: Duration) -> String {
    let v = d.as_secs_f64() * 1e3;
    if v < 1.0 {
        format!("{v:.3}")
    } else if v < 10.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.1}")
    }
}

/// texgeo's speed target: the GPU path at most half of OpenSubdiv's time on knot1.off.
const SPEED_TARGET: f64 = 0.5;

/// One model refined to `Settings::level`.
pub struct Measured {
    pub name: String,
    pub input_faces: usize,
    pub fragments: usize,
    pub faces: usize,
    pub vertices: usize,
    /// Fragment passes the GPU ran (one per GPU level) and GPU levels.
    pub passes: usize,
    pub gpu_levels: u32,
    pub texture: [u32; 2],
    /// Medians of the GPU path's parts, and every run's total.
    pub gpu: Times,
    pub gpu_totals: Samples,
    /// The first run on a fresh pipeline.
    pub cold: Duration,
    /// texgeo's f64 CPU reference (TCPU²).
    pub cpu: Samples,
    /// OpenSubdiv: the minimum and median of refine + interpolate, seconds.
    pub osd: (f64, f64),
    /// OpenSubdiv's every run, interleaved with `gpu_totals` and `cpu`.
    pub osd_runs: Samples,
    /// How the GPU result compares with OpenSubdiv's.
    pub verdict: Agreement,
    /// The largest distance from OpenSubdiv's vertices over the bounding box's diagonal,
    /// when they match.
    pub max_error: Option<f64>,
}

/// The GPU result against OpenSubdiv's, vertex by vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Agreement {
    /// Equal within the tolerance on every vertex and face.
    Match,
    Mismatch,
    /// Not compared.
    NotChecked,
}

impl std::fmt::Display for Agreement {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Agreement::Match => "match",
            Agreement::Mismatch => "MISMATCH",
            Agreement::NotChecked => "not checked",
        })
    }
}

/// Steps [`measure`] reports.
pub fn steps(models: usize) -> u64 {
    3 * models as u64
}

/// Refines every model on the GPU, on the CPU and with OpenSubdiv (Table 5).
pub fn measure(
    ctx: &Context,
    models: &[Model],
    settings: Settings,
    progress: &mut dyn Progress,
) -> Result<Vec<Measured>> {
    progress.total(steps(models.len()));
    let level = settings.level;
    let mut out = Vec::new();
    for model in models {
        let mesh = &model.mesh;
        progress.step(&format!("{}: GPU fragment passes", model.name));
        // Cold: a fresh pipeline and targets (JIT compilation, first-touch allocation).
        let start = Instant::now();
        let mut subdivider = Subdivider::new(ctx)?;
        let first = subdivider.refine(ctx, mesh, level, &Options::default())?;
        let cold = start.elapsed();
        // The GPU path, the CPU reference and OpenSubdiv in turn, run after run: load
        // that comes and goes hits all three alike, and their ratios can be taken run by
        // run.
        progress.step(&format!("{}: GPU path, CPU reference and OpenSubdiv in turn", model.name));
        let mut times = Vec::new();
        let mut last: Option<Run> = None;
        let samples = interleave(
            settings.runs,
            &mut [
                &mut || -> Result<Duration> {
                    let run = subdivider.refine(ctx, mesh, level, &Options::default())?;
                    let total = run.times.total;
                    times.push(run.times.clone());
                    last = Some(run);
                    Ok(total)
                },
                &mut || -> Result<Duration> { cpu_once(mesh, level) },
                &mut || -> Result<Duration> { osd_once(mesh, level) },
            ],
        )?;
        let [gpu_totals, cpu, osd_runs]: [Samples; 3] =
            samples.try_into().unwrap_or_else(|_| unreachable!("three sides"));
        times.remove(0); // the warm-up run
        let gpu = median_times(&times);
        let run = last.unwrap_or(first);
        progress.step(&format!("{}: compared with OpenSubdiv", model.name));
        let osd_times = (osd_runs.min().as_secs_f64(), osd_runs.median().as_secs_f64());
        let (verdict, max_error) = if settings.validate {
            let c = Comparison::new(&run.mesh, &osd::refine(mesh, level)?, 1e-5);
            if c.is_match() {
                (Agreement::Match, Some(c.max_error / c.diagonal.max(f64::MIN_POSITIVE)))
            } else {
                (Agreement::Mismatch, None)
            }
        } else {
            (Agreement::NotChecked, None)
        };
        out.push(Measured {
            name: model.name.clone(),
            input_faces: mesh.num_faces(),
            fragments: run.fragments,
            faces: run.mesh.num_faces(),
            vertices: run.mesh.num_vertices(),
            passes: gpu.passes.len(),
            gpu_levels: run.gpu_levels,
            texture: run.texture,
            gpu,
            gpu_totals,
            cold,
            cpu,
            osd: osd_times,
            osd_runs,
            verdict,
            max_error,
        });
    }
    Ok(out)
}

/// One timed OpenSubdiv refine + interpolate, as the helper measured it (no output
/// written; the helper's start is not counted).
/// One timed run of the CPU reference.
fn cpu_once(mesh: &Mesh, level: u32) -> Result<Duration> {
    let start = Instant::now();
    cpu::refine(mesh, level)?;
    Ok(start.elapsed())
}

fn osd_once(mesh: &Mesh, level: u32) -> Result<Duration> {
    let options = osd::Options { repeat: Some(1), no_output: true, ..Default::default() };
    let timed = osd::run(&crate::subdiv::Surface::smooth(mesh.clone()), level, &options)?;
    timed.min_seconds.map(Duration::from_secs_f64).ok_or_else(|| crate::subdiv::SubdivError::Helper {
        path: "osd-refine".into(),
        message: "no timing was printed".into(),
    })
}

/// One level of [`per_level`].
pub struct LevelTimes {
    pub level: u32,
    /// GPU fragment levels in the GPU path at this level (0: the CPU did all of it).
    pub gpu_levels: u32,
    pub faces: usize,
    pub gpu: Samples,
    pub cpu: Samples,
    /// OpenSubdiv's minimum and median, seconds.
    pub osd: (f64, f64),
    /// OpenSubdiv's every run, interleaved with `gpu` and `cpu`.
    pub osd_runs: Samples,
}

/// The GPU path, the CPU reference and OpenSubdiv at each level of `levels`: where the
/// GPU starts to win.
pub fn per_level(
    ctx: &Context,
    mesh: &Mesh,
    levels: std::ops::RangeInclusive<u32>,
    runs: usize,
    progress: &mut dyn Progress,
) -> Result<Vec<LevelTimes>> {
    let mut subdivider = Subdivider::new(ctx)?;
    let mut out = Vec::new();
    for level in levels {
        progress.step(&format!("level {level}"));
        let mut faces = 0;
        let mut gpu_levels = 0;
        let samples = interleave(
            runs,
            &mut [
                &mut || -> Result<Duration> {
                    let run = subdivider.refine(ctx, mesh, level, &Options::default())?;
                    faces = run.mesh.num_faces();
                    gpu_levels = run.gpu_levels;
                    Ok(run.times.total)
                },
                &mut || -> Result<Duration> { cpu_once(mesh, level) },
                &mut || -> Result<Duration> { osd_once(mesh, level) },
            ],
        )?;
        let [gpu, cpu, osd_runs]: [Samples; 3] =
            samples.try_into().unwrap_or_else(|_| unreachable!("three sides"));
        let osd = (osd_runs.min().as_secs_f64(), osd_runs.median().as_secs_f64());
        out.push(LevelTimes { level, gpu_levels, faces, gpu, cpu, osd, osd_runs });
    }
    Ok(out)
}

/// `texgeo bench subdivide`: [`measure`] and [`report`].
pub fn run(ctx: &Context, models: &[Model], settings: Settings) -> Result<Report> {
    let measured = measure(ctx, models, settings, &mut Log("bench subdivide"))?;
    Ok(report(&measured, settings, Environment::new(ctx.info().label())))
}

/// Table 5 today, where the GPU path's time goes, and the thesis' Table 5.
pub fn report(measured: &[Measured], settings: Settings, environment: Environment) -> Report {
    let level = settings.level;
    let mut table5 = Table::new(
        format!("Table 5 today: level {level}, medians (ms)"),
        &[
            "model",
            "input faces",
            "fragments",
            "faces",
            "vertices",
            "TCPU¹ base level",
            "TGPU passes",
            "GPU path",
            "GPU path spread ± %",
            "TCPU² CPU reference",
            "TCPU² spread ± %",
            "OpenSubdiv",
            "OpenSubdiv spread ± %",
            "GPU path / OpenSubdiv",
            "vs OpenSubdiv",
            "largest distance / diagonal",
        ],
    )
    .unit("ms", [5, 6, 7, 9, 11]);
    let mut split = Table::new(
        format!("Where the GPU path's time goes: level {level}, medians (ms)"),
        &[
            "model",
            "base level (CPU)",
            "fragment build",
            "upload",
            "passes",
            "readback",
            "submission (wall)",
            "assembly",
            "GPU path",
            "first run (cold)",
            "each pass",
            "target width",
            "target height",
        ],
    )
    .unit("ms", 1..=10)
    .unit("texels", 11..=12);
    let mut targets = Vec::new();
    for m in measured {
        let gpu = &m.gpu;
        let osd_time = Duration::from_secs_f64(m.osd.1);
        let ratio = gpu.total.as_secs_f64() / m.osd.1.max(1e-9);
        if m.name.ends_with("knot1.off") {
            targets.push(format!(
                "Speed target (knot1.off, level {level}): GPU path {} ms = {ratio:.2} × OpenSubdiv's {} ms: {} \
                 (target ≤ {SPEED_TARGET}).",
                ms(gpu.total),
                ms(osd_time),
                if ratio <= SPEED_TARGET { "met" } else { "NOT met" }
            ));
        }
        table5.row(vec![
            m.name.clone(),
            m.input_faces.to_string(),
            m.fragments.to_string(),
            m.faces.to_string(),
            m.vertices.to_string(),
            ms(gpu.base),
            ms(gpu.passes_total()),
            ms(gpu.total),
            m.gpu_totals.spread_cell(),
            ms(m.cpu.median()),
            m.cpu.spread_cell(),
            ms(osd_time),
            m.osd_runs.spread_cell(),
            format!("{ratio:.2}"),
            m.verdict.to_string(),
            m.max_error.map_or("–".into(), |e| format!("{e:.1e}")),
        ]);
        let passes: Vec<String> = gpu.passes.iter().map(|&p| ms(p)).collect();
        split.row(vec![
            m.name.clone(),
            ms(gpu.base),
            ms(gpu.fragments),
            ms(gpu.upload),
            ms(gpu.passes_total()),
            ms(gpu.readback),
            ms(gpu.submit),
            ms(gpu.assembly),
            ms(gpu.total),
            ms(m.cold),
            passes.join(" + "),
            m.texture[0].to_string(),
            m.texture[1].to_string(),
        ]);
    }
    table5.note(format!(
        "{} timed runs after one warm-up; medians. TCPU¹: the CPU levels before fragments exist (1 for \
         all-quad input, 2 otherwise). TGPU: the fragment passes, GPU timestamps. GPU path: base level + \
         fragment build + one submission (upload, passes, readback) + assembly of the welded mesh, wall \
         clock, no file writing; the pipeline and render targets are made once and reused (the cold first \
         run, which pays shader compilation and allocation, is in the next table). TCPU²: texgeo's f64 CPU \
         reference, one thread. OpenSubdiv: its helper's own median of refine + interpolate (topology, \
         uniform refinement with full topology, PrimvarRefiner in double), one thread. Spread: half the range \
         of the runs as a share of the median (the three were run in turn, run after run).",
        settings.runs
    ));
    for t in targets {
        table5.note(t);
    }
    split.note(
        "Upload, passes and readback are GPU timestamps inside the one submission; the submission's wall \
         time also holds staging writes and waiting. Fragment build: cutting the base level into fragments, \
         writing their texel stream and the pass tables. Assembly: dropping the support rings and welding \
         by coarse element into a Mesh (two threads). Each pass: the passes' times in order. Targets: two \
         render targets of the width and height given (texels).",
    );
    Report { name: "subdivide".into(), environment, tables: vec![table5, split, thesis_table5()] }
}

/// The thesis' Table 5, from `reference/subdiv/table5.csv`.
pub fn thesis_table5() -> Table {
    let mut table = Table::new(
        "Table 5 in the 2010 thesis: level 5 (seconds)",
        &["fragments", "faces", "vertices", "TCPU¹", "TGPU", "TCPU² (CGAL)"],
    );
    for line in THESIS_TABLE5.lines().skip(1).filter(|l| !l.trim().is_empty()) {
        table.row(line.split(',').map(|c| c.trim().to_string()).collect());
    }
    table.note(
        "NVIDIA GeForce 9800 GT, Pentium 4 3.0 GHz, Windows 7, Cg/OpenGL; CPU times with CGAL. The models are \
         not named in the thesis; the first row is the cube (8 fragments).",
    );
    table
}

/// texgeo's speed target for sharp features: a creased model at level 5 costs the GPU
/// path at most this much more than the same model without creases.
pub const CREASE_TARGET: f64 = 1.2;

/// Models measured by `texgeo bench subdivide --creases` by default: CGAL's CAD parts
/// `fandisk.off` (the classic test of creased subdivision) and `couplingdown.off` when
/// fetched, and the built-in torus knot, whose tube (8 sides) has a crease line along each
/// of its 8 edges.
pub const CREASE_MODELS: &[&str] = &["fandisk.off", "couplingdown.off", "builtin:knot"];

/// What the crease benchmark measures.
#[derive(Clone, Copy, Debug)]
pub struct CreaseSettings {
    pub level: u32,
    /// Timed pairs (smooth, creased) after one warm-up pair; medians are reported.
    pub runs: usize,
    /// Edges whose faces meet at more than this angle are creased.
    pub angle_degrees: f64,
    /// Sharpness values to measure, one row each (10: infinitely sharp).
    pub sharpness: &'static [f32],
}

/// The default crease models found: fetched files in `models_dir`, built-ins.
pub fn crease_models(models_dir: &Path) -> Result<Vec<Model>> {
    let mut models = Vec::new();
    for &name in CREASE_MODELS {
        let spec = MeshSpec::parse(name).in_folder(models_dir);
        if spec.file().is_none_or(Path::is_file) {
            models.push(Model { name: spec.to_string(), mesh: spec.load()? });
        }
    }
    Ok(models)
}

/// Sharp features on the GPU path: each model's feature edges creased (at each sharpness)
/// against the same model without creases, timed in alternation on the same subdivider,
/// medians of the whole GPU path and of its passes, and their ratios.
pub fn run_creases(ctx: &Context, models: &[Model], settings: CreaseSettings) -> Result<Report> {
    use crate::subdiv::{Features, Surface};
    let level = settings.level;
    let mut table = Table::new(
        format!("Sharp features on the GPU path: level {level}, creased vs without creases, medians (ms)"),
        &[
            "model",
            "faces",
            "creased edges",
            "sharpness",
            "fragments with data",
            "fragments",
            "GPU path, no creases",
            "no creases spread ± %",
            "GPU path, creased",
            "creased spread ± %",
            "ratio (median of pairs)",
            "passes, no creases",
            "passes, creased",
            "passes ratio",
            "target ≤ 1.2",
        ],
    )
    .unit("ms", [6, 8, 11, 12]);
    let mut subdivider = Subdivider::new(ctx)?;
    for model in models {
        let smooth = Surface::smooth(model.mesh.clone());
        for &sharpness in settings.sharpness {
            let features = Features::feature_edges(&model.mesh, settings.angle_degrees, sharpness);
            let creases = features.creases.len();
            let creased = Surface { features, ..smooth.clone() };
            let (mut plain, mut sharp) = (Vec::new(), Vec::new());
            let (mut ratios, mut pass_ratios) = (Vec::new(), Vec::new());
            let mut fragments = (0, 0);
            for k in 0..=settings.runs.max(1) {
                // Alternate, so that both see the same load on a shared machine; the ratio
                // is the median of the pairs' ratios.
                let a = subdivider.refine_surface(ctx, &smooth, level, &Options::default())?;
                let b = subdivider.refine_surface(ctx, &creased, level, &Options::default())?;
                fragments = (b.sharp_fragments, b.fragments);
                if k > 0 {
                    ratios.push(b.times.total.as_secs_f64() / a.times.total.as_secs_f64().max(1e-9));
                    pass_ratios.push(
                        b.times.passes_total().as_secs_f64() / a.times.passes_total().as_secs_f64().max(1e-9),
                    );
                    plain.push(a.times);
                    sharp.push(b.times);
                }
            }
            let (p, s) = (median_times(&plain), median_times(&sharp));
            let spread = |t: &[Times]| Samples(t.iter().map(|t| t.total).collect()).spread_cell();
            let median = |v: &mut Vec<f64>| {
                v.sort_by(f64::total_cmp);
                let n = v.len();
                if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) }
            };
            let (ratio, passes) = (median(&mut ratios), median(&mut pass_ratios));
            table.row(vec![
                model.name.clone(),
                model.mesh.num_faces().to_string(),
                creases.to_string(),
                if crate::subdiv::crease::is_infinite(sharpness) {
                    "∞".into()
                } else {
                    format!("{sharpness}")
                },
                fragments.0.to_string(),
                fragments.1.to_string(),
                ms(p.total),
                spread(&plain),
                ms(s.total),
                spread(&sharp),
                format!("{ratio:.2}"),
                ms(p.passes_total()),
                ms(s.passes_total()),
                format!("{passes:.2}"),
                if ratio <= CREASE_TARGET { "met".into() } else { "NOT met".into() },
            ]);
        }
    }
    table.note(format!(
        "Creased: every edge whose two faces meet at more than {}° (feature edges), at the given sharpness \
         (∞: infinitely sharp). {} timed pairs after a warm-up pair, the model without and with creases \
         alternating on the same subdivider; medians. GPU path: base level + fragment build + one submission \
         (upload, passes, readback) + assembly, wall clock; passes: GPU timestamps. Fragments with data carry \
         per-texel sharpness and are drawn with the sharp shader variant (the others with the smooth one).",
        settings.angle_degrees, settings.runs
    ));
    Ok(Report {
        name: "subdivide-creases".into(),
        environment: Environment::new(ctx.info().label()),
        tables: vec![table],
    })
}

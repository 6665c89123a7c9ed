//! `texgeo bench voxelize`: Table 5-2 of the 2006 thesis (§5.4.2) — every voxelization
//! method at 64³ … 512³ — with the thesis' seconds (`reference/voxel/table5-2.csv`) next
//! to today's medians, where the time goes (CPU preparation, draws, copies, readback,
//! exact fallback), and the speed ratios between the CPU and the GPU slicers.

use std::time::Duration;

use crate::gpu::Context;
use crate::mesh::Mesh;
use crate::report::{Environment, Log, Progress, Report, Samples, Table};
use crate::voxel::{Grid, Method, Result, Solid, Timings, VoxelError, Voxelizer};

/// The thesis' Table 5-2, as transcribed.
pub const THESIS_TABLE: &str = include_str!("../../../reference/voxel/table5-2.csv");

/// (thesis model, texgeo stand-in) pairs: built-in or under the models folder.
pub const STAND_INS: &[(&str, &str)] = &[("Torusknot", "builtin:knot"), ("Armadillo", "armadillo.off")];

pub const DEFAULT_RESOLUTIONS: &[usize] = &[64, 128, 256, 512];

/// A model to measure.
pub struct Model {
    /// Row name in Table 5-2 ("–" when the thesis has none).
    pub thesis: &'static str,
    pub name: String,
    pub mesh: Mesh,
}

pub struct Config {
    pub resolutions: Vec<usize>,
    pub methods: Vec<Method>,
    /// Timed runs per measurement (after one warm-up).
    pub runs: usize,
    /// Zone height for `zoned`.
    pub zone: crate::voxel::Zone,
}

/// The thesis' seconds for (resolution, model, method), if transcribed.
pub fn thesis_seconds(resolution: usize, model: &str, method: Method) -> Option<f64> {
    let column = match method {
        Method::Cpu => 3,
        Method::Fgpu => 4,
        Method::Pgpu => 5,
        Method::Zoned => 6,
        Method::Fang => 7,
        Method::Scanline => return None,
    };
    THESIS_TABLE.lines().skip(1).find_map(|line| {
        let cells: Vec<&str> = line.split(',').collect();
        (cells.len() > column && cells[0] == resolution.to_string() && cells[1] == model)
            .then(|| cells[column].parse().ok())
            .flatten()
    })
}

/// The parts of [`Timings`] over several runs.
#[derive(Clone, Debug, Default)]
pub struct Medians {
    pub total: Samples,
    pub prepare: Samples,
    pub draw: Samples,
    pub copy: Samples,
    pub readback: Samples,
    pub fallback: Samples,
}

impl Medians {
    fn push(&mut self, t: &Timings) {
        self.total.push(t.total);
        self.prepare.push(t.prepare);
        self.draw.push(t.draw);
        self.copy.push(t.copy);
        self.readback.push(t.readback);
        self.fallback.push(t.fallback);
    }
}

/// A method's runs so far and its last result, or why this device cannot run it.
type Timed = std::result::Result<(Medians, crate::voxel::Voxelization), String>;

/// One method at one resolution on one model.
#[derive(Clone, Debug)]
pub struct Measured {
    pub model: String,
    /// The model's row name in Table 5-2 ("–" when none).
    pub thesis: &'static str,
    pub triangles: usize,
    pub n: usize,
    pub method: Method,
    /// The timed runs, or why the method cannot run on this device.
    pub result: std::result::Result<MethodResult, String>,
}

#[derive(Clone, Debug)]
pub struct MethodResult {
    pub times: Medians,
    pub fallback_centres: u64,
    pub corrected: u64,
    pub occupied: u64,
    /// Equal, voxel for voxel, to the exact `scanline` volume.
    pub identical: bool,
}

impl Measured {
    /// Median total time, if measured.
    pub fn total(&self) -> Option<Duration> {
        self.result.as_ref().ok().map(|r| r.times.total.median())
    }
}

fn ms(d: Duration) -> String {
    format!("{:.1}", d.as_secs_f64() * 1e3)
}

/// Steps [`measure`] reports.
pub fn steps(models: usize, cfg: &Config) -> u64 {
    (models * cfg.resolutions.len() * (cfg.methods.len() + 1)) as u64
}

/// Whether an error means "this device cannot run the method" (a row to mark) rather
/// than a failure of the run.
fn unsupported(e: &VoxelError) -> bool {
    matches!(e, VoxelError::Gpu(crate::gpu::GpuError::Unsupported(_)))
}

/// Every method at every resolution on every model, each compared with `scanline`.
pub fn measure(
    ctx: &Context,
    models: &[Model],
    cfg: &Config,
    progress: &mut dyn Progress,
) -> Result<Vec<Measured>> {
    progress.total(steps(models.len(), cfg));
    let mut voxelizer = Voxelizer::new(Some(ctx.clone()));
    voxelizer.zone = cfg.zone;
    let mut out = Vec::new();
    for model in models {
        let solid = Solid::new(&model.mesh)?;
        for &n in &cfg.resolutions {
            progress.step(&format!("{} {n}³: exact reference", model.name));
            let grid = Grid::for_mesh(&model.mesh, n)?;
            let reference = voxelizer.run(&solid, &grid, Method::Scanline)?.volume;
            // Every method once untimed (a warm-up, and whether this device can run it),
            // then `runs` rounds of every method in turn: load that comes and goes hits
            // every method alike, and two methods' ratio can be taken round by round.
            let mut results: Vec<(Method, Timed)> = Vec::new();
            for &method in &cfg.methods {
                progress.step(&format!("{} {n}³: {method}", model.name));
                match voxelizer.run(&solid, &grid, method) {
                    Ok(r) => results.push((method, Ok((Medians::default(), r)))),
                    Err(e) if unsupported(&e) => results.push((method, Err(e.to_string()))),
                    Err(e) => return Err(e),
                }
            }
            for _ in 0..cfg.runs.max(1) {
                for (method, result) in &mut results {
                    if let Ok((times, last)) = result {
                        let r = voxelizer.run(&solid, &grid, *method)?;
                        times.push(&r.timings);
                        *last = r;
                    }
                }
            }
            for (method, result) in results {
                let result = result.map(|(times, r)| MethodResult {
                    times,
                    fallback_centres: r.band.candidates as u64,
                    corrected: r.band.changed as u64,
                    occupied: r.volume.count(),
                    identical: r.volume == reference,
                });
                out.push(Measured {
                    model: model.name.clone(),
                    thesis: model.thesis,
                    triangles: solid.triangles.len(),
                    n,
                    method,
                    result,
                });
            }
        }
    }
    Ok(out)
}

/// Median total time of each method of one (model, N), and that time without the
/// preparation.
type Totals = std::collections::HashMap<Method, (Duration, Duration)>;

/// The row of Table 5-2 of one measurement ("–" where the method could not run), and
/// its totals when it ran.
fn method_row(m: &Measured) -> (Vec<String>, Option<(Duration, Duration)>) {
    let (model, n) = (&m.model, m.n);
    let thesis = thesis_seconds(n, m.thesis, m.method).map_or("–".into(), |s| format!("{s}"));
    let r = match &m.result {
        Ok(r) => r,
        Err(_) => {
            let mut row = vec![model.clone(), m.triangles.to_string(), n.to_string(), m.method.to_string()];
            row.extend((0..12).map(|_| "–".to_string()));
            row.push(thesis);
            return (row, None);
        }
    };
    let total = r.times.total.median();
    let prepare = r.times.prepare.median();
    let row = vec![
        model.clone(),
        m.triangles.to_string(),
        n.to_string(),
        m.method.to_string(),
        ms(total),
        r.times.total.spread_cell(),
        ms(total.saturating_sub(prepare)),
        ms(prepare),
        ms(r.times.draw.median()),
        ms(r.times.copy.median()),
        ms(r.times.readback.median()),
        ms(r.times.fallback.median()),
        r.fallback_centres.to_string(),
        r.corrected.to_string(),
        r.occupied.to_string(),
        if r.identical { "yes".into() } else { "NO".into() },
        thesis,
    ];
    (row, Some((total, total.saturating_sub(prepare))))
}

/// The GPU/CPU ratios of one (model, N), when the CPU slicer or both GPU slicers ran.
fn ratio_row(model: &str, n: usize, totals: &Totals) -> Option<Vec<String>> {
    let get = |m: Method| totals.get(&m).copied();
    if get(Method::Cpu).is_none() && (get(Method::Pgpu).is_none() || get(Method::Zoned).is_none()) {
        return None;
    }
    let time = |m: Method, excl: bool| get(m).map_or("–".into(), |t| ms(if excl { t.1 } else { t.0 }));
    let ratio = |a: Method, b: Method, excl: bool| match (get(a), get(b)) {
        (Some(x), Some(y)) => {
            let y = if excl { y.1 } else { y.0 };
            format!("{:.2}", x.0.as_secs_f64() / y.as_secs_f64().max(1e-9))
        }
        _ => "–".into(),
    };
    Some(vec![
        model.to_string(),
        n.to_string(),
        time(Method::Cpu, false),
        time(Method::Pgpu, false),
        time(Method::Zoned, false),
        ratio(Method::Cpu, Method::Pgpu, false),
        ratio(Method::Cpu, Method::Zoned, false),
        ratio(Method::Pgpu, Method::Zoned, false),
        time(Method::Zoned, true),
        ratio(Method::Cpu, Method::Zoned, true),
    ])
}

/// `texgeo bench voxelize`: [`measure`] and [`report`].
pub fn run(ctx: &Context, models: &[Model], cfg: &Config) -> Result<Report> {
    let measured = measure(ctx, models, cfg, &mut Log("bench voxelize"))?;
    Ok(report(&measured, cfg, Environment::new(ctx.info().label())))
}

/// Table 5-2 and the CPU/GPU ratios of `measured`.
pub fn report(measured: &[Measured], cfg: &Config, environment: Environment) -> Report {
    let mut table = Table::new(
        "Table 5-2: voxelization time per method (ms, medians) and where it goes",
        &[
            "model",
            "triangles",
            "N",
            "method",
            "total ms",
            "total spread ± %",
            "excl. prepare ms",
            "prepare ms",
            "draw ms",
            "copy ms",
            "readback ms",
            "fallback ms",
            "fallback centres",
            "corrected",
            "occupied",
            "identical",
            "thesis s",
        ],
    );
    let mut ratios = Table::new(
        "GPU slicing vs CPU slicing (medians of total time, preparation included)",
        &[
            "model",
            "N",
            "cpu ms",
            "pgpu ms",
            "zoned ms",
            "cpu / pgpu",
            "cpu / zoned",
            "pgpu / zoned",
            "zoned excl. prepare ms",
            "cpu / zoned excl. prepare",
        ],
    );
    let mut failures = Vec::new();
    for group in measured.chunk_by(|a, b| a.model == b.model && a.n == b.n) {
        let (model, n) = (&group[0].model, group[0].n);
        let mut totals = Totals::new();
        for m in group {
            let (row, total) = method_row(m);
            table.row(row);
            match (total, &m.result) {
                (Some(t), _) => {
                    totals.insert(m.method, t);
                }
                (None, Err(why)) => failures.push(format!("{model} {n}³ {}: {why}", m.method)),
                (None, Ok(_)) => {}
            }
        }
        if let Some(row) = ratio_row(model, n, &totals) {
            ratios.row(row);
        }
    }
    for f in failures {
        table.note(format!("not measured on this device: {f}"));
    }
    table.note(format!(
        "{} timed runs after one warm-up; medians; total spread: half the range of the runs' totals as a share \
         of their median. total = wall time of one voxelization from the \
         mesh's covering to the finished bit volume, including the CPU preparation (sorting tetras, \
         display lists / zone copies, per-slice triangles for fgpu and fang), which the thesis left out \
         (\"excl. prepare\" is the thesis' convention). draw and copy are GPU timestamps around the render \
         passes and the image-to-buffer copies (for cpu, draw is the CPU rasterizer; for scanline, the whole \
         exact classification). readback = moving the 32-slices-per-texel layers into the bit volume. \
         fallback = finding the voxel centres within τ of the surface and classifying them exactly; \
         corrected = how many of them the rasterizer had wrong. identical = equal to the exact scanline. \
         thesis s = Table 5-2 (Pentium 4 3.4 GHz + GeForce 7800GTX); its Armadillo has 150 000 faces, \
         CGAL's has 52 000.",
        cfg.runs.max(1)
    ));
    ratios.note(
        "texgeo aims for pgpu/zoned at least 3× faster than cpu on armadillo at 256³ with lavapipe, \
         and zoned never slower than pgpu.",
    );
    Report { name: "voxelize".into(), environment, tables: vec![table, ratios] }
}

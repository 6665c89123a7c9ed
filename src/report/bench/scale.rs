//! `texgeo bench scale`: how inclusion and voxelization grow — 1 k, 100 k and
//! 1 M query points per inclusion method (`auto` included), 128³ … 1024³ per voxelization
//! method — with time and peak memory per method and thread count, and the speed of the
//! point-file reader and the label writer.
//!
//! Every measurement runs in a local rayon pool of the given size (the methods'
//! parallel steps use the current pool). Peak memory is the process' peak resident set
//! during the measurement (the kernel's mark is reset before it), so it includes what was
//! already resident (mesh, points, device); "before MiB" gives that base.

use std::time::{Duration, Instant};

use glam::DVec3;

use crate::gpu::Context;
use crate::inclusion::solver::{Solver, resolve};
use crate::inclusion::{Choice, Class, InclusionError, Options, points};
use crate::mesh::{Mesh, MeshError};
use crate::random::Rng;
use crate::report::{Environment, Report, Samples, Table};
use crate::scratch::ScratchDir;
use crate::voxel::{Grid, Solid, VoxelError, Voxelizer};

pub const DEFAULT_POINTS: &[usize] = &[1_000, 100_000, 1_000_000];
pub const DEFAULT_SIZES: &[usize] = &[128, 256, 512, 1024];

#[derive(Debug, thiserror::Error)]
pub enum ScaleError {
    #[error(transparent)]
    Inclusion(#[from] InclusionError),
    #[error(transparent)]
    Voxel(#[from] VoxelError),
    #[error(transparent)]
    Mesh(#[from] MeshError),
    #[error("bench scale: {0}")]
    Other(String),
}

pub struct Config {
    /// Query-point counts (uniform in the mesh's bounding box grown by 5 % per side).
    pub points: Vec<usize>,
    /// Inclusion methods (`auto` included).
    pub methods: Vec<Choice>,
    /// Voxel grid sizes N (N³).
    pub sizes: Vec<usize>,
    pub voxel_methods: Vec<crate::voxel::Method>,
    /// Pool sizes to measure each CPU step with.
    pub threads: Vec<usize>,
    /// Timed runs per measurement (median reported), after no warm-up: the first run
    /// pays for cold caches as a command would.
    pub runs: usize,
    /// A measurement predicted (from the previous size, linearly in points or in N³) to
    /// take longer than this is skipped and named in the notes.
    pub budget: Duration,
}

pub struct Model {
    pub name: String,
    pub mesh: Mesh,
}

fn ms(d: Duration) -> String {
    format!("{:.1}", d.as_secs_f64() * 1e3)
}

fn mib(kib: Option<u64>) -> String {
    kib.map_or("–".into(), |k| format!("{:.0}", k as f64 / 1024.0))
}

fn pool(threads: usize) -> Result<rayon::ThreadPool, ScaleError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| ScaleError::Other(format!("a {threads}-thread pool: {e}")))
}

/// One measurement: `runs` timed calls of `f` (which returns its own time and a
/// result), the median, the peak resident set over them and the resident set before.
struct Measured<T> {
    time: Duration,
    peak_kib: Option<u64>,
    before_kib: Option<u64>,
    last: T,
}

fn measure<T, E>(runs: usize, mut f: impl FnMut() -> Result<(Duration, T), E>) -> Result<Measured<T>, E> {
    let before_kib = crate::host::rss_kib();
    let reset = crate::host::reset_peak_rss();
    let mut samples = Samples::default();
    let mut last = None;
    for _ in 0..runs.max(1) {
        let (d, r) = f()?;
        samples.push(d);
        last = Some(r);
    }
    let peak_kib = if reset { crate::host::peak_rss_kib() } else { None };
    let last = last.expect("runs ≥ 1");
    Ok(Measured { time: samples.median(), peak_kib, before_kib, last })
}

/// Predicted time of the next size from the last measured one, scaled by `factor`.
fn over_budget(last: Option<Duration>, factor: f64, budget: Duration) -> Option<Duration> {
    let predicted = last?.mul_f64(factor);
    (predicted > budget).then_some(predicted)
}

pub fn run(ctx: &Context, inclusion: &Model, voxel: &Model, cfg: &Config) -> Result<Report, ScaleError> {
    let mut tables = vec![inclusion_table(ctx, inclusion, cfg)?];
    tables.push(io_table(inclusion, cfg)?);
    if !cfg.sizes.is_empty() && !cfg.voxel_methods.is_empty() {
        tables.push(voxel_table(ctx, voxel, cfg)?);
    }
    Ok(Report { name: "scale".into(), environment: Environment::new(ctx.info().label()), tables })
}

fn query_points(mesh: &Mesh, n: usize) -> Vec<DVec3> {
    let (lo, hi) = mesh.bounds();
    let pad = (hi - lo) * 0.05;
    Rng::new(13).points_in_box(n, lo - pad, hi + pad)
}

fn inclusion_table(ctx: &Context, model: &Model, cfg: &Config) -> Result<Table, ScaleError> {
    let mesh = &model.mesh;
    let mut table = Table::new(
        format!("Inclusion at scale: {} ({} faces), build + classification", model.name, mesh.num_faces()),
        &[
            "points",
            "method",
            "threads",
            "ran",
            "total ms",
            "build ms",
            "µs / point",
            "peak MiB",
            "before MiB",
            "same as auto",
        ],
    )
    .named("inclusion");
    let mut skipped = Vec::new();
    // Last (points, total, build) per (method, threads), to predict the next point count:
    // the build again plus the classification scaled by the points.
    let mut last: std::collections::HashMap<(Choice, usize), (usize, Duration, Duration)> =
        Default::default();
    for &n in &cfg.points {
        let pts = query_points(mesh, n);
        let mut reference: Option<Vec<Class>> = None;
        for &method in &cfg.methods {
            // The GPU methods' CPU side is small: one pool size (the largest) for them.
            let counts: Vec<usize> = if method.is_cpu() {
                cfg.threads.clone()
            } else {
                cfg.threads.iter().max().copied().into_iter().collect()
            };
            for &threads in &counts {
                let predicted = last.get(&(method, threads)).map(|&(m, total, build)| {
                    build + total.saturating_sub(build).mul_f64(n as f64 / m as f64)
                });
                if let Some(p) = over_budget(predicted, 1.0, cfg.budget) {
                    skipped.push(format!(
                        "{method} at {n} points on {threads} thread(s) (predicted {:.0} s)",
                        p.as_secs_f64()
                    ));
                    continue;
                }
                let options = Options { points: n, ..Options::default() };
                let (ran, options, _) = resolve(method, mesh, &options);
                let m = pool(threads)?.install(|| {
                    measure(cfg.runs, || -> Result<_, InclusionError> {
                        let t = Instant::now();
                        let mut solver = Solver::new(ran, mesh, &options, Some(ctx), None)?;
                        let build = t.elapsed();
                        let classes = solver.classify_all(&pts)?;
                        Ok((t.elapsed(), (build, classes)))
                    })
                })?;
                let (build, classes) = m.last;
                let same = match &reference {
                    Some(r) => {
                        if *r == classes {
                            "yes"
                        } else {
                            "NO"
                        }
                    }
                    None => "–",
                };
                if method == Choice::Auto && reference.is_none() {
                    reference = Some(classes);
                }
                crate::note!(
                    "bench scale: {n} points, {method} ({ran}), {threads} thread(s): {} ms",
                    ms(m.time)
                );
                last.insert((method, threads), (n, m.time, build));
                table.row(vec![
                    n.to_string(),
                    method.to_string(),
                    threads.to_string(),
                    ran.to_string(),
                    ms(m.time),
                    ms(build),
                    format!("{:.3}", m.time.as_secs_f64() * 1e6 / n as f64),
                    mib(m.peak_kib),
                    mib(m.before_kib),
                    same.into(),
                ]);
            }
        }
    }
    table.note(format!(
        "Medians of {} runs, each building the method from the mesh and classifying every point \
         (the solidity check, mesh and point reading are outside: see the command's whole-process \
         numbers in the README). ran = the method `auto` picked. peak = the process' peak resident \
         set during the runs; before = resident before them (mesh, points, the Vulkan device). \
         same as auto = identical labels to `auto` at that point count (listed first). GPU methods run \
         in batches of at most a few thousand points per submission, so their memory does not grow \
         with the point count.",
        cfg.runs.max(1)
    ));
    if !skipped.is_empty() {
        table.note(format!("Skipped (over the {} s budget): {}.", cfg.budget.as_secs(), skipped.join("; ")));
    }
    Ok(table)
}

/// One row of the throughput table: bytes moved by `step` in `time`.
fn throughput_row(table: &mut Table, threads: usize, step: &str, bytes: f64, time: Duration) {
    table.row(vec![
        threads.to_string(),
        step.into(),
        format!("{:.1}", bytes / 1e6),
        ms(time),
        format!("{:.0}", bytes / 1e6 / time.as_secs_f64().max(1e-9)),
    ]);
}

/// Point-file reading and label writing throughput at the largest point count.
fn io_table(model: &Model, cfg: &Config) -> Result<Table, ScaleError> {
    let n = cfg.points.iter().copied().max().unwrap_or(1_000_000);
    let pts = query_points(&model.mesh, n);
    let io = |e: std::io::Error| ScaleError::Other(e.to_string());
    let dir = ScratchDir::new("bench-scale").map_err(|e| ScaleError::Other(e.to_string()))?;
    let text_path = dir.join("points.xyz");
    let npy_path = dir.join("points.npy");
    {
        use std::io::Write as _;
        let mut w = std::io::BufWriter::new(std::fs::File::create(&text_path).map_err(io)?);
        for p in &pts {
            // The digits a typical exporter writes (%.9g).
            writeln!(w, "{:.6} {:.6} {:.6}", p.x, p.y, p.z).map_err(io)?;
        }
        w.flush().map_err(io)?;
        let mut w = std::io::BufWriter::new(std::fs::File::create(&npy_path).map_err(io)?);
        points::write_npy(&mut w, &pts).map_err(io)?;
    }
    let classes: Vec<Class> = (0..n).map(|i| [Class::Outside, Class::Inside][i % 2]).collect();
    let mut table =
        Table::new(format!("Point files and labels, {n} points"), &["threads", "step", "MB", "ms", "MB/s"])
            .named("io");
    for &threads in &cfg.threads {
        let pool = pool(threads)?;
        for (step, path) in [("read text points", &text_path), ("read .npy points", &npy_path)] {
            let bytes = std::fs::metadata(path).map_err(io)?.len() as f64;
            let m = pool.install(|| {
                measure(cfg.runs, || -> Result<_, ScaleError> {
                    let t = Instant::now();
                    let got = points::read(path)?;
                    Ok((t.elapsed(), got.len()))
                })
            })?;
            throughput_row(&mut table, threads, step, bytes, m.time);
        }
        for (step, name) in [("write text labels", "labels.txt"), ("write .npy labels", "labels.npy")] {
            let path = dir.join(name);
            let m = measure(cfg.runs, || -> Result<_, ScaleError> {
                let t = Instant::now();
                if points::is_npy(&path) {
                    crate::output::write_with(&path, |w| points::write_classes_npy(w, &classes))
                } else {
                    crate::output::write_with(&path, |w| points::write_classes(w, &classes))
                }
                .map_err(|e| ScaleError::Other(e.to_string()))?;
                Ok((t.elapsed(), ()))
            })?;
            let bytes = std::fs::metadata(&path).map_err(io)?.len() as f64;
            throughput_row(&mut table, threads, step, bytes, m.time);
        }
    }
    table.note(
        "Text points as `x y z` lines with 6 decimals; .npy as float64 N×3. Writing goes through \
         texgeo's atomic output (temporary file, then rename) into a temporary folder.",
    );
    Ok(table)
}

fn voxel_table(ctx: &Context, model: &Model, cfg: &Config) -> Result<Table, ScaleError> {
    let mut table = Table::new(
        format!("Voxelization at scale: {}", model.name),
        &["N", "method", "threads", "total ms", "peak MiB", "before MiB", "occupied"],
    )
    .named("voxelize");
    let solid = Solid::new(&model.mesh)?;
    let dir = ScratchDir::new("bench-scale").map_err(|e| ScaleError::Other(e.to_string()))?;
    let mut voxelizer = Voxelizer::new(Some(ctx.clone()));
    let row = |table: &mut Table, n: usize, method: &str, threads: usize, m: &Measured<u64>| {
        crate::note!("bench scale: {n}³ {method}, {threads} thread(s): {} ms", ms(m.time));
        table.row(vec![
            n.to_string(),
            method.to_string(),
            threads.to_string(),
            ms(m.time),
            mib(m.peak_kib),
            mib(m.before_kib),
            m.last.to_string(),
        ]);
    };
    let mut skipped = Vec::new();
    let mut last: std::collections::HashMap<(crate::voxel::Method, usize), (usize, Duration)> =
        Default::default();
    for &n in &cfg.sizes {
        crate::voxel::grid::check_resolution(n)?;
        let grid = Grid::for_mesh(&model.mesh, n)?;
        for &method in &cfg.voxel_methods {
            for &threads in &cfg.threads {
                let prev = last.get(&(method, threads)).copied();
                let factor = prev.map_or(1.0, |p| (n as f64 / p.0 as f64).powi(3));
                if let Some(p) = over_budget(prev.map(|p| p.1), factor, cfg.budget) {
                    skipped.push(format!(
                        "{method} at {n}³ on {threads} thread(s) (predicted {:.0} s)",
                        p.as_secs_f64()
                    ));
                    continue;
                }
                let m = pool(threads)?.install(|| {
                    measure(cfg.runs, || -> Result<_, VoxelError> {
                        let r = voxelizer.run(&solid, &grid, method)?;
                        Ok((r.timings.total, r.volume.count()))
                    })
                })?;
                last.insert((method, threads), (n, m.time));
                row(&mut table, n, &method.to_string(), threads, &m);
            }
        }
        // What `texgeo voxelize` does when only the file is wanted: the scanline volume
        // streamed to a binvox file in x planes, never held whole.
        if cfg.voxel_methods.contains(&crate::voxel::Method::Scanline) {
            let file = dir.join("v.binvox");
            for &threads in &cfg.threads {
                let m = pool(threads)?.install(|| {
                    measure(cfg.runs, || -> Result<_, VoxelError> {
                        let t = std::time::Instant::now();
                        let written = crate::voxel::binvox::write_scanline(&file, &grid, &solid)?;
                        Ok((t.elapsed(), written.occupied))
                    })
                })?;
                row(&mut table, n, "scanline → binvox file (streamed)", threads, &m);
            }
        }
    }
    table.note(format!(
        "Medians of {} runs of one voxelization (covering to finished bit volume, exact fallback \
         included; for the streamed rows, covering to finished binvox file); peak and before as in \
         the inclusion table.",
        cfg.runs.max(1)
    ));
    if !skipped.is_empty() {
        table.note(format!("Skipped (over the {} s budget): {}.", cfg.budget.as_secs(), skipped.join("; ")));
    }
    Ok(table)
}

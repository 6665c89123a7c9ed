//! `texgeo bench inclusion`: the 2006 thesis' point-in-solid experiments (§4.4), Tables
//! 4-4 to 4-9, on today's machine and Vulkan device, beside the thesis' numbers.
//!
//! Each model gets `sets` sets of `points` uniform random points in its bounding box
//! (fixed seeds); a table cell is the mean time per set, as in the thesis (§4.4.2).
//! Every method's answers are checked against `cpu` on every set.

use std::time::{Duration, Instant};

use glam::DVec3;

use crate::gpu::Context;
use crate::inclusion::bvh::Bvh;
use crate::inclusion::octants::Octants;
use crate::inclusion::octree::JordanOctree;
use crate::inclusion::solver::Solver;
use crate::inclusion::tetragrid::{GridClassifier, RESOLUTIONS};
use crate::inclusion::{Class, Classifier, EdgeRule, FeitoTorres, InclusionError, Method, Options};
use crate::mesh::Mesh;
use crate::random::Rng;
use crate::report::{Environment, Log, Progress, Report, Samples, Table};

/// A model of the experiment and the thesis model it stands in for.
pub struct Model {
    pub thesis: &'static str,
    pub name: String,
    pub mesh: Mesh,
}

/// Which models stand in for the thesis' (closed meshes of similar size and shape from
/// Debian's libcgal-demo; `builtin:` ones need no download).
pub const STAND_INS: &[(&str, &str)] = &[
    ("Torusknot", "builtin:knot"),
    ("Celtic Cross", "handle.off"),
    ("Vertebra", "femur.off"),
    ("Lion Head", "bear.off"),
    ("Golf Ball", "diplodocus.off"),
    ("Armadillo", "armadillo.off"),
    ("Venus / Buddha / Dragon", "bunny00.off"),
];

#[derive(Clone, Debug)]
pub struct Config {
    pub sets: usize,
    pub points: usize,
    /// TetraGrid resolutions of Tables 4-4 and 4-5.
    pub resolutions: Vec<usize>,
}

impl Default for Config {
    fn default() -> Config {
        Config { sets: 10, points: 1000, resolutions: vec![2, 4, 8, 16, 32, 64] }
    }
}

/// The thesis' tables, embedded so the binary carries them.
const THESIS: [(&str, &str); 6] = [
    ("4-4", include_str!("../../../reference/inclusion/table4-4.csv")),
    ("4-5", include_str!("../../../reference/inclusion/table4-5.csv")),
    ("4-6", include_str!("../../../reference/inclusion/table4-6.csv")),
    ("4-7", include_str!("../../../reference/inclusion/table4-7.csv")),
    ("4-8", include_str!("../../../reference/inclusion/table4-8.csv")),
    ("4-9", include_str!("../../../reference/inclusion/table4-9.csv")),
];

/// The thesis' table `id` ("4-4" … "4-9") as transcribed: header, then rows.
pub fn thesis_csv(id: &str) -> &'static str {
    THESIS.iter().find(|(t, _)| *t == id).map(|(_, c)| *c).unwrap_or("")
}

/// A column of the transcribed tables in words: `feito_octants_kb` → "Feito (octants)
/// KB", `time_32` → "32³ s".
fn column_words(column: &str) -> String {
    let unit = |rest: &str, unit: &str| format!("{} {unit}", column_words(rest));
    if let Some(n) = column.strip_prefix("time_") {
        return format!("{n}³ s");
    }
    if let Some(n) = column.strip_prefix("kb_") {
        return format!("{n}³ KB");
    }
    if let Some(rest) = column.strip_suffix("_kb") {
        return unit(rest, "KB");
    }
    if let Some(rest) = column.strip_suffix("_s") {
        return unit(rest, "s");
    }
    if let Some(n) = column.strip_prefix("tetragrid_") {
        return format!("TetraGrid {n}³");
    }
    if let Some(rest) = column.strip_prefix("feito_") {
        return format!("Feito ({})", column_words(rest));
    }
    match column {
        "model" | "faces" | "triangles" | "vertices" | "octants" => column.to_string(),
        "no_optimizer" => "no optimizer".into(),
        "basic" => "basic (CPU)".into(),
        "cpu" => "CPU".into(),
        "gpu" => "GPU".into(),
        "cpu_gpu" => "CPU+GPU".into(),
        "gpu_tetragrid_32" => "GPU + TetraGrid 32³".into(),
        "bsp" => "BSP".into(),
        "jordan" => "Jordan".into(),
        "jordan_octree_6" => "Jordan + octree 6".into(),
        other => other.replace('_', " "),
    }
}

/// Table 4-6 as printed repeats Table 4-5's TetraGrid 2³ … 64³ columns under its six
/// method names; said under the table wherever it is shown.
pub const TABLE_4_6_NOTE: &str = "As printed, the thesis' Table 4-6 repeats Table 4-5's TetraGrid 2³ … 64³ columns \
     under its six method names (its \"basic\" column equals Table 4-5's TetraGrid 2³, its CPU+GPU column TetraGrid \
     4³, and so on): only its TetraGrid 32³ column can be the method it names. Its numbers are shown as printed, \
     from that one table; the claims take the CPU and GPU times from Table 4-9.";

fn thesis_table(id: &str) -> Table {
    let mut lines = thesis_csv(id).lines();
    let columns: Vec<String> = lines.next().unwrap_or("").split(',').map(column_words).collect();
    let columns: Vec<&str> = columns.iter().map(String::as_str).collect();
    let mut t = Table::new(
        format!("Table {id} as printed in the thesis (Pentium 4E 3.4 GHz, GeForce 7800 GTX)"),
        &columns,
    )
    .named(&format!("table{id}-thesis"));
    // Tables 4-5, 4-6 and 4-9 give seconds per set without saying so in their columns.
    if matches!(id, "4-5" | "4-6" | "4-9") {
        t = t.unit("s", 2..columns.len());
    }
    for l in lines.filter(|l| !l.trim().is_empty()) {
        t.row(l.split(',').map(str::to_string).collect());
    }
    if id == "4-6" {
        t.note(TABLE_4_6_NOTE);
    }
    t
}

fn secs(d: Duration) -> String {
    crate::report::sig(d.as_secs_f64(), 4)
}

fn kib(bytes: usize) -> String {
    format!("{}", bytes.div_ceil(1024))
}

/// The point sets of one model (fixed seeds).
fn point_sets(mesh: &Mesh, cfg: &Config) -> Vec<Vec<DVec3>> {
    let (lo, hi) = mesh.bounds();
    (0..cfg.sets).map(|k| Rng::new(4000 + k as u64).points_in_box(cfg.points, lo, hi)).collect()
}

/// A timed classifier of the experiment: a TetraGrid or a method's solver.
enum Contender {
    Grid(Box<GridClassifier>),
    Solver(Box<Solver>),
}

impl Contender {
    fn classify(&mut self, points: &[DVec3]) -> Result<Vec<Class>, InclusionError> {
        match self {
            Contender::Grid(g) => Ok(g.classify_all(points)),
            Contender::Solver(s) => s.classify_all(points),
        }
    }
}

/// Everything measured on one model.
pub struct Measured {
    pub name: String,
    pub thesis: &'static str,
    pub vertices: usize,
    pub faces: usize,
    /// Covering triangles = tetrahedra.
    pub triangles: usize,
    /// TetraGrid build (time, bytes) at each of `Config::resolutions`.
    pub grid_builds: Vec<(Duration, usize)>,
    /// Every TetraGrid build at each resolution (median in `grid_builds`).
    pub grid_build_times: Vec<Samples>,
    /// Method name → the time of every set (`gpu-batch-1`: the thesis' one tetrahedron
    /// per point-vertex).
    pub times: Vec<(String, Samples)>,
    /// Methods that could not run on this device, with the reason.
    pub failed: Vec<(String, String)>,
    /// TetraGrid at each resolution: the time of every set.
    pub grid_times: Vec<Samples>,
    /// TetraGrid at each resolution: the mean share of all tetrahedra a query point is
    /// tested against (the tetrahedra listed in its cell).
    pub grid_tested: Vec<f64>,
    pub gpu_split: Vec<String>,
    pub disagreements: Vec<String>,
    /// Index-only build stats of the methods with preprocessing (Tables 4-7, 4-8).
    pub index: Vec<(&'static str, crate::inclusion::BuildStats)>,
    /// Every build of each index of `index` (median in its stats).
    pub index_builds: Vec<Samples>,
}

impl Measured {
    /// Mean time per set of `method`, if it ran.
    pub fn mean(&self, method: &str) -> Option<Duration> {
        self.samples(method).map(Samples::mean)
    }

    pub fn samples(&self, method: &str) -> Option<&Samples> {
        self.times.iter().find(|t| t.0 == method).map(|t| &t.1)
    }

    fn time(&self, method: &str) -> String {
        self.mean(method).map(secs).unwrap_or_else(|| "–".into())
    }

    /// Build time and bytes of an index (`octants`, `tetragrid`, `bvh`, `jordan-octree`).
    pub fn index(&self, method: &str) -> Option<(Duration, usize)> {
        self.index.iter().find(|t| t.0 == method).map(|t| (t.1.build_time, t.1.bytes))
    }

    fn ratio(&self, method: &str) -> String {
        let get = |m: &str| self.mean(m).map(|d| d.as_secs_f64());
        match (get("cpu"), get(method)) {
            (Some(c), Some(m)) if m > 0.0 => crate::report::sig(c / m, 3),
            _ => "–".into(),
        }
    }
}

/// Steps [`measure`] reports per model: the reference, building each TetraGrid
/// resolution, each method and the thesis' GPU layout, then each set.
pub fn steps(models: usize, cfg: &Config) -> u64 {
    (models * (cfg.resolutions.len() + METHODS.len() + 2 + cfg.sets)) as u64
}

/// Builds of every index and TetraGrid resolution, for the medians and ranges of
/// Tables 4-4, 4-7 and 4-8.
const BUILDS: usize = 3;

/// The methods of Tables 4-6 to 4-9, at their default settings (TetraGrid 32³, octree 6).
const METHODS: [Method; 9] = [
    Method::Cpu,
    Method::CpuGpu,
    Method::Gpu,
    Method::Octants,
    Method::Bvh,
    Method::TetraGrid,
    Method::GpuTetraGrid,
    Method::Jordan,
    Method::JordanOctree,
];

/// Measures one model: the reference answers, TetraGrid at every resolution (Tables
/// 4-4, 4-5), every method (Tables 4-6 … 4-9), all of them timed set by set in turn,
/// then the indexes' own builds (Tables 4-7, 4-8).
fn measure_model(
    ctx: &Context,
    model: &Model,
    cfg: &Config,
    progress: &mut dyn Progress,
) -> Result<Measured, InclusionError> {
    let mesh = &model.mesh;
    progress.step(&format!("{}: reference answers", model.name));
    let sets = point_sets(mesh, cfg);
    let mut m = Measured::new(model);
    // The reference answers: the exact test with basic preprocessing.
    let cpu = crate::inclusion::build(Method::Cpu, mesh, &Options::default())?;
    let want: Vec<Vec<Class>> = sets.iter().map(|s| cpu.classify_all(s)).collect();
    let mut sides = grids(model, cfg, &sets, &mut m, progress)?;
    sides.extend(solvers(ctx, model, &mut m, progress)?);
    let (times, agree) = in_turn(&mut sides, &sets, &want, &model.name, progress)?;
    m.record(sides, times, agree);
    index_builds(mesh, &mut m)?;
    Ok(m)
}

impl Measured {
    /// Nothing measured yet on `model`.
    fn new(model: &Model) -> Measured {
        let mesh = &model.mesh;
        Measured {
            name: model.name.clone(),
            thesis: model.thesis,
            vertices: mesh.num_vertices(),
            faces: mesh.num_faces(),
            triangles: crate::mesh::covering::Covering::new(mesh).triangles.len(),
            grid_builds: Vec::new(),
            grid_build_times: Vec::new(),
            times: Vec::new(),
            failed: Vec::new(),
            grid_times: Vec::new(),
            grid_tested: Vec::new(),
            gpu_split: Vec::new(),
            disagreements: Vec::new(),
            index: Vec::new(),
            index_builds: Vec::new(),
        }
    }

    /// Each contender's times and whether it agreed with the reference on every set;
    /// the GPU methods' last split of the work.
    fn record(&mut self, sides: Vec<(String, Contender)>, times: Vec<Samples>, agree: Vec<bool>) {
        for ((name, side), (time, ok)) in sides.into_iter().zip(times.into_iter().zip(agree)) {
            if !ok {
                self.disagreements.push(if name == "gpu-batch-1" {
                    "gpu (batch 1)".into()
                } else {
                    name.clone()
                });
            }
            if let Contender::Solver(solver) = &side
                && let Some(g) = solver.gpu_stats()
                && name != "gpu-batch-1"
            {
                self.gpu_split.push(format!(
                    "{}: last set {} points drawn in {} draw(s), GPU submissions {:.3} ms, host {:.3} ms, {} flagged → exact CPU {:.3} ms",
                    name,
                    g.gpu_points,
                    g.draws,
                    g.gpu.as_secs_f64() * 1e3,
                    g.host.as_secs_f64() * 1e3,
                    g.flagged,
                    g.fallback.as_secs_f64() * 1e3
                ));
            }
            if name.starts_with("tetragrid-") {
                self.grid_times.push(time);
            } else {
                self.times.push((name, time));
            }
        }
    }
}

/// Tables 4-4 and 4-5: GridClassifier at every resolution, built `BUILDS` times (the
/// resolutions in turn: a build time is as exposed to load as a query time, and the
/// build's growth in n is a claim), with the share of tetrahedra each tests.
fn grids(
    model: &Model,
    cfg: &Config,
    sets: &[Vec<DVec3>],
    m: &mut Measured,
    progress: &mut dyn Progress,
) -> Result<Vec<(String, Contender)>, InclusionError> {
    let mesh = &model.mesh;
    let mut sides: Vec<(String, Contender)> = Vec::new();
    for &n in &cfg.resolutions {
        if !RESOLUTIONS.contains(&n) {
            return Err(InclusionError::Resolution(n));
        }
        progress.step(&format!("{}: building TetraGrid {n}³", model.name));
        let ft = FeitoTorres::with_options(mesh, None, EdgeRule::Rerun)?;
        let grid = GridClassifier::new(ft, n)?;
        m.grid_build_times.push(Samples(vec![grid.index_stats().build_time]));
        m.grid_builds.push((Duration::ZERO, grid.index_stats().bytes));
        m.grid_tested.push(tested_share(&grid, sets, m.triangles));
        sides.push((format!("tetragrid-{n}"), Contender::Grid(Box::new(grid))));
    }
    for _ in 1..BUILDS {
        for (i, &n) in cfg.resolutions.iter().enumerate() {
            let grid = GridClassifier::new(FeitoTorres::with_options(mesh, None, EdgeRule::Rerun)?, n)?;
            m.grid_build_times[i].push(grid.index_stats().build_time);
        }
    }
    for (b, t) in m.grid_builds.iter_mut().zip(&m.grid_build_times) {
        b.0 = t.median();
    }
    Ok(sides)
}

/// Tables 4-6 to 4-9: every method at its default settings (TetraGrid 32³, octree 6),
/// and the thesis' layout: one point-vertex per tetrahedron. A GPU method this device
/// cannot run is recorded in `m.failed`, not an error.
fn solvers(
    ctx: &Context,
    model: &Model,
    m: &mut Measured,
    progress: &mut dyn Progress,
) -> Result<Vec<(String, Contender)>, InclusionError> {
    let mut sides = Vec::new();
    let methods = METHODS.iter().map(|&k| (k, k.name().to_string(), None));
    for (method, name, batch) in
        methods.chain(std::iter::once((Method::Gpu, "gpu-batch-1".to_string(), Some(1))))
    {
        progress.step(&format!("{}: building {name}", model.name));
        match Solver::new(method, &model.mesh, &Options::default(), Some(ctx), batch) {
            Ok(s) => sides.push((name, Contender::Solver(Box::new(s)))),
            Err(e) if method.is_cpu() => return Err(e),
            Err(e) => m.failed.push((name, e.to_string())),
        }
    }
    Ok(sides)
}

/// Every contender on every set in turn (set 1: A, B, …; set 2: A, B, …), after one
/// untimed warm-up each (lavapipe compiles shaders at the first draw): load that comes
/// and goes hits every method alike, and the ratio of two methods can be taken set by
/// set. Each one's times, and whether it gave `want` on every set.
fn in_turn(
    sides: &mut [(String, Contender)],
    sets: &[Vec<DVec3>],
    want: &[Vec<Class>],
    name: &str,
    progress: &mut dyn Progress,
) -> Result<(Vec<Samples>, Vec<bool>), InclusionError> {
    for (_, side) in sides.iter_mut() {
        side.classify(&sets[0])?;
    }
    let mut times = vec![Samples::default(); sides.len()];
    let mut agree = vec![true; sides.len()];
    for (k, (set, w)) in sets.iter().zip(want).enumerate() {
        progress.step(&format!("{name}: set {} of {}, every method in turn", k + 1, sets.len()));
        for (i, (_, side)) in sides.iter_mut().enumerate() {
            let t = Instant::now();
            let got = side.classify(set)?;
            times[i].push(t.elapsed());
            agree[i] &= got == *w;
        }
    }
    Ok((times, agree))
}

/// Tables 4-7 and 4-8 count each method's own index, as the thesis did, not the
/// covering and per-tetra planes every Feito-Torres variant shares. Each built BUILDS
/// times, the indexes in turn; the medians go into `m.index`.
fn index_builds(mesh: &Mesh, m: &mut Measured) -> Result<(), InclusionError> {
    let ft = || FeitoTorres::with_options(mesh, None, EdgeRule::Rerun);
    for _ in 0..BUILDS {
        let built = [
            ("octants", Octants::new(ft()?).index_stats()),
            ("tetragrid", GridClassifier::new(ft()?, 32)?.index_stats()),
            ("bvh", Bvh::new(ft()?).index_stats()),
            ("jordan-octree", JordanOctree::new(mesh, 6)?.index_stats()),
        ];
        if m.index.is_empty() {
            m.index_builds = vec![Samples::default(); built.len()];
            m.index = built.to_vec();
        }
        for (s, (_, stats)) in m.index_builds.iter_mut().zip(&built) {
            s.push(stats.build_time);
        }
    }
    for ((_, stats), s) in m.index.iter_mut().zip(&m.index_builds) {
        stats.build_time = s.median();
    }
    Ok(())
}

/// The mean share of the `tetrahedra` a query point of `sets` is tested against: those
/// listed in its TetraGrid cell (none outside the grid).
fn tested_share(grid: &GridClassifier, sets: &[Vec<DVec3>], tetrahedra: usize) -> f64 {
    let (mut listed, mut points) = (0usize, 0usize);
    for p in sets.iter().flatten() {
        listed += grid.cell_of(*p).map_or(0, |c| grid.cell_tetras(c).len());
        points += 1;
    }
    listed as f64 / (points.max(1) * tetrahedra.max(1)) as f64
}

/// Runs every method on every model (Tables 4-4 to 4-9).
pub fn measure(
    ctx: &Context,
    models: &[Model],
    cfg: &Config,
    progress: &mut dyn Progress,
) -> Result<Vec<Measured>, InclusionError> {
    progress.total(steps(models.len(), cfg));
    // The thesis' CPU columns are one thread: the tables run in a one-thread pool (the
    // classifiers use every core of the current pool otherwise; `texgeo bench scale`
    // measures that).
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| InclusionError::Options(format!("a one-thread pool: {e}")))?;
    one.install(|| models.iter().map(|model| measure_model(ctx, model, cfg, progress)).collect())
}

/// `texgeo bench inclusion`: [`measure`] and [`report`].
pub fn run(ctx: &Context, models: &[Model], cfg: &Config) -> Result<Report, InclusionError> {
    let measured = measure(ctx, models, cfg, &mut Log("bench inclusion"))?;
    Ok(report(&measured, cfg, Environment::new(ctx.info().label())))
}

/// A model's row label: "name (thesis model)".
fn label(m: &Measured) -> String {
    format!("{} ({})", m.name, m.thesis)
}

/// The thesis' tables for `measured`, today's beside the thesis', then the speed-ups
/// and the spread of the timed sets.
pub fn report(measured: &[Measured], cfg: &Config, environment: Environment) -> Report {
    let (t47, t48) = index_tables(measured);
    let mut tables = Vec::new();
    for (id, today) in [
        ("4-4", table_4_4(measured, cfg)),
        ("4-5", table_4_5(measured, cfg)),
        ("4-6", table_4_6(measured, cfg)),
        ("4-7", t47),
        ("4-8", t48),
        ("4-9", table_4_9(measured, cfg)),
    ] {
        tables.push(today.named(&format!("table{id}")));
        tables.push(thesis_table(id));
    }
    tables.push(speed_ups(measured, cfg).named("speedup"));
    tables.push(spread_table(measured));
    Report { name: "inclusion".into(), environment, tables }
}

/// Table 4-4: each TetraGrid resolution's build time and memory.
fn table_4_4(measured: &[Measured], cfg: &Config) -> Table {
    let mut cols = vec!["model".to_string(), "vertices".into(), "tetrahedra".into()];
    for n in &cfg.resolutions {
        cols.push(format!("{n}³ s"));
        cols.push(format!("{n}³ KiB"));
    }
    let mut t44 = Table {
        title: "Table 4-4: GridClassifier build time (s) and memory (KiB)".into(),
        columns: cols,
        ..Default::default()
    };
    for m in measured {
        let mut row = vec![label(m), m.vertices.to_string(), m.triangles.to_string()];
        for &(t, b) in &m.grid_builds {
            row.push(secs(t));
            row.push(kib(b));
        }
        t44.row(row);
    }
    t44
}

/// Table 4-5: the CPU test without an optimizer and with each TetraGrid resolution.
fn table_4_5(measured: &[Measured], cfg: &Config) -> Table {
    let mut cols = vec!["model".to_string(), "faces".into(), "no optimizer".into()];
    cols.extend(cfg.resolutions.iter().map(|n| format!("TetraGrid {n}³")));
    let mut t45 = Table {
        title: format!(
            "Table 4-5: Feito-Torres without and with TetraGrid, s per set of {} points",
            cfg.points
        ),
        columns: cols,
        ..Default::default()
    };
    let columns = t45.columns.len();
    t45 = t45.unit("s", 2..columns);
    for m in measured {
        let mut row = vec![label(m), m.faces.to_string(), m.time("cpu")];
        row.extend(m.grid_times.iter().map(|t| secs(t.mean())));
        t45.row(row);
    }
    t45
}

/// Table 4-6: the versions of the Feito-Torres test.
fn table_4_6(measured: &[Measured], cfg: &Config) -> Table {
    times_table(
        measured,
        format!("Table 4-6: versions of Feito-Torres, s per set of {} points", cfg.points),
        &[
            ("basic (cpu)", "cpu"),
            ("CPU+GPU", "cpu+gpu"),
            ("GPU", "gpu"),
            ("GPU, thesis layout (batch 1)", "gpu-batch-1"),
            ("octants", "octants"),
            ("TetraGrid 32", "tetragrid"),
            ("GPU+TetraGrid 32", "gpu+tetragrid"),
        ],
    )
}

/// A table of the mean time per set of each method (column header, method) beside each
/// model and its faces.
fn times_table(measured: &[Measured], title: String, methods: &[(&str, &str)]) -> Table {
    let mut columns = vec!["model", "faces"];
    columns.extend(methods.iter().map(|m| m.0));
    let mut t = Table::new(title, &columns).unit("s", 2..2 + methods.len());
    for m in measured {
        let mut row = vec![label(m), m.faces.to_string()];
        row.extend(methods.iter().map(|(_, method)| m.time(method)));
        t.row(row);
    }
    t
}

/// Tables 4-7 and 4-8: each method's index, its memory and its build time.
fn index_tables(measured: &[Measured]) -> (Table, Table) {
    let pre = ["octants", "tetragrid", "bvh", "jordan-octree"];
    let columns =
        ["model", "triangles", "Feito (octants)", "Feito (TetraGrid 32)", "Feito (BVH)", "Jordan (octree 6)"];
    let mut t47 = Table::new(
        "Table 4-7: memory of each method's index (KiB; BVH stands where the thesis had BSP)",
        &columns,
    )
    .unit("KiB", 2..6);
    let mut t48 = Table::new("Table 4-8: time to build each method's index (s)", &columns).unit("s", 2..6);
    for m in measured {
        let mut mem = vec![label(m), m.triangles.to_string()];
        let mut time = mem.clone();
        for p in pre {
            let b = m.index(p);
            mem.push(b.map(|b| kib(b.1)).unwrap_or_default());
            time.push(b.map(|b| secs(b.0)).unwrap_or_default());
        }
        t47.row(mem);
        t48.row(time);
    }
    (t47, t48)
}

/// Table 4-9: the inclusion tests of both families.
fn table_4_9(measured: &[Measured], cfg: &Config) -> Table {
    times_table(
        measured,
        format!("Table 4-9: inclusion tests, s per set of {} points", cfg.points),
        &[
            ("Feito CPU", "cpu"),
            ("Feito GPU", "gpu"),
            ("Feito GPU+TetraGrid 32", "gpu+tetragrid"),
            ("Feito BVH", "bvh"),
            ("Jordan", "jordan"),
            ("Jordan octree 6", "jordan-octree"),
        ],
    )
}

/// The speed-up of every method over the CPU test, with what was measured and how.
fn speed_ups(measured: &[Measured], cfg: &Config) -> Table {
    let mut speed = Table::new(
        "Speed-up over the single-thread exact CPU test (`cpu`), from the means above (×)",
        &[
            "model",
            "cpu+gpu",
            "gpu",
            "gpu (batch 1)",
            "octants",
            "tetragrid",
            "gpu+tetragrid",
            "jordan-octree",
        ],
    )
    .unit("×", 1..8);
    for m in measured {
        speed.row(vec![
            label(m),
            m.ratio("cpu+gpu"),
            m.ratio("gpu"),
            m.ratio("gpu-batch-1"),
            m.ratio("octants"),
            m.ratio("tetragrid"),
            m.ratio("gpu+tetragrid"),
            m.ratio("jordan-octree"),
        ]);
    }
    let disagreements: Vec<String> = measured
        .iter()
        .flat_map(|m| m.disagreements.iter().map(move |d| format!("{} on {}", d, m.name)))
        .collect();
    speed.note(if disagreements.is_empty() {
        "Every method gave exactly the `cpu` answer for every point of every set.".to_string()
    } else {
        format!("DISAGREEMENTS with `cpu`: {}", disagreements.join(", "))
    });
    for m in measured {
        for line in &m.gpu_split {
            speed.note(format!("{}: {line}", m.name));
        }
        for (method, why) in &m.failed {
            speed.note(format!("{}: {method} not measured: {why}", m.name));
        }
    }
    speed.note(format!(
        "{} sets of {} uniform random points in each model's bounding box (seeds 4000…), mean per set after one \
         untimed warm-up. GPU methods: {} tetrahedra per point-vertex (`gpu`), {} (`gpu+tetragrid`); 32 query \
         points per point-vertex; points the GPU cannot decide exactly are answered by the exact CPU test.",
        cfg.sets,
        cfg.points,
        crate::inclusion::solver::GPU_BATCH,
        crate::inclusion::solver::GPU_GRID_BATCH
    ));
    speed
}

/// The spread of the sets' times beside the means of Tables 4-5, 4-6 and 4-9.
fn spread_table(measured: &[Measured]) -> Table {
    let timed = [
        "cpu",
        "cpu+gpu",
        "gpu",
        "gpu-batch-1",
        "octants",
        "tetragrid",
        "gpu+tetragrid",
        "bvh",
        "jordan",
        "jordan-octree",
    ];
    let mut columns = vec!["model".to_string()];
    columns.extend(timed.iter().map(|m| format!("{m} ± %")));
    let mut spread = Table {
        title: "Spread of the sets' times: half their range as a share of the mean shown above (± %)".into(),
        columns,
        ..Default::default()
    }
    .named("spread");
    for m in measured {
        let mut row = vec![label(m)];
        row.extend(timed.iter().map(|k| {
            m.samples(k)
                .and_then(|s| s.spread_percent(s.mean()))
                .map_or_else(|| "–".to_string(), |p| crate::report::sig(p, 2))
        }));
        spread.row(row);
    }
    spread
}

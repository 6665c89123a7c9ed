//! `texgeo bench voxelize`: Table 5-2 of the 2006 thesis (§5.4.2) — every voxelization
//! method at 64³ … 512³ — with the thesis' seconds (`reference/voxel/table5-2.csv`) next
//! to today's medians, where the time goes (CPU preparation, draws, copies, readback,
//! exact fallback), and the speed ratios between the CPU and the GPU slicers.

use std::time::Duration;

use crate::gpu::Context;
use crate::mesh::Mesh;
use crate::report::{Environment, Report, Samples, Table};
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

/// Medians of the parts of [`Timings`] over several runs.
#[derive(Default)]
struct Medians {
    total: Samples,
    prepare: Samples,
    draw: Samples,
    copy: Samples,
    readback: Samples,
    fallback: Samples,
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

fn ms(d: Duration) -> String {
    format!("{:.1}", d.as_secs_f64() * 1e3)
}

pub fn run(ctx: &Context, models: &[Model], cfg: &Config) -> Result<Report> {
    let mut voxelizer = Voxelizer::new(Some(ctx.clone()));
    voxelizer.zone = cfg.zone;
    let mut table = Table::new(
        "Table 5-2: voxelization time per method (ms, medians) and where it goes",
        &[
            "model",
            "triangles",
            "N",
            "method",
            "total ms",
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
    for model in models {
        let solid = Solid::new(&model.mesh)?;
        for &n in &cfg.resolutions {
            let grid = Grid::for_mesh(&model.mesh, n)?;
            let reference = voxelizer.run(&solid, &grid, Method::Scanline)?.volume;
            let mut totals = std::collections::HashMap::new();
            for &method in &cfg.methods {
                let mut medians = Medians::default();
                let mut last = None;
                for run in 0..=cfg.runs.max(1) {
                    let r = voxelizer.run(&solid, &grid, method)?;
                    if run > 0 {
                        medians.push(&r.timings);
                    }
                    last = Some(r);
                }
                let r = last.ok_or_else(|| VoxelError::Usage("no run".into()))?;
                let identical = r.volume == reference;
                let total = medians.total.median();
                let prepare = medians.prepare.median();
                totals.insert(method, (total, total.saturating_sub(prepare)));
                table.row(vec![
                    model.name.clone(),
                    solid.triangles.len().to_string(),
                    n.to_string(),
                    method.to_string(),
                    ms(total),
                    ms(total.saturating_sub(prepare)),
                    ms(prepare),
                    ms(medians.draw.median()),
                    ms(medians.copy.median()),
                    ms(medians.readback.median()),
                    ms(medians.fallback.median()),
                    r.band.candidates.to_string(),
                    r.band.changed.to_string(),
                    r.volume.count().to_string(),
                    if identical { "yes".into() } else { "NO".into() },
                    thesis_seconds(n, model.thesis, method).map_or("–".into(), |s| format!("{s}")),
                ]);
                eprintln!("{} {n}³ {method}: {} ms", model.name, ms(total));
            }
            let get = |m: Method| totals.get(&m).copied();
            if get(Method::Cpu).is_some() || (get(Method::Pgpu).is_some() && get(Method::Zoned).is_some()) {
                let time =
                    |m: Method, excl: bool| get(m).map_or("–".into(), |t| ms(if excl { t.1 } else { t.0 }));
                let ratio = |a: Method, b: Method, excl: bool| match (get(a), get(b)) {
                    (Some(x), Some(y)) => {
                        let y = if excl { y.1 } else { y.0 };
                        format!("{:.2}", x.0.as_secs_f64() / y.as_secs_f64().max(1e-9))
                    }
                    _ => "–".into(),
                };
                ratios.row(vec![
                    model.name.clone(),
                    n.to_string(),
                    time(Method::Cpu, false),
                    time(Method::Pgpu, false),
                    time(Method::Zoned, false),
                    ratio(Method::Cpu, Method::Pgpu, false),
                    ratio(Method::Cpu, Method::Zoned, false),
                    ratio(Method::Pgpu, Method::Zoned, false),
                    time(Method::Zoned, true),
                    ratio(Method::Cpu, Method::Zoned, true),
                ]);
            }
        }
    }
    table.note(format!(
        "{} timed runs after one warm-up; medians. total = wall time of one voxelization from the \
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
        "The issue asks pgpu/zoned to be at least 3× faster than cpu on armadillo at 256³ with lavapipe, \
         and zoned never slower than pgpu.",
    );
    Ok(Report {
        name: "voxelize".into(),
        environment: Environment::new(ctx.info().label()),
        tables: vec![table, ratios],
    })
}

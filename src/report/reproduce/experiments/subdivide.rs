//! Catmull-Clark with fragment meshes (2010 §3.4, Table 5) through `texgeo bench
//! subdivide`'s measuring code, plus a level sweep: where the GPU starts to win.

use super::{Quantity, Speedup, both, comparison, curve, details, speedup_plot};
use crate::mesh::spec::MeshSpec;
use crate::mesh::{Mesh, formats, procedural};
use crate::report::bench::subdiv::{self, LevelTimes, Measured, Model, Settings, default_models};
use crate::report::plot::{Chart, Series};
use crate::report::reproduce::doc::Block;
use crate::report::reproduce::facts::Stat;
use crate::report::reproduce::{Result, Run};
use crate::report::{Environment, Samples, Table};

const EXP: &str = "subdivide";
const LEVEL: u32 = 5;

/// Refines every model to level 5 (GPU path, CPU reference and OpenSubdiv in turn) and
/// the largest through every level, adds the facts, then writes the section: Table 5
/// beside the thesis', the level sweep, the plots and the bench's own tables.
pub fn run(r: &mut Run) -> Result<Vec<Block>> {
    let models = models(r)?;
    let settings = Settings { level: LEVEL, runs: if r.quick { 3 } else { 5 } + r.repeat, validate: true };
    let measured = subdiv::measure(r.ctx, &models, settings, r.progress)?;
    let (sweep_name, sweep_mesh) = sweep_model(r)?;
    r.progress.total(5);
    let levels = subdiv::per_level(r.ctx, &sweep_mesh, 1..=LEVEL, 3 + r.repeat, r.progress)?;
    let wrong = record_facts(r, &measured, &sweep_name, &levels);
    let mut blocks = section_text(settings, &wrong);
    let t = comparison(
        r,
        EXP,
        &format!("Table 5: level {LEVEL}"),
        "s",
        &[
            Quantity::same("TCPU¹ (CPU base level)", "time:tcpu1"),
            Quantity::same("TGPU (fragment passes)", "time:tgpu"),
            Quantity::same("GPU path (thesis: TCPU¹ + TGPU)", "time:gpu-path"),
            Quantity::same("TCPU² (today: texgeo's CPU reference; thesis: CGAL)", "time:tcpu2"),
            Quantity::same("OpenSubdiv", "time:osd"),
        ],
    );
    blocks.push(r.table(t, "subdivide-table5")?);
    blocks.push(r.table(level_table(&sweep_name, &levels), "subdivide-levels")?);
    blocks.extend(r.plot(&level_chart(&sweep_name, &levels), "subdivide-time-vs-level")?);
    blocks.extend(face_plots(r)?);
    let bench = subdiv::report(&measured, settings, Environment::new(r.ctx.info().label()));
    blocks.extend(details(r, EXP, bench.tables)?);
    Ok(blocks)
}

/// `--quick`: the cube, the pyramid and the knot; else the default models. Named in the
/// report by their file name, not the folder they were found in.
fn models(r: &Run) -> Result<Vec<Model>> {
    let mut models = if r.quick {
        ["cube", "pyramid", "knot"]
            .iter()
            .filter_map(|n| procedural::by_name(n).map(|mesh| Model { name: format!("builtin:{n}"), mesh }))
            .collect()
    } else {
        default_models(r.models_dir)?
    };
    for m in &mut models {
        if let Some(file) = MeshSpec::parse(&m.name).file().and_then(std::path::Path::file_name) {
            m.name = file.to_string_lossy().into_owned();
        }
    }
    Ok(models)
}

/// The model of the level sweep: the largest (knot1.off when fetched).
fn sweep_model(r: &Run) -> Result<(String, Mesh)> {
    let knot1 = r.models_dir.join("knot1.off");
    Ok(if !r.quick && knot1.is_file() {
        ("knot1.off".to_string(), formats::read(&knot1)?)
    } else {
        ("builtin:knot".to_string(), procedural::torus_knot())
    })
}

/// The facts of every model at level 5 and of the sweep's every level; the models whose
/// GPU result differs from OpenSubdiv's (also recorded as disagreements).
fn record_facts(r: &mut Run, measured: &[Measured], sweep_name: &str, levels: &[LevelTimes]) -> Vec<String> {
    let f = &mut *r.facts;
    let mut wrong = Vec::new();
    for m in measured {
        let name = m.name.as_str();
        f.model(EXP, name, m.faces as f64, if name == "builtin:cube" { "row 1: cube" } else { "–" });
        f.add(EXP, name, "time:tcpu1", "s", Stat::exact(m.gpu.base.as_secs_f64()));
        f.add(EXP, name, "time:tgpu", "s", Stat::exact(m.gpu.passes_total().as_secs_f64()));
        f.add_runs(EXP, name, "time:gpu-path", Stat::median_of(&m.gpu_totals), &m.gpu_totals);
        f.add_runs(EXP, name, "time:tcpu2", Stat::median_of(&m.cpu), &m.cpu);
        f.add_runs(EXP, name, "time:osd", Stat::median_of(&m.osd_runs), &m.osd_runs);
        f.add(EXP, name, "faces", "", Stat::exact(m.faces as f64));
        f.add(EXP, name, "fragments", "", Stat::exact(m.fragments as f64));
        f.add(EXP, name, "passes", "", Stat::exact(m.passes as f64));
        f.add(EXP, name, "gpu-levels", "", Stat::exact(f64::from(m.gpu_levels)));
        if m.verdict != subdiv::Agreement::Match {
            wrong.push(format!("{name}: {}", m.verdict));
        }
    }
    if f.size(EXP, sweep_name).is_none() {
        let faces = levels.last().map_or(0, |l| l.faces);
        f.model(EXP, sweep_name, faces as f64, "–");
    }
    for l in levels {
        let k = |what: &str| format!("level:{}:{what}", l.level);
        f.add_runs(EXP, sweep_name, &k("gpu-path"), Stat::median_of(&l.gpu), &l.gpu);
        f.add_runs(EXP, sweep_name, &k("cpu"), Stat::median_of(&l.cpu), &l.cpu);
        f.add_runs(EXP, sweep_name, &k("osd"), Stat::median_of(&l.osd_runs), &l.osd_runs);
        f.add(EXP, sweep_name, &k("gpu-levels"), "", Stat::exact(f64::from(l.gpu_levels)));
    }
    for w in &wrong {
        r.disagreement(format!("subdivide: {w}"));
    }
    wrong
}

/// The section's opening: what was timed and how, and whether every GPU result equals
/// OpenSubdiv's.
fn section_text(settings: Settings, wrong: &[String]) -> Vec<Block> {
    vec![
        Block::Para(format!(
            "Every model refined to level {LEVEL}: the GPU path (CPU base level TCPU¹, fragment passes TGPU, upload, \
             readback and welded assembly), texgeo's f64 CPU reference (TCPU²) and OpenSubdiv (one thread), each run \
             of the three back to back, medians of {} runs. The thesis' CPU column is CGAL. Every GPU result is compared with OpenSubdiv's, vertex by vertex \
             (1e-5 × bounding-box diagonal). The thesis does not name its models; its first row is the cube.",
            settings.runs
        )),
        Block::Para(if wrong.is_empty() {
            "**The GPU result equals OpenSubdiv's on every vertex and face of every model.**".to_string()
        } else {
            format!("**Results that differ from OpenSubdiv's:** {}.", wrong.join("; "))
        }),
    ]
}

/// The level sweep as a table: medians and spreads per level, and the speed-ups.
fn level_table(sweep_name: &str, levels: &[LevelTimes]) -> Table {
    let mut sweep = Table::new(
        format!("The GPU against the CPU level by level: {sweep_name} (medians, ms)"),
        &[
            "level",
            "faces",
            "GPU levels",
            "GPU path",
            "GPU path spread ± %",
            "CPU reference",
            "CPU reference spread ± %",
            "OpenSubdiv",
            "OpenSubdiv spread ± %",
            "CPU / GPU",
            "OpenSubdiv / GPU",
        ],
    )
    .unit("ms", [3, 5, 7]);
    for l in levels {
        let (g, c, o) = (l.gpu.median_ms(), l.cpu.median_ms(), l.osd.1 * 1e3);
        sweep.row(vec![
            l.level.to_string(),
            l.faces.to_string(),
            l.gpu_levels.to_string(),
            subdiv::ms(l.gpu.median()),
            l.gpu.spread_cell(),
            subdiv::ms(l.cpu.median()),
            l.cpu.spread_cell(),
            subdiv::ms(std::time::Duration::from_secs_f64(l.osd.1)),
            l.osd_runs.spread_cell(),
            format!("{:.2}", c / g.max(1e-9)),
            format!("{:.2}", o / g.max(1e-9)),
        ]);
    }
    sweep.note(
        "Levels the CPU does before fragments exist (1 for quads, 2 otherwise) have no GPU level: there the GPU path \
         is the CPU. Spread: half the range of the runs as a share of the median.",
    );
    sweep
}

/// The level sweep's medians against the level (time on a log axis).
fn level_chart(sweep_name: &str, levels: &[LevelTimes]) -> Chart {
    fn median(s: &Samples) -> f64 {
        s.median().as_secs_f64()
    }
    let curve = |label: &str, colour: usize, time: fn(&LevelTimes) -> f64| Series {
        label: label.to_string(),
        points: levels.iter().map(|l| (f64::from(l.level), time(l))).collect(),
        thesis: false,
        colour,
    };
    let series = vec![
        curve("GPU path", 0, |l| median(&l.gpu)),
        curve("CPU reference", 1, |l| median(&l.cpu)),
        curve("OpenSubdiv", 2, |l| l.osd.1),
    ];
    Chart {
        title: format!("Subdivision time against level: {sweep_name}"),
        x_label: "level".into(),
        y_label: "s".into(),
        x_log: false,
        y_log: true,
        series,
    }
}

/// Table 5's times and the GPU's speed-ups against the faces at level 5, today's beside
/// the thesis'.
fn face_plots(r: &mut Run) -> Result<Vec<Block>> {
    let mut series =
        both("GPU path", 0, curve(r.facts, EXP, "time:gpu-path"), curve(r.thesis, EXP, "time:gpu-path"));
    series.extend(both(
        "CPU (thesis: CGAL)",
        1,
        curve(r.facts, EXP, "time:tcpu2"),
        curve(r.thesis, EXP, "time:tcpu2"),
    ));
    series.extend(both("OpenSubdiv", 2, curve(r.facts, EXP, "time:osd"), Vec::new()));
    let chart =
        Chart::loglog(format!("Table 5: level-{LEVEL} time against faces"), "faces at level 5", "s", series);
    let mut blocks = r.plot(&chart, "subdivide-time-vs-faces")?;
    let cpu = ["time:tcpu2", "time:gpu-path"];
    let speedups: [Speedup; 2] = [
        ("CPU / GPU path".into(), 0, cpu, Some(cpu)),
        ("OpenSubdiv / GPU path".into(), 2, ["time:osd", "time:gpu-path"], None),
    ];
    blocks.extend(speedup_plot(
        r,
        EXP,
        &speedups,
        format!("Subdivision: GPU speed-up at level {LEVEL} against faces"),
        "faces at level 5",
        "subdivide-speedup",
    )?);
    Ok(blocks)
}

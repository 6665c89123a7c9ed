//! Catmull-Clark with fragment meshes (2010 §3.4, Table 5) through `texgeo bench
//! subdivide`'s measuring code, plus a level sweep: where the GPU starts to win.

use super::{Quantity, both, comparison, curve, ratio_curve};
use crate::mesh::{formats, procedural};
use crate::report::bench::subdiv::{self, Model, Settings, default_models};
use crate::report::plot::{Chart, Series};
use crate::report::reproduce::doc::Block;
use crate::report::reproduce::facts::Stat;
use crate::report::reproduce::{Result, Run};
use crate::report::{Environment, Samples, Table};

const EXP: &str = "subdivide";
const LEVEL: u32 = 5;

pub fn run(r: &mut Run) -> Result<Vec<Block>> {
    let mut models = if r.quick {
        ["cube", "pyramid", "knot"]
            .iter()
            .filter_map(|n| procedural::by_name(n).map(|mesh| Model { name: format!("builtin:{n}"), mesh }))
            .collect()
    } else {
        default_models(r.models_dir)?
    };
    // Model names in the report: the file name, not the folder it was found in.
    for m in &mut models {
        if let Some(file) =
            std::path::Path::new(&m.name).file_name().filter(|_| !m.name.starts_with("builtin:"))
        {
            m.name = file.to_string_lossy().into_owned();
        }
    }
    let settings = Settings { level: LEVEL, runs: if r.quick { 3 } else { 5 } + r.repeat, validate: true };
    let measured = subdiv::measure(r.ctx, &models, settings, r.progress)?;

    // The level sweep on the largest model (knot1.off when fetched).
    let knot1 = r.models_dir.join("knot1.off");
    let (sweep_name, sweep_mesh) = if !r.quick && knot1.is_file() {
        ("knot1.off".to_string(), formats::read(&knot1)?)
    } else {
        ("builtin:knot".to_string(), procedural::torus_knot())
    };
    r.progress.total(5);
    let levels = subdiv::per_level(r.ctx, &sweep_mesh, 1..=LEVEL, 3 + r.repeat, r.progress)?;

    let f = &mut *r.facts;
    let mut wrong = Vec::new();
    for m in &measured {
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
    if f.size(EXP, &sweep_name).is_none() {
        let faces = levels.last().map_or(0, |l| l.faces);
        f.model(EXP, &sweep_name, faces as f64, "–");
    }
    for l in &levels {
        let k = |what: &str| format!("level:{}:{what}", l.level);
        f.add_runs(EXP, &sweep_name, &k("gpu-path"), Stat::median_of(&l.gpu), &l.gpu);
        f.add_runs(EXP, &sweep_name, &k("cpu"), Stat::median_of(&l.cpu), &l.cpu);
        f.add_runs(EXP, &sweep_name, &k("osd"), Stat::median_of(&l.osd_runs), &l.osd_runs);
        f.add(EXP, &sweep_name, &k("gpu-levels"), "", Stat::exact(f64::from(l.gpu_levels)));
    }
    for w in &wrong {
        r.disagreement(format!("subdivide: {w}"));
    }

    let mut blocks = vec![Block::Para(format!(
        "Every model refined to level {LEVEL}: the GPU path (CPU base level TCPU¹, fragment passes TGPU, upload, \
         readback and welded assembly), texgeo's f64 CPU reference (TCPU²) and OpenSubdiv (one thread), each run \
         of the three back to back, medians of {} runs. The thesis' CPU column is CGAL. Every GPU result is compared with OpenSubdiv's, vertex by vertex \
         (1e-5 × bounding-box diagonal). The thesis does not name its models; its first row is the cube.",
        settings.runs
    ))];
    blocks.push(Block::Para(if wrong.is_empty() {
        "**The GPU result equals OpenSubdiv's on every vertex and face of every model.**".to_string()
    } else {
        format!("**Results that differ from OpenSubdiv's:** {}.", wrong.join("; "))
    }));
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
    for l in &levels {
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
    blocks.push(r.table(sweep, "subdivide-levels")?);

    let level_curve = |s: &dyn Fn(&subdiv::LevelTimes) -> f64| -> Vec<(f64, f64)> {
        levels.iter().map(|l| (f64::from(l.level), s(l))).collect()
    };
    let median = |s: &Samples| s.median().as_secs_f64();
    let chart = Chart {
        title: format!("Subdivision time against level: {sweep_name}"),
        x_label: "level".into(),
        y_label: "s".into(),
        x_log: false,
        y_log: true,
        series: vec![
            Series {
                label: "GPU path".into(),
                points: level_curve(&|l| median(&l.gpu)),
                thesis: false,
                colour: 0,
            },
            Series {
                label: "CPU reference".into(),
                points: level_curve(&|l| median(&l.cpu)),
                thesis: false,
                colour: 1,
            },
            Series {
                label: "OpenSubdiv".into(),
                points: level_curve(&|l| l.osd.1),
                thesis: false,
                colour: 2,
            },
        ],
    };
    blocks.extend(r.plot(&chart, "subdivide-time-vs-level")?);

    let mut series =
        both("GPU path", 0, curve(r.facts, EXP, "time:gpu-path"), curve(r.thesis, EXP, "time:gpu-path"));
    series.extend(both(
        "CPU (thesis: CGAL)",
        1,
        curve(r.facts, EXP, "time:tcpu2"),
        curve(r.thesis, EXP, "time:tcpu2"),
    ));
    series.extend(both("OpenSubdiv", 2, curve(r.facts, EXP, "time:osd"), Vec::new()));
    let chart = Chart {
        title: format!("Table 5: level-{LEVEL} time against faces"),
        x_label: "faces at level 5".into(),
        y_label: "s".into(),
        x_log: true,
        y_log: true,
        series,
    };
    blocks.extend(r.plot(&chart, "subdivide-time-vs-faces")?);

    let mut series = both(
        "CPU / GPU path",
        0,
        ratio_curve(r.facts, EXP, "time:tcpu2", "time:gpu-path"),
        ratio_curve(r.thesis, EXP, "time:tcpu2", "time:gpu-path"),
    );
    series.extend(both(
        "OpenSubdiv / GPU path",
        2,
        ratio_curve(r.facts, EXP, "time:osd", "time:gpu-path"),
        Vec::new(),
    ));
    let chart = Chart {
        title: format!("Subdivision: GPU speed-up at level {LEVEL} against faces"),
        x_label: "faces at level 5".into(),
        y_label: "speed-up (×)".into(),
        x_log: true,
        y_log: true,
        series,
    };
    blocks.extend(r.plot(&chart, "subdivide-speedup")?);

    blocks.push(Block::Heading(3, "Details (as `texgeo bench subdivide` prints them)".into()));
    let details = subdiv::report(&measured, settings, Environment::new(r.ctx.info().label()));
    for (k, t) in details.tables.into_iter().enumerate() {
        blocks.push(r.table(Table { stem: String::new(), ..t }, &format!("subdivide-bench-{}", k + 1))?);
    }
    Ok(blocks)
}

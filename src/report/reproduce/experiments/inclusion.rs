//! Point in solid (2006 Ch. 4, Tables 4-4 … 4-9) through `texgeo bench inclusion`'s
//! measuring code.

use super::{
    Model, Quantity, Speedup, both, comparison, curve, details, models_table, quick_models, speedup_plot,
    stand_ins, today_or_thesis,
};
use crate::report::Environment;
use crate::report::bench::inclusion::{self, Config, Measured, STAND_INS};
use crate::report::plot::{Chart, Series};
use crate::report::reproduce::doc::Block;
use crate::report::reproduce::facts::{Facts, Stat};
use crate::report::reproduce::{Result, Run};

const EXP: &str = "inclusion";

/// A chart's subject, its file stem and its methods (key, label).
type Curves = (&'static str, &'static str, &'static [(&'static str, &'static str)]);

/// The time curves, two charts of methods with their labels (the CPU test on both, as
/// the yardstick): few enough curves per chart to tell apart.
const METHODS: [Curves; 2] = [
    (
        "the GPU and TetraGrid",
        "inclusion-time-vs-triangles",
        &[
            ("cpu", "Feito-Torres CPU"),
            ("gpu", "GPU"),
            ("gpu+tetragrid", "GPU + TetraGrid 32³"),
            ("tetragrid", "TetraGrid 32³"),
        ],
    ),
    (
        "octants and Jordan",
        "inclusion-time-indexes",
        &[
            ("cpu", "Feito-Torres CPU"),
            ("octants", "octants"),
            ("jordan", "Jordan"),
            ("jordan-octree", "Jordan + octree 6"),
        ],
    ),
];

/// Measures every model with every method (set by set, in turn), adds the facts, then
/// writes the section: the models and answers, Tables 4-4 … 4-9 beside the thesis', the
/// time and TetraGrid plots, and the bench's own tables.
pub fn run(r: &mut Run) -> Result<Vec<Block>> {
    let (models, notes) = models(r)?;
    let cfg = Config { sets: if r.quick { 4 } else { 10 } + r.repeat, ..Config::default() };
    let measured = inclusion::measure(r.ctx, &models, &cfg, r.progress)?;
    record_facts(r, &measured, &cfg);
    let mut blocks = section_text(r, &measured, &cfg, notes)?;
    blocks.extend(thesis_tables(r, &cfg.resolutions)?);
    blocks.extend(time_plots(r, cfg.points)?);
    blocks.extend(tetragrid_plots(r, &cfg.resolutions)?);
    let bench = inclusion::report(&measured, &cfg, Environment::new(r.ctx.info().label()));
    blocks.extend(details(r, EXP, bench.tables)?);
    Ok(blocks)
}

/// The built-in models (`--quick`) or the thesis' stand-ins found, with notes on those
/// missing.
fn models(r: &Run) -> Result<(Vec<inclusion::Model>, Vec<String>)> {
    let (models, notes) =
        if r.quick { (quick_models(), Vec::new()) } else { stand_ins(r.models_dir, STAND_INS)? };
    let models = models
        .into_iter()
        .map(|Model { thesis, name, mesh }| inclusion::Model { thesis, name, mesh })
        .collect();
    Ok((models, notes))
}

/// The facts of every model: each method's time (or why it is missing), each TetraGrid
/// resolution's time, build, memory and share tested, each index's build and memory;
/// and the answers that differ from the exact test.
fn record_facts(r: &mut Run, measured: &[Measured], cfg: &Config) {
    for m in measured {
        let f = &mut *r.facts;
        f.model(EXP, &m.name, m.triangles as f64, m.thesis);
        for (method, samples) in &m.times {
            f.add_runs(EXP, &m.name, &format!("time:{method}"), Stat::mean_of(samples), samples);
        }
        for (method, why) in &m.failed {
            f.missing(EXP, &m.name, &format!("time:{method}"), "s", why);
        }
        for (i, &n) in cfg.resolutions.iter().enumerate() {
            let t = &m.grid_times[i];
            f.add_runs(EXP, &m.name, &format!("time:tetragrid-{n}"), Stat::mean_of(t), t);
            let (_, bytes) = m.grid_builds[i];
            let builds = &m.grid_build_times[i];
            f.add_runs(EXP, &m.name, &format!("build:tetragrid-{n}"), Stat::median_of(builds), builds);
            f.add(EXP, &m.name, &format!("memory:tetragrid-{n}"), "KiB", kib(bytes));
            f.add(EXP, &m.name, &format!("tested:tetragrid-{n}"), "", Stat::exact(m.grid_tested[i]));
        }
        for ((index, stats), builds) in m.index.iter().zip(&m.index_builds) {
            f.add_runs(EXP, &m.name, &format!("build:{index}"), Stat::median_of(builds), builds);
            f.add(EXP, &m.name, &format!("memory:{index}"), "KiB", kib(stats.bytes));
        }
        for d in &m.disagreements {
            r.disagreement(format!("inclusion: {d} on {}", m.name));
        }
    }
}

/// `bytes` in KiB, rounded up.
fn kib(bytes: usize) -> Stat {
    Stat::exact(bytes.div_ceil(1024) as f64)
}

/// The section's opening: how the points were tested, the models, and whether every
/// method agreed with the exact test and which could not run here.
fn section_text(r: &mut Run, measured: &[Measured], cfg: &Config, notes: Vec<String>) -> Result<Vec<Block>> {
    let mut blocks = vec![Block::Para(format!(
        "{} sets of {} uniform random points in each model's bounding box (fixed seeds); a time is the mean per set \
         after one untimed warm-up, as in the thesis (§4.4.2). Every method runs on set 1, then every method on set \
         2, and so on, so that load from other work hits all methods alike and two methods' ratio can be taken set \
         by set. Every method's answer is compared with the exact `cpu` test on every point.",
        cfg.sets, cfg.points
    ))];
    let list: Vec<(String, &str, usize)> =
        measured.iter().map(|m| (m.name.clone(), m.thesis, m.triangles)).collect();
    blocks.push(r.table(models_table(EXP, r, &list), "inclusion-models")?);
    blocks.extend(notes.into_iter().map(Block::Para));
    let wrong: Vec<String> = measured
        .iter()
        .flat_map(|m| m.disagreements.iter().map(move |d| format!("{d} on {}", m.name)))
        .collect();
    blocks.push(Block::Para(if wrong.is_empty() {
        "**All methods agree on every point** of every set.".to_string()
    } else {
        format!("**Methods that disagree with the exact test:** {}.", wrong.join(", "))
    }));
    let failed: Vec<String> = measured
        .iter()
        .flat_map(|m| m.failed.iter().map(move |(k, why)| format!("{k} on {}: {why}", m.name)))
        .collect();
    if !failed.is_empty() {
        blocks.push(Block::Para(format!("**Not measurable on this device:** {}.", failed.join("; "))));
    }
    Ok(blocks)
}

/// Tables 4-4 … 4-9: (id, title, unit, quantities) at the TetraGrid resolutions `res`.
fn thesis_table_quantities(res: &[usize]) -> [(&'static str, &'static str, &'static str, Vec<Quantity>); 6] {
    let mut q44 = Vec::new();
    for n in res {
        q44.push(Quantity::same(format!("{n}³ build (s)"), format!("build:tetragrid-{n}")));
        q44.push(Quantity::same(format!("{n}³ memory (KiB)"), format!("memory:tetragrid-{n}")));
    }
    [
        ("4-4", "Table 4-4: TetraGrid build time and memory", "s or KiB", q44),
        (
            "4-5",
            "Table 4-5: Feito-Torres without and with TetraGrid, s per set",
            "s",
            std::iter::once(Quantity::same("no optimizer", "time:cpu"))
                .chain(
                    res.iter()
                        .map(|n| Quantity::same(format!("TetraGrid {n}³"), format!("time:tetragrid-{n}"))),
                )
                .collect(),
        ),
        (
            "4-6",
            "Table 4-6: versions of Feito-Torres, s per set",
            "s",
            vec![
                Quantity::new("basic (cpu)", "time:cpu", "table4-6:basic"),
                Quantity::new("CPU+GPU", "time:cpu+gpu", "table4-6:cpu+gpu"),
                Quantity::new("GPU", "time:gpu", "table4-6:gpu"),
                Quantity::new("GPU, one tetrahedron per point-vertex", "time:gpu-batch-1", "table4-6:gpu"),
                Quantity::new("octants", "time:octants", "table4-6:octants"),
                Quantity::new("TetraGrid 32³", "time:tetragrid", "table4-6:tetragrid"),
                Quantity::new("GPU + TetraGrid 32³", "time:gpu+tetragrid", "table4-6:gpu+tetragrid"),
            ],
        ),
        (
            "4-7",
            "Table 4-7: memory of each method's index (KiB; a BVH stands where the thesis had a BSP)",
            "KiB",
            vec![
                Quantity::same("Feito (octants)", "memory:octants"),
                Quantity::same("Feito (TetraGrid 32³)", "memory:tetragrid"),
                Quantity::new("BVH (thesis: BSP)", "memory:bvh", "memory:bsp"),
                Quantity::same("Jordan (octree 6)", "memory:jordan-octree"),
            ],
        ),
        (
            "4-8",
            "Table 4-8: time to build each method's index (s)",
            "s",
            vec![
                Quantity::same("Feito (octants)", "build:octants"),
                Quantity::same("Feito (TetraGrid 32³)", "build:tetragrid"),
                Quantity::new("BVH (thesis: BSP)", "build:bvh", "build:bsp"),
                Quantity::same("Jordan (octree 6)", "build:jordan-octree"),
            ],
        ),
        (
            "4-9",
            "Table 4-9: inclusion tests, s per set",
            "s",
            vec![
                Quantity::same("Feito CPU", "time:cpu"),
                Quantity::same("Feito GPU", "time:gpu"),
                Quantity::same("Feito GPU + TetraGrid 32³", "time:gpu+tetragrid"),
                Quantity::new("Feito BVH (thesis: BSP)", "time:bvh", "time:bsp"),
                Quantity::same("Jordan", "time:jordan"),
                Quantity::same("Jordan + octree 6", "time:jordan-octree"),
            ],
        ),
    ]
}

/// Tables 4-4 … 4-9, the thesis' numbers beside today's.
fn thesis_tables(r: &mut Run, res: &[usize]) -> Result<Vec<Block>> {
    let mut blocks = Vec::new();
    for (id, title, unit, quantities) in thesis_table_quantities(res) {
        let mut t = comparison(r, EXP, title, unit, &quantities);
        if id == "4-6" {
            t.note(inclusion::TABLE_4_6_NOTE);
        }
        blocks.push(r.table(t, &format!("inclusion-table{id}"))?);
    }
    Ok(blocks)
}

/// The thesis' Figs. 4-5 … 4-10 as curves, today's beside the thesis': time against
/// triangles per method, and the speed-ups over the CPU test.
fn time_plots(r: &mut Run, points: usize) -> Result<Vec<Block>> {
    let mut blocks = Vec::new();
    for (what, stem, methods) in METHODS {
        let mut series = Vec::new();
        for (i, (key, label)) in methods.iter().enumerate() {
            let k = format!("time:{key}");
            series.extend(both(label, i, curve(r.facts, EXP, &k), curve(r.thesis, EXP, &k)));
        }
        let chart = Chart::loglog(
            format!("Point in solid, {what}: time against triangles (Figs. 4-7, 4-10)"),
            "triangles",
            format!("s per set of {points} points"),
            series,
        );
        blocks.extend(r.plot(&chart, stem)?);
    }
    let speedups: Vec<Speedup> =
        [("time:gpu", "GPU"), ("time:gpu+tetragrid", "GPU + TetraGrid"), ("time:tetragrid", "TetraGrid")]
            .into_iter()
            .enumerate()
            .map(|(i, (key, label))| {
                (format!("cpu / {label}"), i, ["time:cpu", key], Some(["time:cpu", key]))
            })
            .collect();
    blocks.extend(speedup_plot(
        r,
        EXP,
        &speedups,
        "Point in solid: speed-up over the CPU test against triangles",
        "triangles",
        "inclusion-speedup",
    )?);
    Ok(blocks)
}

/// TetraGrid's test time and memory against its resolution, per model (Figs. 4-5, 4-6).
fn tetragrid_plots(r: &mut Run, res: &[usize]) -> Result<Vec<Block>> {
    let mut blocks = Vec::new();
    for (key, what, unit, stem, fig) in [
        ("time", "test time", "s per set", "inclusion-tetragrid-time", "Fig. 4-6"),
        ("memory", "memory", "KiB", "inclusion-tetragrid-memory", "Fig. 4-5"),
    ] {
        let pts = |f: &Facts, m: &str| -> Vec<(f64, f64)> {
            res.iter()
                .filter_map(|&n| {
                    f.get(EXP, m, &format!("{key}:tetragrid-{n}")).ok().map(|s| (n as f64, s.value))
                })
                .collect()
        };
        let mut series = Vec::new();
        for (i, (model, _)) in r.facts.models_of(EXP).iter().enumerate() {
            let thesis_model = r.facts.thesis_name(EXP, model);
            series.push(Series {
                label: model.clone(),
                points: pts(r.facts, model),
                thesis: false,
                colour: i,
            });
            let then = pts(r.thesis, &thesis_model);
            series.extend(today_or_thesis(format!("{thesis_model} (thesis)"), then, true, i));
        }
        let chart = Chart::loglog(
            format!("TetraGrid {what} against resolution ({fig})"),
            "grid resolution n (n³ cells)",
            unit,
            series,
        );
        blocks.extend(r.plot(&chart, stem)?);
    }
    Ok(blocks)
}

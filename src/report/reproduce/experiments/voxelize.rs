//! Solid voxelization (2006 Ch. 5, Table 5-2) through `texgeo bench voxelize`'s
//! measuring code.

use super::{
    Model, Quantity, both, comparison, details, models_table, quick_models, stand_ins, today_or_thesis,
};
use crate::report::Environment;
use crate::report::bench::voxelize::{self, Config, DEFAULT_RESOLUTIONS, Measured, STAND_INS};
use crate::report::plot::Chart;
use crate::report::reproduce::doc::Block;
use crate::report::reproduce::facts::{Facts, Stat};
use crate::report::reproduce::{Result, Run};
use crate::voxel::Method;

const EXP: &str = "voxelize";

/// The thesis' five methods (the exact `scanline` is measured too, as the reference).
const SLICERS: [Method; 5] = [Method::Cpu, Method::Fgpu, Method::Pgpu, Method::Zoned, Method::Fang];

/// The resolutions a plot looks for, the thesis' and today's.
const PLOTTED: [usize; 6] = [32, 64, 128, 256, 512, 1024];

/// What the experiment found over all models, for its section.
#[derive(Default)]
struct Findings {
    /// (name, thesis model, triangles) of the models measured.
    list: Vec<(String, &'static str, usize)>,
    /// Volumes that differ from the exact one: method, model and resolution.
    wrong: Vec<String>,
    /// Why methods could not run here, each reason with the methods it stops.
    failed: Vec<(String, Vec<String>)>,
}

/// Measures every model with every method at every resolution (in turn, round by
/// round), adds the facts, then writes the section: the models and answers, Table 5-2
/// beside the thesis', the plots and the bench's own tables.
pub fn run(r: &mut Run) -> Result<Vec<Block>> {
    let (models, notes) = models(r)?;
    let cfg = Config {
        resolutions: if r.quick { vec![64, 128] } else { DEFAULT_RESOLUTIONS.to_vec() },
        methods: Method::ALL.to_vec(),
        runs: 3 + r.repeat,
        zone: crate::voxel::Zone::Auto,
    };
    let measured = voxelize::measure(r.ctx, &models, &cfg, r.progress)?;
    let found = record_facts(r, &measured);
    let mut blocks = section_text(r, &cfg, notes, &found)?;
    let t = comparison(r, EXP, "Table 5-2: voxelization time per method", "s", &quantities(&cfg.resolutions));
    blocks.push(r.table(t, "voxelize-table5-2")?);
    blocks.extend(time_plots(r)?);
    blocks.extend(r.plot(&speedup_chart(r), "voxelize-speedup")?);
    let bench = voxelize::report(&measured, &cfg, Environment::new(r.ctx.info().label()));
    blocks.extend(details(r, EXP, bench.tables)?);
    Ok(blocks)
}

/// `--quick`: the knot and the finest tube, two sizes eight times apart; else the
/// thesis' stand-ins found, with notes on those missing.
fn models(r: &Run) -> Result<(Vec<voxelize::Model>, Vec<String>)> {
    let (models, notes) = if r.quick {
        let mut q = quick_models();
        q.remove(1);
        (q, Vec::new())
    } else {
        stand_ins(r.models_dir, STAND_INS)?
    };
    let models = models
        .into_iter()
        .map(|Model { thesis, name, mesh }| voxelize::Model { thesis, name, mesh })
        .collect();
    Ok((models, notes))
}

/// Every method's time at every resolution (or why it is missing), and what the section
/// says about the models, the answers and the methods that could not run.
fn record_facts(r: &mut Run, measured: &[Measured]) -> Findings {
    let mut found = Findings::default();
    for m in measured {
        r.facts.model(EXP, &m.model, m.triangles as f64, m.thesis);
        if !found.list.iter().any(|l| l.0 == m.model) {
            found.list.push((m.model.clone(), m.thesis, m.triangles));
        }
        let key = format!("time:{}@{}", m.method, m.n);
        match &m.result {
            Ok(res) => {
                r.facts.add_runs(EXP, &m.model, &key, Stat::median_of(&res.times.total), &res.times.total);
                if !res.identical {
                    found.wrong.push(format!("{} on {} at {}³", m.method, m.model, m.n));
                }
            }
            Err(why) => {
                r.facts.missing(EXP, &m.model, &key, "s", why);
                // One line per reason: the methods it stops, every model and resolution.
                match found.failed.iter_mut().find(|(w, _)| w == why) {
                    Some((_, methods)) if !methods.contains(&m.method.to_string()) => {
                        methods.push(m.method.to_string())
                    }
                    Some(_) => {}
                    None => found.failed.push((why.clone(), vec![m.method.to_string()])),
                }
            }
        }
    }
    for w in &found.wrong {
        r.disagreement(format!("voxelize: {w}"));
    }
    found
}

/// The section's opening: how the volumes were timed and checked, the models, the
/// answers, and the methods this device could not run.
fn section_text(r: &mut Run, cfg: &Config, notes: Vec<String>, found: &Findings) -> Result<Vec<Block>> {
    let mut blocks = vec![Block::Para(format!(
        "Every method at {} voxels per side, {} timed rounds after a warm-up, each round running every method in \
         turn (medians, CPU preparation included; the thesis left the display lists' compilation out). Every volume is compared voxel by voxel with the exact \
         `scanline` classification.",
        cfg.resolutions.iter().map(|n| format!("{n}³")).collect::<Vec<_>>().join(", "),
        cfg.runs
    ))];
    blocks.push(r.table(models_table(EXP, r, &found.list), "voxelize-models")?);
    blocks.extend(notes.into_iter().map(Block::Para));
    blocks.push(Block::Para(if found.wrong.is_empty() {
        "**All methods agree on every voxel** (each volume equals the exact one).".to_string()
    } else {
        format!("**Volumes that differ from the exact one:** {}.", found.wrong.join(", "))
    }));
    for (why, methods) in &found.failed {
        blocks
            .push(Block::Para(format!("**Not measurable on this device:** {} ({why}).", methods.join(", "))));
    }
    Ok(blocks)
}

/// Table 5-2's rows: every slicer and the exact `scanline` at every resolution.
fn quantities(resolutions: &[usize]) -> Vec<Quantity> {
    let mut quantities = Vec::new();
    for n in resolutions {
        for m in SLICERS.iter().chain([Method::Scanline].iter()) {
            quantities.push(Quantity::same(format!("{n}³ {m}"), format!("time:{m}@{n}")));
        }
    }
    quantities
}

/// Time against resolution per model (the thesis' Figs. 5-10, 5-11 show the same
/// numbers against models), today's beside the thesis'.
fn time_plots(r: &mut Run) -> Result<Vec<Block>> {
    let mut blocks = Vec::new();
    for (k, (model, _)) in r.facts.models_of(EXP).into_iter().enumerate() {
        let thesis_model = r.facts.thesis_name(EXP, &model);
        let mut series = Vec::new();
        for (i, m) in SLICERS.iter().enumerate() {
            let pts = |f: &Facts, name: &str| -> Vec<(f64, f64)> {
                PLOTTED
                    .iter()
                    .filter_map(|&n| {
                        f.get(EXP, name, &format!("time:{m}@{n}")).ok().map(|s| (n as f64, s.value))
                    })
                    .collect()
            };
            series.extend(both(m.name(), i, pts(r.facts, &model), pts(r.thesis, &thesis_model)));
        }
        let chart = Chart::loglog(
            format!("Voxelization time against resolution: {model} (thesis: {thesis_model})"),
            "voxels per side N",
            "s",
            series,
        );
        blocks.extend(r.plot(&chart, &format!("voxelize-time-{}", k + 1))?);
    }
    Ok(blocks)
}

/// The GPU slicers' speed-ups over the CPU slicer against resolution, per model.
fn speedup_chart(r: &Run) -> Chart {
    let mut series = Vec::new();
    for (k, (model, _)) in r.facts.models_of(EXP).into_iter().enumerate() {
        let thesis_model = r.facts.thesis_name(EXP, &model);
        for (j, gpu) in [Method::Pgpu, Method::Zoned].iter().enumerate() {
            let pts = |f: &Facts, name: &str| -> Vec<(f64, f64)> {
                PLOTTED
                    .iter()
                    .filter_map(|&n| {
                        let c = f.get(EXP, name, &format!("time:cpu@{n}")).ok()?;
                        let g = f.get(EXP, name, &format!("time:{gpu}@{n}")).ok()?;
                        Some((n as f64, c.value / g.value))
                    })
                    .collect()
            };
            let colour = 2 * k + j;
            series.extend(today_or_thesis(
                format!("cpu / {gpu}: {model}"),
                pts(r.facts, &model),
                false,
                colour,
            ));
            let then = pts(r.thesis, &thesis_model);
            series.extend(today_or_thesis(
                format!("cpu / {gpu}: {thesis_model} (thesis)"),
                then,
                true,
                colour,
            ));
        }
    }
    Chart::loglog(
        "Voxelization: GPU speed-up over the CPU slicer",
        "voxels per side N",
        "speed-up (×)",
        series,
    )
}

//! Solid voxelization (2006 Ch. 5, Table 5-2) through `texgeo bench voxelize`'s
//! measuring code.

use super::{Model, Quantity, both, comparison, models_table, quick_models, stand_ins};
use crate::report::bench::voxelize::{self, Config, DEFAULT_RESOLUTIONS, STAND_INS};
use crate::report::plot::{Chart, Series};
use crate::report::reproduce::doc::Block;
use crate::report::reproduce::facts::Stat;
use crate::report::reproduce::{Result, Run};
use crate::report::{Environment, Table};
use crate::voxel::Method;

const EXP: &str = "voxelize";

/// The thesis' five methods (the exact `scanline` is measured too, as the reference).
const SLICERS: [Method; 5] = [Method::Cpu, Method::Fgpu, Method::Pgpu, Method::Zoned, Method::Fang];

pub fn run(r: &mut Run) -> Result<Vec<Block>> {
    let (models, notes) = if r.quick {
        // The knot and the finest tube: two sizes eight times apart.
        let mut q = quick_models();
        q.remove(1);
        (q, Vec::new())
    } else {
        stand_ins(r.models_dir, STAND_INS)?
    };
    let cfg = Config {
        resolutions: if r.quick { vec![64, 128] } else { DEFAULT_RESOLUTIONS.to_vec() },
        methods: Method::ALL.to_vec(),
        runs: 3 + r.repeat,
        zone: crate::voxel::Zone::Auto,
    };
    let models: Vec<voxelize::Model> = models
        .into_iter()
        .map(|Model { thesis, name, mesh }| voxelize::Model { thesis, name, mesh })
        .collect();
    let measured = voxelize::measure(r.ctx, &models, &cfg, r.progress)?;

    let mut list: Vec<(String, &str, usize)> = Vec::new();
    let mut wrong = Vec::new();
    let mut failed: Vec<(String, Vec<String>)> = Vec::new();
    for m in &measured {
        r.facts.model(EXP, &m.model, m.triangles as f64, m.thesis);
        if !list.iter().any(|l| l.0 == m.model) {
            list.push((m.model.clone(), m.thesis, m.triangles));
        }
        let key = format!("time:{}@{}", m.method, m.n);
        match &m.result {
            Ok(res) => {
                r.facts.add_runs(EXP, &m.model, &key, Stat::median_of(&res.times.total), &res.times.total);
                if !res.identical {
                    wrong.push(format!("{} on {} at {}³", m.method, m.model, m.n));
                }
            }
            Err(why) => {
                r.facts.missing(EXP, &m.model, &key, "s", why);
                // One line per reason: the methods it stops, every model and resolution.
                match failed.iter_mut().find(|(w, _)| w == why) {
                    Some((_, methods)) if !methods.contains(&m.method.to_string()) => {
                        methods.push(m.method.to_string())
                    }
                    Some(_) => {}
                    None => failed.push((why.clone(), vec![m.method.to_string()])),
                }
            }
        }
    }
    for w in &wrong {
        r.disagreement(format!("voxelize: {w}"));
    }

    let mut blocks = vec![Block::Para(format!(
        "Every method at {} voxels per side, {} timed rounds after a warm-up, each round running every method in \
         turn (medians, CPU preparation included; the thesis left the display lists' compilation out). Every volume is compared voxel by voxel with the exact \
         `scanline` classification.",
        cfg.resolutions.iter().map(|n| format!("{n}³")).collect::<Vec<_>>().join(", "),
        cfg.runs
    ))];
    blocks.push(r.table(models_table(EXP, r, &list), "voxelize-models")?);
    blocks.extend(notes.into_iter().map(Block::Para));
    blocks.push(Block::Para(if wrong.is_empty() {
        "**All methods agree on every voxel** (each volume equals the exact one).".to_string()
    } else {
        format!("**Volumes that differ from the exact one:** {}.", wrong.join(", "))
    }));
    for (why, methods) in &failed {
        blocks
            .push(Block::Para(format!("**Not measurable on this device:** {} ({why}).", methods.join(", "))));
    }

    let mut quantities = Vec::new();
    for n in &cfg.resolutions {
        for m in SLICERS.iter().chain([Method::Scanline].iter()) {
            quantities.push(Quantity::same(format!("{n}³ {m}"), format!("time:{m}@{n}")));
        }
    }
    let t = comparison(r, EXP, "Table 5-2: voxelization time per method", "s", &quantities);
    blocks.push(r.table(t, "voxelize-table5-2")?);

    // Plots: time against resolution per model (the thesis' Figs. 5-10, 5-11 show the
    // same numbers against models), and the GPU/CPU speed-ups.
    for (k, (model, _)) in r.facts.models_of(EXP).into_iter().enumerate() {
        let thesis_model = r.facts.thesis_name(EXP, &model);
        let mut series = Vec::new();
        for (i, m) in SLICERS.iter().enumerate() {
            let pts = |f: &crate::report::reproduce::Facts, name: &str| -> Vec<(f64, f64)> {
                [32usize, 64, 128, 256, 512, 1024]
                    .iter()
                    .filter_map(|&n| {
                        f.get(EXP, name, &format!("time:{m}@{n}")).ok().map(|s| (n as f64, s.value))
                    })
                    .collect()
            };
            series.extend(both(m.name(), i, pts(r.facts, &model), pts(r.thesis, &thesis_model)));
        }
        let chart = Chart {
            title: format!("Voxelization time against resolution: {model} (thesis: {thesis_model})"),
            x_label: "voxels per side N".into(),
            y_label: "s".into(),
            x_log: true,
            y_log: true,
            series,
        };
        blocks.extend(r.plot(&chart, &format!("voxelize-time-{}", k + 1))?);
    }
    let mut series = Vec::new();
    for (k, (model, _)) in r.facts.models_of(EXP).into_iter().enumerate() {
        let thesis_model = r.facts.thesis_name(EXP, &model);
        for (j, gpu) in [Method::Pgpu, Method::Zoned].iter().enumerate() {
            let pts = |f: &crate::report::reproduce::Facts, name: &str| -> Vec<(f64, f64)> {
                [32usize, 64, 128, 256, 512, 1024]
                    .iter()
                    .filter_map(|&n| {
                        let c = f.get(EXP, name, &format!("time:cpu@{n}")).ok()?;
                        let g = f.get(EXP, name, &format!("time:{gpu}@{n}")).ok()?;
                        Some((n as f64, c.value / g.value))
                    })
                    .collect()
            };
            let today = pts(r.facts, &model);
            let colour = 2 * k + j;
            if !today.is_empty() {
                series.push(Series {
                    label: format!("cpu / {gpu}: {model}"),
                    points: today,
                    thesis: false,
                    colour,
                });
            }
            let then = pts(r.thesis, &thesis_model);
            if !then.is_empty() {
                series.push(Series {
                    label: format!("cpu / {gpu}: {thesis_model} (thesis)"),
                    points: then,
                    thesis: true,
                    colour,
                });
            }
        }
    }
    let chart = Chart {
        title: "Voxelization: GPU speed-up over the CPU slicer".into(),
        x_label: "voxels per side N".into(),
        y_label: "speed-up (×)".into(),
        x_log: true,
        y_log: true,
        series,
    };
    blocks.extend(r.plot(&chart, "voxelize-speedup")?);

    blocks.push(Block::Heading(3, "Details (as `texgeo bench voxelize` prints them)".into()));
    let details = voxelize::report(&measured, &cfg, Environment::new(r.ctx.info().label()));
    for (k, t) in details.tables.into_iter().enumerate() {
        blocks.push(r.table(Table { stem: String::new(), ..t }, &format!("voxelize-bench-{}", k + 1))?);
    }
    Ok(blocks)
}

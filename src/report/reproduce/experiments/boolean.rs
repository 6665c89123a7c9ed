//! Boolean operations (2006 Ch. 6, Table 6-1) through `texgeo bench boolean`'s measuring
//! code: each pair is a solid and its turned copy; phase 1 (index + refinement), phase 2
//! (classification + assembly) with grouped classification on CPU and GPU point tests and
//! with plain classification, every answer checked by the volume identity and, when the
//! helper is built, against CGAL's exact corefinement.

use std::time::Duration;

use super::{Model, Quantity, both, comparison, curve, models_table, num, ratio_curve, stand_ins};
use crate::boolean::{Grouping, cgal};
use crate::inclusion::Method;
use crate::mesh::{Mesh, procedural};
use crate::report::Samples;
use crate::report::Table;
use crate::report::bench::boolean::{OPERATIONS, Pair, STAND_INS, measure_interleaved, sequential};
use crate::report::plot::Chart;
use crate::report::reproduce::doc::Block;
use crate::report::reproduce::facts::Stat;
use crate::report::reproduce::{Result, Run};

const EXP: &str = "boolean";

/// Relative volume agreement asked of the identity and of CGAL (as the Boolean tests ask).
const TOLERANCE: f64 = 1e-9;

/// The CPU point test of the timed runs (the Boolean command's default).
const CPU_METHOD: Method = Method::Octants;

/// Built-in solids for `--quick`, each paired with its turned copy: a torus and the
/// thesis' torus knot (its Torre stand-in) and finer tubes around the same knot, about
/// 1 000 to 19 000 triangles a pair.
fn quick_models() -> Vec<Model> {
    vec![
        Model { thesis: "–", name: "torus 24×12".into(), mesh: procedural::torus(1.0, 0.4, 24, 12) },
        Model { thesis: "Torre", name: "builtin:knot".into(), mesh: procedural::torus_knot() },
        Model { thesis: "–", name: "knot tube 150×12".into(), mesh: procedural::torus_knot_tube(150, 12) },
        Model { thesis: "–", name: "knot tube 300×16".into(), mesh: procedural::torus_knot_tube(300, 16) },
    ]
}

fn volume(m: &Mesh) -> f64 {
    crate::mesh::covering::measures(m).0
}

/// Element-wise sums of timed runs (the same runs of one evaluation's parts).
fn sum(parts: &[&Samples]) -> Samples {
    let n = parts.iter().map(|s| s.0.len()).min().unwrap_or(0);
    Samples((0..n).map(|i| parts.iter().map(|s| s.0[i]).sum::<Duration>()).collect())
}

fn ms(d: Duration) -> String {
    format!("{:.1}", d.as_secs_f64() * 1e3)
}

pub fn run(r: &mut Run) -> Result<Vec<Block>> {
    let (models, notes) =
        if r.quick { (quick_models(), Vec::new()) } else { stand_ins(r.models_dir, STAND_INS)? };
    let runs = 3 + r.repeat;
    let cgal_ready = cgal::helper_path().is_ok();
    r.progress.total(models.len() as u64);

    let columns = [
        &["pair (A and its turned copy)"][..],
        &crate::report::bench::boolean::PHASE_COLUMNS,
        &["total grouped GPU", "CGAL corefinement", "volume", "check"],
    ]
    .concat();
    let mut table = Table::new("Table 6-1 today: Boolean operations (ms)", &columns);
    let mut list: Vec<(String, &str, usize)> = Vec::new();
    let mut refused = Vec::new();
    let mut failed = Vec::new();
    let mut wrong: Vec<String> = Vec::new();
    let mut checked_cgal = 0usize;
    let mut cgal_declined = Vec::new();
    for model in models {
        r.progress.step(&format!("{}: phases, grouped and plain, CPU and GPU", model.name));
        let pair = Pair::with_turned_copy(model.thesis, model.name.clone(), model.mesh)?;
        let triangles = pair.a.num_faces() + pair.b.num_faces();
        // Grouped with CPU and with GPU point tests, and plain, in turn, run after run.
        let (cpu, gpu, plain) = (
            sequential(CPU_METHOD, Grouping::Grouped),
            sequential(Method::Gpu, Grouping::Grouped),
            sequential(CPU_METHOD, Grouping::Plain),
        );
        let measured = measure_interleaved(&pair, &[(&cpu, None), (&gpu, Some(r.ctx)), (&plain, None)], runs);
        let mut measured = match measured {
            Err(e @ crate::boolean::BooleanError::Input { .. }) => {
                refused.push(format!("{} ({e})", pair.name));
                continue;
            }
            // A pair texgeo cannot evaluate is named, and the other pairs measured.
            Err(e @ crate::boolean::BooleanError::Refine(_)) => {
                failed.push(format!("{}: {e}", pair.name));
                continue;
            }
            other => other?,
        };
        let three = "three variants";
        let (_, p2_plain, asm_plain, ev_plain) = measured.pop().unwrap_or_else(|| unreachable!("{three}"));
        let (_, p2_gpu, asm_gpu, ev_gpu) = measured.pop().unwrap_or_else(|| unreachable!("{three}"));
        let (p1, p2, asm, ev) = measured.pop().unwrap_or_else(|| unreachable!("{three}"));
        let same = |a: &crate::boolean::Evaluation| {
            a.classification.a == ev.classification.a && a.classification.b == ev.classification.b
        };
        if !same(&ev_gpu) {
            wrong.push(format!("{}: GPU point tests classify differently from the CPU's", pair.name));
        }
        if !same(&ev_plain) {
            wrong.push(format!("{}: plain classification differs from grouped", pair.name));
        }

        // Every answer: vol(A∪B) + vol(A∩B) = vol(A) + vol(B) and vol(A−B) = vol(A) − vol(A∩B),
        // from the one refinement; CGAL's volumes when the helper is built.
        let results: Vec<Mesh> =
            OPERATIONS.iter().map(|&op| ev.result(op, true)).collect::<std::result::Result<_, _>>()?;
        let vols: Vec<f64> = results.iter().map(volume).collect();
        let (va, vb) = (volume(&pair.a), volume(&pair.b));
        let scale = (va + vb).abs().max(f64::MIN_POSITIVE);
        let identity = (vols[0] + vols[1] - va - vb).abs() / scale;
        let difference = (vols[2] - (va - vols[1])).abs() / scale;
        if identity > TOLERANCE || difference > TOLERANCE {
            wrong.push(format!(
                "{}: volume identities off by {identity:.1e} / {difference:.1e} relative",
                pair.name
            ));
        }
        let reference = if cgal_ready {
            // --quick: one CGAL run per operation, enough to check the volumes.
            match cgal::reference(&pair.a, &pair.b, Some(if r.quick { 1 } else { runs as u32 })) {
                Ok(reference) => Some(reference),
                Err(e) => {
                    cgal_declined.push(format!("{}: {e}", pair.name));
                    None
                }
            }
        } else {
            None
        };

        let s = ev.classification.stats;
        let name = pair.name.clone();
        r.facts.model(EXP, &name, triangles as f64, pair.thesis);
        list.push((name.clone(), pair.thesis, triangles));
        let phase2_cpu = sum(&[&p2, &asm[2]]);
        let phase2_gpu = sum(&[&p2_gpu, &asm_gpu[2]]);
        let phase2_plain = sum(&[&p2_plain, &asm_plain[2]]);
        let timed = |f: &mut crate::report::reproduce::Facts, key: &str, s: &Samples| {
            f.add_runs(EXP, &name, key, Stat::median_of(s), s);
        };
        timed(r.facts, "time:phase1", &p1);
        timed(r.facts, "time:phase2-grouped", &phase2_cpu);
        timed(r.facts, "time:phase2-cpu", &phase2_cpu);
        timed(r.facts, "time:phase2-gpu", &phase2_gpu);
        timed(r.facts, "time:phase2-plain", &phase2_plain);
        timed(r.facts, "time:total", &sum(&[&p1, &p2, &asm[2]]));
        r.facts.add(EXP, &name, "reduction", "", Stat::exact(s.saved_share()));
        r.facts.add(EXP, &name, "point-tests", "", Stat::exact(s.point_tests as f64));
        r.facts.add(
            EXP,
            &name,
            "point-tests-plain",
            "",
            Stat::exact(ev_plain.classification.stats.point_tests as f64),
        );
        // All three operations from one refinement and classification, against the
        // dearest single one.
        let all = sum(&[&p1, &p2, &asm[0], &asm[1], &asm[2]]);
        let dearest = (0..OPERATIONS.len()).max_by_key(|&k| asm[k].median()).unwrap_or(0);
        timed(r.facts, "time:all-ops", &all);
        timed(r.facts, "time:one-op", &sum(&[&p1, &p2, &asm[dearest]]));
        for (k, &op) in OPERATIONS.iter().enumerate() {
            let grouped_gpu = sum(&[&p1, &p2_gpu, &asm_gpu[k]]);
            let grouped_cpu = sum(&[&p1, &p2, &asm[k]]);
            let plain = sum(&[&p1, &p2_plain, &asm_plain[k]]);
            for (kind, times) in [("grouped", &grouped_gpu), ("grouped-cpu", &grouped_cpu), ("plain", &plain)]
            {
                r.facts.add(EXP, &name, &format!("time:{kind}:{}", op.name()), "s", Stat::median_of(times));
            }
            let cgal_cell = match &reference {
                None => "–".to_string(),
                Some(reference) => match reference.measures(op) {
                    None => "declined".to_string(),
                    Some((cv, _)) => {
                        checked_cgal += 1;
                        let rel = (vols[k] - cv).abs() / cv.abs().max(f64::MIN_POSITIVE);
                        if rel > TOLERANCE {
                            wrong.push(format!(
                                "{} {} : volume {} vs CGAL's {} ({rel:.1e} relative)",
                                pair.name,
                                op.symbol(),
                                vols[k],
                                cv
                            ));
                        }
                        reference.median_seconds(op).map_or("timed out".into(), |t| format!("{:.1}", t * 1e3))
                    }
                },
            };
            let check = match &reference {
                Some(reference) => match reference.measures(op) {
                    Some((cv, _)) => {
                        format!("CGAL {:.1e}", (vols[k] - cv).abs() / cv.abs().max(f64::MIN_POSITIVE))
                    }
                    None => format!("identity {:.1e}", identity.max(difference)),
                },
                None => format!("identity {:.1e}", identity.max(difference)),
            };
            table.row(vec![
                name.clone(),
                pair.thesis.to_string(),
                op.symbol().to_string(),
                triangles.to_string(),
                (ev.refinement.stats.cut_a + ev.refinement.stats.cut_b).to_string(),
                format!("{} / {}", s.point_tests, ev_plain.classification.stats.point_tests),
                format!("{:.1} %", 100.0 * s.saved_share()),
                ms(p1.median()),
                ms(p2.median() + asm[k].median()),
                ms(p2_gpu.median() + asm_gpu[k].median()),
                ms(p2_plain.median() + asm_plain[k].median()),
                ms(grouped_gpu.median()),
                cgal_cell,
                num(vols[k]),
                check,
            ]);
        }
    }
    for w in &wrong {
        r.disagreement(format!("boolean: {w}"));
    }
    for f in &failed {
        r.disagreement(format!("boolean: no answer on {f}"));
    }
    table.note(format!(
        "Medians of {runs} runs after a warm-up, each run measuring grouped CPU, grouped GPU and plain in turn. \
         Each pair is a solid and its copy \
         rotated 10° about y and moved by 1 % of its diagonal along x (`texgeo bench boolean`'s pairs); triangles = \
         both operands. phase 1 = index + pair tests + intersection points + re-triangulation; phase 2 = both \
         inclusion classifiers + on-tests + groups (grouped) + point tests + the operation's assembly. CPU point tests \
         by `{CPU_METHOD}`, GPU = Feito-Torres on the GPU with its exact fallback. total grouped GPU = phase 1 + phase 2 \
         grouped GPU, the thesis' \"optimizado\". check: the result's volume against CGAL's (relative), or, without \
         CGAL, the larger of the volume identities' gaps."
    ));
    if !refused.is_empty() {
        table.note(format!("Refused as operands, so not measured: {}.", refused.join("; ")));
    }

    let mut blocks = vec![Block::Para(format!(
        "Every pair is measured with grouped classification (one point test per group, §6.5.1) on the CPU and on \
         the GPU, and with plain classification (one point test per triangle), {runs} timed runs after a warm-up, the three \
         back to back in every run so that load from other work hits them alike. \
         Union, intersection and difference are all assembled from the one refinement and classification."
    ))];
    blocks.push(r.table(models_table(EXP, r, &list), "boolean-models")?);
    blocks.extend(notes.into_iter().map(Block::Para));
    let how = if checked_cgal > 0 {
        format!(
            "every result's volume against CGAL's exact corefinement ({checked_cgal} results, relative {TOLERANCE:e}), \
             and vol(A∪B) + vol(A∩B) = vol(A) + vol(B), vol(A−B) = vol(A) − vol(A∩B) on every pair"
        )
    } else {
        format!(
            "vol(A∪B) + vol(A∩B) = vol(A) + vol(B) and vol(A−B) = vol(A) − vol(A∩B) on every pair (relative \
             {TOLERANCE:e}); CGAL's helper is {} (run tools/setup)",
            if cgal_ready { "declined every pair" } else { "not built" }
        )
    };
    blocks.push(Block::Para(if wrong.is_empty() {
        format!(
            "**All methods agree on every triangle** (CPU and GPU point tests, grouped and plain classification give \
             the same class to every refined triangle). Checked: {how}."
        )
    } else {
        format!("**Answers that differ:** {}. Checked: {how}.", wrong.join("; "))
    }));
    if !failed.is_empty() {
        blocks.push(Block::Para(format!("**Pairs texgeo could not evaluate:** {}.", failed.join("; "))));
    }
    if !cgal_declined.is_empty() {
        blocks.push(Block::Para(format!("CGAL could not answer: {}.", cgal_declined.join("; "))));
    }
    blocks.push(r.table(table, "boolean-table6-1-today")?);

    let mut quantities = Vec::new();
    for op in OPERATIONS {
        quantities.push(Quantity::same(
            format!("{} plain total", op.symbol()),
            format!("time:plain:{}", op.name()),
        ));
        quantities.push(Quantity::same(
            format!("{} grouped total", op.symbol()),
            format!("time:grouped:{}", op.name()),
        ));
    }
    quantities.push(Quantity::same("phase 1 (A − B)", "time:phase1"));
    quantities.push(Quantity::new(
        "phase 2 grouped, GPU point tests (A − B)",
        "time:phase2-gpu",
        "time:phase2-grouped",
    ));
    quantities.push(Quantity::same("phase 2 plain (A − B)", "time:phase2-plain"));
    let t = comparison(r, EXP, "Table 6-1: thesis beside today", "s", &quantities);
    blocks.push(r.table(t, "boolean-table6-1")?);

    // Time against triangles per phase and method, the thesis' beside ours.
    let series = [
        ("phase 1", "time:phase1", "time:phase1"),
        ("phase 2 grouped GPU", "time:phase2-gpu", "time:phase2-grouped"),
        ("phase 2 grouped CPU", "time:phase2-cpu", "-"),
        ("phase 2 plain", "time:phase2-plain", "time:phase2-plain"),
        ("total grouped", "time:total", "time:total"),
    ]
    .iter()
    .enumerate()
    .flat_map(|(i, &(label, today, thesis))| {
        both(label, i, curve(r.facts, EXP, today), curve(r.thesis, EXP, thesis))
    })
    .collect();
    let chart = Chart {
        title: "Boolean operations (A − B): time against triangles per phase and method".into(),
        x_label: "triangles (both operands)".into(),
        y_label: "s".into(),
        x_log: true,
        y_log: true,
        series,
    };
    blocks.extend(r.plot(&chart, "boolean-time")?);
    let mut series = both(
        "phase 2 plain / grouped",
        0,
        ratio_curve(r.facts, EXP, "time:phase2-plain", "time:phase2-cpu"),
        ratio_curve(r.thesis, EXP, "time:phase2-plain", "time:phase2-grouped"),
    );
    series.extend(both(
        "phase 2 CPU / GPU",
        1,
        ratio_curve(r.facts, EXP, "time:phase2-cpu", "time:phase2-gpu"),
        Vec::new(),
    ));
    let chart = Chart {
        title: "Boolean operations: grouped classification's and the GPU's speed-ups in phase 2".into(),
        x_label: "triangles (both operands)".into(),
        y_label: "speed-up (×)".into(),
        x_log: true,
        y_log: true,
        series,
    };
    blocks.extend(r.plot(&chart, "boolean-speedup")?);
    Ok(blocks)
}

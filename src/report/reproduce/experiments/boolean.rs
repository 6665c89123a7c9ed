//! Boolean operations (2006 Ch. 6, Table 6-1) through `texgeo bench boolean`'s measuring
//! code: each pair is a solid and its turned copy; phase 1 (index + refinement), phase 2
//! (classification + assembly) with grouped classification on CPU and GPU point tests and
//! with plain classification, every answer checked by the volume identity and, when the
//! helper is built, against CGAL's exact corefinement.

use std::time::Duration;

use super::{Model, Quantity, Speedup, both, comparison, curve, models_table, num, speedup_plot, stand_ins};
use crate::boolean::{Grouping, cgal};
use crate::inclusion::Method;
use crate::mesh::{Mesh, procedural};
use crate::report::Samples;
use crate::report::Table;
use crate::report::bench::boolean::{OPERATIONS, Pair, STAND_INS, Timed, measure_interleaved, sequential};
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

fn ms(d: Duration) -> String {
    format!("{:.1}", d.as_secs_f64() * 1e3)
}

/// The three timed variants of one pair, each run after run in turn: grouped
/// classification with CPU point tests, with GPU point tests, and plain classification.
struct Variants {
    grouped: Timed,
    gpu: Timed,
    plain: Timed,
}

/// What the experiment found over all pairs, for its section.
#[derive(Default)]
struct Findings {
    /// (name, thesis pair, triangles) of the pairs measured.
    list: Vec<(String, &'static str, usize)>,
    /// Pairs refused as operands, and pairs texgeo could not evaluate.
    refused: Vec<String>,
    failed: Vec<String>,
    /// Answers that differ between variants or from the volumes' checks.
    wrong: Vec<String>,
    /// Results whose volume was checked against CGAL's, and pairs CGAL declined.
    checked_cgal: usize,
    cgal_declined: Vec<String>,
}

/// Measures every pair (grouped CPU, grouped GPU and plain in turn), checks every answer,
/// adds the facts, then writes the section: Table 6-1 today, the thesis beside today,
/// the plots.
pub fn run(r: &mut Run) -> Result<Vec<Block>> {
    let (models, notes) =
        if r.quick { (quick_models(), Vec::new()) } else { stand_ins(r.models_dir, STAND_INS)? };
    let runs = 3 + r.repeat;
    let cgal_ready = cgal::helper_path().is_ok();
    r.progress.total(models.len() as u64);
    let columns = [
        &["pair (A and its turned copy)"][..],
        &crate::report::bench::boolean::PHASE_COLUMNS,
        &["total grouped GPU", "CGAL corefinement", "volume", "checked against", "relative gap"],
    ]
    .concat();
    let mut table = Table::new("Table 6-1 today: Boolean operations (ms)", &columns)
        .unit("ms", crate::report::bench::boolean::PHASE_MS)
        .unit("ms", 16..=17);
    let mut found = Findings::default();
    for model in models {
        r.progress.step(&format!("{}: phases, grouped and plain, CPU and GPU", model.name));
        let pair = Pair::with_turned_copy(model.thesis, model.name.clone(), model.mesh)?;
        let Some(v) = measure_pair(r, &pair, runs, &mut found)? else { continue };
        let reference = if cgal_ready { cgal_reference(&pair, r.quick, runs, &mut found) } else { None };
        let volumes = check_volumes(&pair, &v, &mut found)?;
        record_facts(r, &pair, &v);
        table_rows(&mut table, &pair, &v, &volumes, reference.as_ref(), &mut found);
        found.list.push((pair.name.clone(), pair.thesis, pair.a.num_faces() + pair.b.num_faces()));
    }
    for w in &found.wrong {
        r.disagreement(format!("boolean: {w}"));
    }
    for f in &found.failed {
        r.disagreement(format!("boolean: no answer on {f}"));
    }
    table.note(format!(
        "Medians of {runs} runs after a warm-up, each run measuring grouped CPU, grouped GPU and plain in turn; \
         spread: half the range of the runs as a share of the median. \
         Each pair is a solid and its copy \
         rotated 10° about y and moved by 1 % of its diagonal along x (`texgeo bench boolean`'s pairs); triangles = \
         both operands. phase 1 = index + pair tests + intersection points + re-triangulation; phase 2 = both \
         inclusion classifiers + on-tests + groups (grouped) + point tests + the operation's assembly. CPU point tests \
         by `{CPU_METHOD}`, GPU = Feito-Torres on the GPU with its exact fallback. total grouped GPU = phase 1 + phase 2 \
         grouped GPU, the thesis' \"optimizado\". relative gap: the result's volume against CGAL's (checked against \
         CGAL), or, without CGAL, the larger of the volume identities' gaps (checked against the identity)."
    ));
    if !found.refused.is_empty() {
        table.note(format!("Refused as operands, so not measured: {}.", found.refused.join("; ")));
    }
    let mut blocks = section_text(r, runs, cgal_ready, notes, &found)?;
    blocks.push(r.table(table, "boolean-table6-1-today")?);
    blocks.push(r.table(thesis_beside_today(r), "boolean-table6-1")?);
    blocks.extend(plots(r)?);
    Ok(blocks)
}

/// The three variants of `pair`, measured in turn run after run; `None` (and the pair
/// named in `found`) when texgeo refuses or cannot evaluate it. Classifications that
/// differ between the variants are recorded as wrong answers.
fn measure_pair(r: &Run, pair: &Pair, runs: usize, found: &mut Findings) -> Result<Option<Variants>> {
    let (cpu, gpu, plain) = (
        sequential(CPU_METHOD, Grouping::Grouped),
        sequential(Method::Gpu, Grouping::Grouped),
        sequential(CPU_METHOD, Grouping::Plain),
    );
    let measured = measure_interleaved(pair, &[(&cpu, None), (&gpu, Some(r.ctx)), (&plain, None)], runs);
    let measured = match measured {
        Err(e @ crate::boolean::BooleanError::Input { .. }) => {
            found.refused.push(format!("{} ({e})", pair.name));
            return Ok(None);
        }
        // A pair texgeo cannot evaluate is named, and the other pairs measured.
        Err(e @ crate::boolean::BooleanError::Refine(_)) => {
            found.failed.push(format!("{}: {e}", pair.name));
            return Ok(None);
        }
        other => other?,
    };
    let Ok([grouped, gpu, plain]) = <[Timed; 3]>::try_from(measured) else {
        unreachable!("one timing per variant")
    };
    let same = |a: &crate::boolean::Evaluation| {
        a.classification.a == grouped.3.classification.a && a.classification.b == grouped.3.classification.b
    };
    if !same(&gpu.3) {
        found.wrong.push(format!("{}: GPU point tests classify differently from the CPU's", pair.name));
    }
    if !same(&plain.3) {
        found.wrong.push(format!("{}: plain classification differs from grouped", pair.name));
    }
    Ok(Some(Variants { grouped, gpu, plain }))
}

/// CGAL's exact corefinement of `pair` (one run per operation with `--quick`, enough to
/// check the volumes); `None`, and the pair named, when CGAL declines.
fn cgal_reference(pair: &Pair, quick: bool, runs: usize, found: &mut Findings) -> Option<cgal::Reference> {
    match cgal::reference(&pair.a, &pair.b, Some(if quick { 1 } else { runs as u32 })) {
        Ok(reference) => Some(reference),
        Err(e) => {
            found.cgal_declined.push(format!("{}: {e}", pair.name));
            None
        }
    }
}

/// Every result's volume, and the larger gap of vol(A∪B) + vol(A∩B) = vol(A) + vol(B)
/// and vol(A−B) = vol(A) − vol(A∩B), all from the one refinement.
struct Volumes {
    results: Vec<f64>,
    identity_gap: f64,
}

fn check_volumes(pair: &Pair, v: &Variants, found: &mut Findings) -> Result<Volumes> {
    let ev = &v.grouped.3;
    let results: Vec<Mesh> =
        OPERATIONS.iter().map(|&op| ev.result(op, true)).collect::<std::result::Result<_, _>>()?;
    let vols: Vec<f64> = results.iter().map(volume).collect();
    let (va, vb) = (volume(&pair.a), volume(&pair.b));
    let scale = (va + vb).abs().max(f64::MIN_POSITIVE);
    let identity = (vols[0] + vols[1] - va - vb).abs() / scale;
    let difference = (vols[2] - (va - vols[1])).abs() / scale;
    if identity > TOLERANCE || difference > TOLERANCE {
        found.wrong.push(format!(
            "{}: volume identities off by {identity:.1e} / {difference:.1e} relative",
            pair.name
        ));
    }
    Ok(Volumes { results: vols, identity_gap: identity.max(difference) })
}

/// The facts of one pair: phase times per variant, the point tests saved, all three
/// operations against the dearest single one, each operation's totals.
fn record_facts(r: &mut Run, pair: &Pair, v: &Variants) {
    let (p1, p2, asm) = (&v.grouped.0, &v.grouped.1, &v.grouped.2);
    let (p2_gpu, asm_gpu) = (&v.gpu.1, &v.gpu.2);
    let (p2_plain, asm_plain) = (&v.plain.1, &v.plain.2);
    let name = pair.name.as_str();
    let f = &mut *r.facts;
    f.model(EXP, name, (pair.a.num_faces() + pair.b.num_faces()) as f64, pair.thesis);
    let timed = |f: &mut crate::report::reproduce::Facts, key: &str, s: &Samples| {
        f.add_runs(EXP, name, key, Stat::median_of(s), s);
    };
    let phase2_cpu = Samples::sum(&[p2, &asm[2]]);
    timed(f, "time:phase1", p1);
    timed(f, "time:phase2-grouped", &phase2_cpu);
    timed(f, "time:phase2-cpu", &phase2_cpu);
    timed(f, "time:phase2-gpu", &Samples::sum(&[p2_gpu, &asm_gpu[2]]));
    timed(f, "time:phase2-plain", &Samples::sum(&[p2_plain, &asm_plain[2]]));
    timed(f, "time:total", &Samples::sum(&[p1, p2, &asm[2]]));
    let stats = v.grouped.3.classification.stats;
    f.add(EXP, name, "reduction", "", Stat::exact(stats.saved_share()));
    f.add(EXP, name, "point-tests", "", Stat::exact(stats.point_tests as f64));
    f.add(EXP, name, "point-tests-plain", "", Stat::exact(v.plain.3.classification.stats.point_tests as f64));
    // All three operations from one refinement and classification, against the
    // dearest single one.
    let dearest = (0..OPERATIONS.len()).max_by_key(|&k| asm[k].median()).unwrap_or(0);
    timed(f, "time:all-ops", &Samples::sum(&[p1, p2, &asm[0], &asm[1], &asm[2]]));
    timed(f, "time:one-op", &Samples::sum(&[p1, p2, &asm[dearest]]));
    for (k, &op) in OPERATIONS.iter().enumerate() {
        for (kind, times) in [
            ("grouped", Samples::sum(&[p1, p2_gpu, &asm_gpu[k]])),
            ("grouped-cpu", Samples::sum(&[p1, p2, &asm[k]])),
            ("plain", Samples::sum(&[p1, p2_plain, &asm_plain[k]])),
        ] {
            f.add(EXP, name, &format!("time:{kind}:{}", op.name()), "s", Stat::median_of(&times));
        }
    }
}

/// One row of Table 6-1 today per operation; each volume checked against CGAL's when
/// there is a reference.
fn table_rows(
    table: &mut Table,
    pair: &Pair,
    v: &Variants,
    volumes: &Volumes,
    reference: Option<&cgal::Reference>,
    found: &mut Findings,
) {
    let (p1, p2, asm) = (&v.grouped.0, &v.grouped.1, &v.grouped.2);
    let (p2_gpu, asm_gpu) = (&v.gpu.1, &v.gpu.2);
    let (p2_plain, asm_plain) = (&v.plain.1, &v.plain.2);
    let ev = &v.grouped.3;
    let s = ev.classification.stats;
    let identity = format!("{:.1e}", volumes.identity_gap);
    for (k, &op) in OPERATIONS.iter().enumerate() {
        let vol = volumes.results[k];
        let cgal_volume = reference.and_then(|r| r.measures(op)).map(|(cv, _)| cv);
        let relative = |cv: f64| (vol - cv).abs() / cv.abs().max(f64::MIN_POSITIVE);
        if let Some(cv) = cgal_volume {
            found.checked_cgal += 1;
            if relative(cv) > TOLERANCE {
                found.wrong.push(format!(
                    "{} {} : volume {vol} vs CGAL's {cv} ({:.1e} relative)",
                    pair.name,
                    op.symbol(),
                    relative(cv)
                ));
            }
        }
        let cgal_cell = match (reference, cgal_volume) {
            (None, _) => "–".to_string(),
            (Some(_), None) => "declined".to_string(),
            (Some(r), Some(_)) => {
                r.median_seconds(op).map_or("timed out".into(), |t| format!("{:.1}", t * 1e3))
            }
        };
        let (against, gap) = match cgal_volume {
            Some(cv) => ("CGAL", format!("{:.1e}", relative(cv))),
            None => ("identity", identity.clone()),
        };
        table.row(vec![
            pair.name.clone(),
            pair.thesis.to_string(),
            op.symbol().to_string(),
            (pair.a.num_faces() + pair.b.num_faces()).to_string(),
            (ev.refinement.stats.cut_a + ev.refinement.stats.cut_b).to_string(),
            s.point_tests.to_string(),
            v.plain.3.classification.stats.point_tests.to_string(),
            format!("{:.1} %", 100.0 * s.saved_share()),
            ms(p1.median()),
            p1.spread_cell(),
            ms(p2.median() + asm[k].median()),
            Samples::sum(&[p2, &asm[k]]).spread_cell(),
            ms(p2_gpu.median() + asm_gpu[k].median()),
            Samples::sum(&[p2_gpu, &asm_gpu[k]]).spread_cell(),
            ms(p2_plain.median() + asm_plain[k].median()),
            Samples::sum(&[p2_plain, &asm_plain[k]]).spread_cell(),
            ms(Samples::sum(&[p1, p2_gpu, &asm_gpu[k]]).median()),
            cgal_cell,
            num(vol),
            against.to_string(),
            gap,
        ]);
    }
}

/// The section's opening: how the pairs were measured, the models, and whether every
/// answer agreed and how that was checked.
fn section_text(
    r: &mut Run,
    runs: usize,
    cgal_ready: bool,
    notes: Vec<String>,
    found: &Findings,
) -> Result<Vec<Block>> {
    let mut blocks = vec![Block::Para(format!(
        "Every pair is measured with grouped classification (one point test per group, §6.5.1) on the CPU and on \
         the GPU, and with plain classification (one point test per triangle), {runs} timed runs after a warm-up, the three \
         back to back in every run so that load from other work hits them alike. \
         Union, intersection and difference are all assembled from the one refinement and classification."
    ))];
    blocks.push(r.table(models_table(EXP, r, &found.list), "boolean-models")?);
    blocks.extend(notes.into_iter().map(Block::Para));
    let how = if found.checked_cgal > 0 {
        format!(
            "every result's volume against CGAL's exact corefinement ({} results, relative {TOLERANCE:e}), \
             and vol(A∪B) + vol(A∩B) = vol(A) + vol(B), vol(A−B) = vol(A) − vol(A∩B) on every pair",
            found.checked_cgal
        )
    } else {
        format!(
            "vol(A∪B) + vol(A∩B) = vol(A) + vol(B) and vol(A−B) = vol(A) − vol(A∩B) on every pair (relative \
             {TOLERANCE:e}); CGAL's helper is {} (run tools/setup)",
            if cgal_ready { "declined every pair" } else { "not built" }
        )
    };
    blocks.push(Block::Para(if found.wrong.is_empty() {
        format!(
            "**All methods agree on every triangle** (CPU and GPU point tests, grouped and plain classification give \
             the same class to every refined triangle). Checked: {how}."
        )
    } else {
        format!("**Answers that differ:** {}. Checked: {how}.", found.wrong.join("; "))
    }));
    if !found.failed.is_empty() {
        blocks
            .push(Block::Para(format!("**Pairs texgeo could not evaluate:** {}.", found.failed.join("; "))));
    }
    if !found.cgal_declined.is_empty() {
        blocks.push(Block::Para(format!("CGAL could not answer: {}.", found.cgal_declined.join("; "))));
    }
    Ok(blocks)
}

/// Table 6-1's totals and phases, the thesis' beside today's.
fn thesis_beside_today(r: &Run) -> Table {
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
    comparison(r, EXP, "Table 6-1: thesis beside today", "s", &quantities)
}

/// Time against triangles per phase and method, and the speed-ups of grouping and of
/// the GPU in phase 2, the thesis' beside ours.
fn plots(r: &mut Run) -> Result<Vec<Block>> {
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
    let chart = Chart::loglog(
        "Boolean operations (A − B): time against triangles per phase and method",
        "triangles (both operands)",
        "s",
        series,
    );
    let mut blocks = r.plot(&chart, "boolean-time")?;
    let speedups: [Speedup; 2] = [
        (
            "phase 2 plain / grouped".into(),
            0,
            ["time:phase2-plain", "time:phase2-cpu"],
            Some(["time:phase2-plain", "time:phase2-grouped"]),
        ),
        ("phase 2 CPU / GPU".into(), 1, ["time:phase2-cpu", "time:phase2-gpu"], None),
    ];
    blocks.extend(speedup_plot(
        r,
        EXP,
        &speedups,
        "Boolean operations: grouped classification's and the GPU's speed-ups in phase 2",
        "triangles (both operands)",
        "boolean-speedup",
    )?);
    Ok(blocks)
}

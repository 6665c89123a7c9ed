//! `texgeo bench boolean`: Table 6-1 of the 2006 thesis (§6.6) — per pair of solids, the
//! triangles, phase 1 (index + refinement) and phase 2 (classification + assembly) with
//! plain and grouped classification, CPU and GPU point tests, and CGAL's corefinement —
//! beside the thesis' seconds (`reference/boolean/table6-1.csv`); then how the time
//! grows from 1 k to 100 k triangles (§6.6: near-linear).

use std::time::Duration;

use crate::boolean::{self, Evaluation, Grouping, Names, Operation, Options, Transform, cgal};
use crate::gpu::Context;
use crate::inclusion::{Choice, Method};
use crate::mesh::{Mesh, procedural};
use crate::report::{Environment, Report, Samples, Table};

/// The thesis' Table 6-1, as transcribed.
pub const THESIS_TABLE: &str = include_str!("../../../reference/boolean/table6-1.csv");

/// (thesis pair, texgeo stand-in): each stand-in minus/with a copy of itself rotated 10°
/// about y and moved by 1 % of its bounding-box diagonal along x.
pub const STAND_INS: &[(&str, &str)] = &[
    ("Torre", "builtin:knot"),
    ("Alfil", "elephant.off"),
    ("LionHd", "bear.off"),
    ("Golfball", "diplodocus.off"),
    ("Armadillo", "armadillo.off"),
];

/// The operations of Table 6-1.
pub const OPERATIONS: [Operation; 3] = [Operation::Union, Operation::Intersection, Operation::Difference];

/// A pair to measure.
pub struct Pair {
    /// Row name in Table 6-1 ("–" when the thesis has none).
    pub thesis: &'static str,
    pub name: String,
    pub a: Mesh,
    pub b: Mesh,
}

impl Pair {
    /// `mesh` and its copy rotated 10° about y and moved by 1 % of its diagonal along x.
    pub fn with_turned_copy(thesis: &'static str, name: String, mesh: Mesh) -> crate::mesh::Result<Pair> {
        let b = turned_copy(&mesh)?;
        Ok(Pair { thesis, name, a: mesh, b })
    }
}

/// The copy every stand-in is paired with (armadillo minus its copy turned 10° about y, moved 1 % of its diagonal).
pub fn turned_copy(mesh: &Mesh) -> crate::mesh::Result<Mesh> {
    let (lo, hi) = mesh.bounds();
    let shift = 0.01 * (hi - lo).length();
    let t = Transform::parse(&format!("rotate y 10; translate {shift} 0 0"))
        .unwrap_or_else(|e| unreachable!("a fixed transform parses: {e}"));
    t.apply(mesh)
}

/// The scaling series' pair for about n triangles in both operands together: a UV sphere
/// (r rings, 2r segments: about 4r² triangles) and its turned copy.
pub fn scaling_pair(n: usize) -> crate::mesh::Result<Pair> {
    let r = ((n as f64 / 8.0).sqrt().round() as usize).max(3);
    Pair::with_turned_copy("–", format!("sphere {r}×{}", 2 * r), procedural::sphere(r, 2 * r))
}

pub struct Config {
    /// Timed runs per measurement (after one warm-up); medians reported.
    pub runs: usize,
    /// CPU inclusion method.
    pub cpu_method: Choice,
    /// Also classify one point per triangle (slow on big models).
    pub plain: bool,
    /// Time CGAL's corefinement (needs the helper from tools/setup).
    pub cgal: bool,
    /// Triangle counts of the scaling series (spheres minus a turned copy); empty = none.
    pub scaling: Vec<usize>,
}

/// The thesis' (plain total, grouped total) seconds for (pair, op), if transcribed.
pub fn thesis_seconds(pair: &str, op: Operation) -> Option<(f64, f64)> {
    THESIS_TABLE.lines().skip(1).find_map(|line| {
        let c: Vec<&str> = line.split(',').collect();
        (c.len() >= 9 && c[0] == pair && c[1] == op.name())
            .then(|| Some((c[5].parse().ok()?, c[8].parse().ok()?)))?
    })
}

fn ms(d: Duration) -> String {
    format!("{:.1}", d.as_secs_f64() * 1e3)
}

/// The timed runs of one evaluation: (phase 1, phase 2 without assembly, assembly per
/// op of [`OPERATIONS`], the last evaluation).
pub type Timed = (Samples, Samples, Vec<Samples>, Evaluation);

/// One timed evaluation: `runs` timed runs after a warm-up; `ctx` for the GPU point
/// tests. `texgeo reproduce` measures Table 6-1 with it too.
pub fn measure(pair: &Pair, options: &Options, ctx: Option<&Context>, runs: usize) -> boolean::Result<Timed> {
    let mut all = measure_interleaved(pair, &[(options, ctx)], runs)?;
    Ok(all.pop().unwrap_or_else(|| unreachable!("one variant")))
}

/// Several ways to evaluate `pair` (options and, for GPU point tests, the device), each
/// warmed up once, then `runs` rounds of every way in turn: load that comes and goes hits
/// every way alike, and the ratio of two ways can be taken round by round.
pub fn measure_interleaved(
    pair: &Pair,
    variants: &[(&Options, Option<&Context>)],
    runs: usize,
) -> boolean::Result<Vec<Timed>> {
    let names = Names { a: &pair.name, b: "copy" };
    let mut out: Vec<Timed> = Vec::new();
    for (options, ctx) in variants {
        let ev = boolean::evaluate(&pair.a, &pair.b, names, options, *ctx)?;
        let assembly = OPERATIONS.iter().map(|_| Samples::default()).collect();
        out.push((Samples::default(), Samples::default(), assembly, ev));
    }
    for _ in 0..runs.max(1) {
        for ((options, ctx), (p1, p2, assembly, last)) in variants.iter().zip(&mut out) {
            let ev = boolean::evaluate(&pair.a, &pair.b, names, options, *ctx)?;
            p1.push(ev.timings.refine);
            p2.push(ev.timings.classification());
            for (k, &op) in OPERATIONS.iter().enumerate() {
                let start = std::time::Instant::now();
                ev.result(op, true)?;
                assembly[k].push(start.elapsed());
            }
            *last = ev;
        }
    }
    Ok(out)
}

/// The options of a timed evaluation: phases one after the other (no overlap of the
/// classifiers' build with the refinement), so each phase's time is its own; operands
/// checked every time (no verdicts from or into the user's cache).
pub fn sequential(method: impl Into<Choice>, grouping: Grouping) -> Options {
    Options {
        method: method.into(),
        grouping,
        overlap: false,
        remember_verdicts: false,
        ..Options::default()
    }
}

/// The columns of Table 6-1 between the pair and the totals, shared with `texgeo
/// reproduce`'s table: the thesis' pair, the operation and the measured phases (ms, the
/// columns [`PHASE_MS`]), each with its spread: half the range of its runs as a share of
/// its median.
pub const PHASE_COLUMNS: [&str; 15] = [
    "thesis pair",
    "op",
    "triangles",
    "cut A+B",
    "point tests grouped",
    "point tests plain",
    "saved",
    "phase 1",
    "phase 1 spread ± %",
    "phase 2 grouped CPU",
    "phase 2 grouped CPU spread ± %",
    "phase 2 grouped GPU",
    "phase 2 grouped GPU spread ± %",
    "phase 2 plain CPU",
    "phase 2 plain CPU spread ± %",
];

/// The columns of a table that starts with the pair's name and [`PHASE_COLUMNS`] that
/// hold milliseconds.
pub const PHASE_MS: [usize; 4] = [8, 10, 12, 14];

/// Runs the benchmark: Table 6-1 over `pairs`, and the growth with size when asked.
pub fn run(ctx: &Context, pairs: &[Pair], cfg: &Config) -> boolean::Result<Report> {
    let table = table6_1(ctx, pairs, cfg)?;
    // No pairs (only the scaling series asked for): no empty Table 6-1.
    let mut tables = if pairs.is_empty() { Vec::new() } else { vec![table] };
    if !cfg.scaling.is_empty() {
        tables.push(scaling_table(cfg)?);
    }
    Ok(Report { name: "boolean".into(), environment: Environment::new(ctx.info().label()), tables })
}

/// Table 6-1: every pair's operations, phase by phase, beside CGAL and the thesis.
fn table6_1(ctx: &Context, pairs: &[Pair], cfg: &Config) -> boolean::Result<Table> {
    let columns = [
        &["pair (stand-in)"][..],
        &PHASE_COLUMNS,
        &["total grouped CPU", "CGAL corefinement", "thesis plain total", "thesis grouped total"],
    ]
    .concat();
    let mut table = Table::new("Table 6-1: Boolean operations (ms; thesis in s)", &columns)
        .named("table6-1")
        .unit("ms", PHASE_MS)
        .unit("ms", 16..=17)
        .unit("s", 18..=19);
    let mut refused = Vec::new();
    for pair in pairs {
        if let Err(why) = pair_rows(ctx, pair, cfg, &mut table)? {
            refused.push(why);
        }
    }
    table.note(format!(
        "Medians of {} runs after a warm-up (plain: one run); spread: half the range of the runs as a share of \
         the median (– for one run). triangles = both operands; cut = input \
         triangles re-triangulated; point tests = one per group (§6.5.1) / one per triangle off the other \
         surface (on-triangles are decided exactly without a test); saved = the thesis' reduction. phase 1 = \
         index + pair tests + intersection points + constrained re-triangulation (the operand checks — closed, \
         oriented, volume, self-intersections — are not included, as the thesis had none); phase 2 = building \
         both inclusion classifiers + on-tests + groups + point tests + the operation's assembly; CPU = `{}`, \
         GPU = `gpu` (Feito-Torres on the GPU with its exact fallback; device below), both give the same \
         classification (else DIFFERS). CGAL = `corefine_and_compute_*` with the exact kernel, inputs copied \
         outside the clock. Each B is A rotated 10° about y and moved by 1 % of its diagonal along x; the \
         thesis used chess pieces (not public) and a 150 000-face armadillo per instance.",
        cfg.runs.max(1),
        cfg.cpu_method
    ));
    if !refused.is_empty() {
        table.note(format!("Refused as operands, so not measured: {}.", refused.join("; ")));
    }
    Ok(table)
}

/// The rows of one pair, one per operation: the CPU and GPU point tests in turn, run
/// after run, plain classification once, CGAL when asked. `Err` (inside `Ok`): the pair
/// was refused as operands, and why.
fn pair_rows(
    ctx: &Context,
    pair: &Pair,
    cfg: &Config,
    table: &mut Table,
) -> boolean::Result<std::result::Result<(), String>> {
    let triangles = pair.a.num_faces() + pair.b.num_faces();
    let (cpu, gpu) =
        (sequential(cfg.cpu_method, Grouping::Grouped), sequential(Method::Gpu, Grouping::Grouped));
    let grouped = measure_interleaved(pair, &[(&cpu, None), (&gpu, Some(ctx))], cfg.runs);
    let mut both = match grouped {
        Err(e @ boolean::BooleanError::Input { .. }) => {
            crate::note!("texgeo: skipping {}: {e}", pair.name);
            return Ok(Err(format!("{} ({e})", pair.name)));
        }
        r => r?,
    };
    let (_, p2_gpu, _, ev_gpu) = both.pop().unwrap_or_else(|| unreachable!("two variants"));
    let (p1, p2, asm, ev) = both.pop().unwrap_or_else(|| unreachable!("two variants"));
    // The GPU and CPU classifications agree (they are both exact).
    let same =
        ev_gpu.classification.a == ev.classification.a && ev_gpu.classification.b == ev.classification.b;
    let plain = if cfg.plain {
        Some(measure(pair, &sequential(cfg.cpu_method, Grouping::Plain), None, 1)?)
    } else {
        None
    };
    let reference = if cfg.cgal { cgal_reference(pair, cfg.runs) } else { None };
    let s = ev.classification.stats;
    for (k, &op) in OPERATIONS.iter().enumerate() {
        let total = p1.median() + p2.median() + asm[k].median();
        let thesis = thesis_seconds(pair.thesis, op);
        table.row(vec![
            pair.name.clone(),
            pair.thesis.to_string(),
            op.symbol().to_string(),
            triangles.to_string(),
            (ev.refinement.stats.cut_a + ev.refinement.stats.cut_b).to_string(),
            s.point_tests.to_string(),
            plain.as_ref().map_or("–".into(), |p| p.3.classification.stats.point_tests.to_string()),
            format!("{:.1} %", 100.0 * s.saved_share()),
            ms(p1.median()),
            p1.spread_cell(),
            ms(p2.median() + asm[k].median()),
            Samples::sum(&[&p2, &asm[k]]).spread_cell(),
            format!("{}{}", ms(p2_gpu.median() + asm[k].median()), if same { "" } else { " (DIFFERS)" }),
            Samples::sum(&[&p2_gpu, &asm[k]]).spread_cell(),
            plain.as_ref().map_or("–".into(), |p| ms(p.1.median() + p.2[k].median())),
            plain.as_ref().map_or("–".into(), |p| Samples::sum(&[&p.1, &p.2[k]]).spread_cell()),
            ms(total),
            reference
                .as_ref()
                .and_then(|r| r.median_seconds(op))
                .map_or("–".into(), |t| format!("{:.1}", t * 1e3)),
            thesis.map_or("–".into(), |t| t.0.to_string()),
            thesis.map_or("–".into(), |t| t.1.to_string()),
        ]);
    }
    crate::note!("{}: phase 1 {} ms, phase 2 {} ms", pair.name, ms(p1.median()), ms(p2.median()));
    Ok(Ok(()))
}

/// CGAL's exact corefinement of `pair`, `runs` times; `None` (and a note) when it
/// cannot answer.
fn cgal_reference(pair: &Pair, runs: usize) -> Option<cgal::Reference> {
    match cgal::reference(&pair.a, &pair.b, Some(runs.max(1) as u32)) {
        Ok(r) => Some(r),
        Err(e) => {
            crate::note!("texgeo: CGAL on {}: {e}", pair.name);
            None
        }
    }
}

/// The growth with size: a sphere minus its turned copy at each size of `cfg.scaling`,
/// with the growth exponents of both phases.
fn scaling_table(cfg: &Config) -> boolean::Result<Table> {
    let mut scaling = Table::new(
        "Growth with size: sphere − turned copy (ms)",
        &[
            "triangles",
            "cut A+B",
            "phase 1",
            "phase 2",
            "total",
            "µs per triangle",
            "phase 1 µs/tri",
            "phase 2 µs/tri",
        ],
    )
    .named("scaling")
    .unit("ms", 2..=4);
    // (triangles, phase 1 s, phase 2 s) per size, for the growth exponents.
    let mut growth: Vec<(f64, f64, f64)> = Vec::new();
    for &n in &cfg.scaling {
        let pair = scaling_pair(n)?;
        let (p1, p2, asm, ev) =
            measure(&pair, &sequential(cfg.cpu_method, Grouping::Grouped), None, cfg.runs)?;
        let total = p1.median() + p2.median() + asm[2].median();
        let tris = ev.a.triangles.len() + ev.b.triangles.len();
        let (s1, s2) = (p1.median().as_secs_f64(), (p2.median() + asm[2].median()).as_secs_f64());
        growth.push((tris as f64, s1, s2));
        scaling.row(vec![
            tris.to_string(),
            (ev.refinement.stats.cut_a + ev.refinement.stats.cut_b).to_string(),
            ms(p1.median()),
            ms(p2.median() + asm[2].median()),
            ms(total),
            format!("{:.2}", total.as_secs_f64() * 1e6 / tris as f64),
            format!("{:.2}", s1 * 1e6 / tris as f64),
            format!("{:.2}", s2 * 1e6 / tris as f64),
        ]);
    }
    scaling.note(
        "Difference A − B; phases as above, CPU point tests. Near-constant µs per triangle = linear growth.",
    );
    // Time ∝ n^k between the first size of at least 10 000 triangles (below, fixed costs
    // dominate) and the largest.
    let from = growth.iter().position(|g| g.0 >= 1e4).unwrap_or(0);
    if let (Some(&(n0, a0, b0)), Some(&(n1, a1, b1))) = (growth.get(from), growth.last())
        && n1 > n0
    {
        let k = |t0: f64, t1: f64| (t1 / t0).ln() / (n1 / n0).ln();
        scaling.note(format!(
            "Growth from {n0} to {n1} triangles: phase 1 ∝ n^{:.2}, phase 2 ∝ n^{:.2} (1 = linear).",
            k(a0, a1),
            k(b0, b1)
        ));
    }
    Ok(scaling)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thesis_rows_are_found() {
        assert_eq!(thesis_seconds("Torre", Operation::Union), Some((0.863995, 0.235081)));
        assert_eq!(thesis_seconds("Armadillo", Operation::Difference), Some((694.831357, 102.500169)));
        assert_eq!(thesis_seconds("Armadillo", Operation::Union), None);
    }
}

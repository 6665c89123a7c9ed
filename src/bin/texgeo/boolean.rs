//! `texgeo boolean`: Boolean operations on two closed solids (2006 thesis Ch. 6), or one
//! operation folded over more; and the evaluation of expressions that `texgeo csg` shares.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::Context as _;
use rayon::prelude::*;
use texgeo::boolean::expr::{self, Expr};
use texgeo::boolean::{self, Evaluation, Grouping, Names, Operation, Options, Transform};
use texgeo::gpu::Context;
use texgeo::inclusion::method::AUTO;
use texgeo::inclusion::{Choice, Method};
use texgeo::mesh::formats::{self, Format};
use texgeo::mesh::frame::Frame;
use texgeo::mesh::{Mesh, covering, covering::Covering, solidity};
use texgeo::render::{self, Look, Model, Renderer, View};

use crate::mesh::MeshArg;

#[derive(clap::Args)]
pub struct Args {
    /// The solids: closed mesh files or `builtin:NAME`. Every option takes two (A and B);
    /// more than two are combined from the left with --op and -o: `A B C --op difference`
    /// is (A − B) − C (like `texgeo csg "a - b - c"`).
    #[arg(num_args = 2.., required = true, value_name = "SOLID")]
    operands: Vec<MeshArg>,
    /// union, intersection, difference (A − B) or symmetric-difference.
    #[arg(long, required_unless_present = "all")]
    op: Option<String>,
    /// Keep the thesis' non-regularized sets (∩ keeps, − drops the faces where the
    /// solids touch from outside; the result may then be open there).
    #[arg(long)]
    non_regularized: bool,
    /// Transform of A, steps applied in order: "translate X Y Z; rotate x|y|z DEG;
    /// rotate AX AY AZ DEG; scale S | scale SX SY SZ; matrix M00 … M23".
    #[arg(long, value_name = "STEPS", allow_hyphen_values = true)]
    transform_a: Option<String>,
    /// Transform of B (same steps as --transform-a).
    #[arg(long, value_name = "STEPS", allow_hyphen_values = true)]
    transform_b: Option<String>,
    #[command(flatten)]
    evaluate: Evaluate,
    /// Output mesh (.obj .off .ply .stl) of --op.
    #[arg(short, long, conflicts_with = "all", required_unless_present = "all")]
    output: Option<PathBuf>,
    /// Write every operation from the one refinement into DIR (union.EXT, …).
    #[arg(long, value_name = "DIR")]
    all: Option<PathBuf>,
    /// File extension for --all.
    #[arg(long, default_value = "off", requires = "all")]
    format: String,
    /// Also draw each written operation into DIR/OP.png (2006 thesis Figs. 6-9 … 6-12: the
    /// operands in two colours with the cut curve, and beside them the result, its faces
    /// coloured by operand).
    #[arg(long, value_name = "DIR")]
    pictures: Option<PathBuf>,
}

/// How `boolean` and `csg` evaluate and report.
#[derive(clap::Args)]
pub struct Evaluate {
    /// Inclusion method for the point tests: octants, gpu, cpu+gpu, gpu+tetragrid, cpu,
    /// bvh, tetragrid, jordan, jordan-octree, winding. The default is the fastest exact one
    /// for the few points grouped classification tests (measured: `texgeo bench boolean`);
    /// `gpu` is the thesis' GPU test, with its exact fallback.
    #[arg(long, value_parser = texgeo::choice::value_parser::<Method>(AUTO), default_value_t = Choice::Fixed(Method::Octants))]
    method: Choice,
    /// One point test per triangle instead of one per group (the thesis' plain version).
    #[arg(long)]
    plain: bool,
    /// Go on even if an operand's faces cross each other (best effort).
    #[arg(long)]
    allow_self_intersections: bool,
    /// Reverse the faces of an operand whose faces point inwards (negative volume)
    /// instead of refusing it.
    #[arg(long)]
    flip_inverted: bool,
    /// Print triangle counts, cut triangles, groups, point tests saved and phase times
    /// (of each operation, for several).
    #[arg(long)]
    stats: bool,
    /// Print one JSON object on stdout (each result's triangles, volume and file; with
    /// --stats the counts and times, in ms); the text lines go to stderr.
    #[arg(long)]
    pub json: bool,
}

impl Evaluate {
    fn options(&self) -> Options {
        Options {
            method: self.method,
            grouping: if self.plain { Grouping::Plain } else { Grouping::Grouped },
            allow_self_intersections: self.allow_self_intersections,
            ..Options::default()
        }
    }
}

/// An operand of an expression as the command line gives it.
pub struct Operand {
    /// Its name in the expression.
    pub name: String,
    /// Its name in messages.
    pub label: String,
    pub mesh: MeshArg,
    pub transform: Option<Transform>,
}

/// Checks that `path` can take a mesh (format by extension, not one of `inputs`).
pub fn check_mesh_output(path: &Path, inputs: &[&MeshArg]) -> anyhow::Result<()> {
    Format::from_path(path).with_context(|| format!("output {}", path.display()))?;
    texgeo::output::check_output(path, &MeshArg::files(inputs.iter().copied()))?;
    Ok(())
}

/// Reads an operand, transformed, and (asked to) with an inverted solid's faces reversed:
/// the operand checks refuse an inverted solid.
fn load_operand(spec: &MeshArg, t: Option<Transform>, flip_inverted: bool) -> anyhow::Result<Mesh> {
    let m = crate::mesh::load(spec)?;
    let m = match t {
        Some(t) => t.apply(&m).with_context(|| format!("transforming {spec}"))?,
        None => m,
    };
    // The operand checks refuse an inverted solid; asked to, flip it first (its sign taken
    // in its frame, where the volume cannot underflow).
    let inverted = || {
        let frame = Frame::of(&[&m]);
        Covering::new(&frame.mesh_in_ref(&m)).volume() < 0.0
    };
    Ok(if flip_inverted && inverted() { solidity::flipped(&m) } else { m })
}

/// The `--stats` lines of one evaluation of A against B, before its times.
fn evaluation_lines(a: &str, b: &str, ev: &Evaluation) -> [String; 3] {
    let r = &ev.refinement.stats;
    let c = &ev.classification.stats;
    [
        format!(
            "A: {a}  ({} triangles) | B: {b}  ({} triangles)",
            ev.a.triangles.len(),
            ev.b.triangles.len()
        ),
        format!(
            "refinement: {} candidate pairs, {} meeting ({} coplanar), {} new points (implicit; {} signs decided by exact arithmetic past the filter, {} positions rounded exactly past double-double), cut triangles A {} B {}, refined triangles A {} B {}",
            r.candidate_pairs,
            r.meeting_pairs,
            r.coplanar_pairs,
            r.new_points,
            r.exact_signs,
            r.exact_roundings,
            r.cut_a,
            r.cut_b,
            ev.refinement.a.triangles.len(),
            ev.refinement.b.triangles.len()
        ),
        format!(
            "classification ({}): {} triangles, {} on the other surface, {} groups, {} point tests ({:.1} % saved; {} by exact ray crossings, no structure built), {} decided by an exact local side, {} at a rounded centroid, {} exact fallbacks, {} signs by exact arithmetic",
            ev.method,
            c.triangles,
            c.on,
            c.groups,
            c.point_tests,
            100.0 * c.saved_share(),
            c.ray_tests,
            c.local_sides,
            c.rounded_probes,
            c.exact_fallbacks,
            c.exact_signs
        ),
    ]
}

/// The `--stats --json` object of one evaluation of A against B, before its times.
fn evaluation_json(a: &str, b: &str, ev: &Evaluation) -> serde_json::Value {
    let r = &ev.refinement.stats;
    let c = &ev.classification.stats;
    serde_json::json!({
        "a": { "name": a, "triangles": ev.a.triangles.len() },
        "b": { "name": b, "triangles": ev.b.triangles.len() },
        "refinement": {
            "candidate_pairs": r.candidate_pairs,
            "meeting_pairs": r.meeting_pairs,
            "coplanar_pairs": r.coplanar_pairs,
            "new_points": r.new_points,
            "exact_signs": r.exact_signs,
            "exact_roundings": r.exact_roundings,
            "cut_a": r.cut_a,
            "cut_b": r.cut_b,
            "refined_a": ev.refinement.a.triangles.len(),
            "refined_b": ev.refinement.b.triangles.len(),
        },
        "classification": {
            "method": ev.method.to_string(),
            "triangles": c.triangles,
            "on": c.on,
            "groups": c.groups,
            "point_tests": c.point_tests,
            "saved_share": c.saved_share(),
            "exact_fallbacks": c.exact_fallbacks,
            "ray_tests": c.ray_tests,
            "local_sides": c.local_sides,
            "rounded_probes": c.rounded_probes,
            "exact_signs": c.exact_signs,
        },
    })
}

/// What rounding the result to f64 did, for `--stats --json`.
fn repair_json(r: &boolean::Repair) -> serde_json::Value {
    serde_json::json!({
        "tested": r.tested,
        "crossings": r.crossings,
        "flat_triangles": r.flat_triangles,
        "folded_edges": r.folded_edges,
        "snapped": r.snapped,
        "split_edges": r.split_edges,
        "ulp_moves": r.ulp_moves,
        "collapsed_edges": r.collapsed_edges,
        "removed_triangles": r.removed_triangles,
        "flipped": r.flipped,
        "merged": r.merged,
        "pockets": r.pockets,
        "pocket_triangles": r.pocket_triangles,
        "sheets": r.sheets,
        "sheet_triangles": r.sheet_triangles,
        "joined_sheets": r.joined_sheets,
        "merged_sheets": r.merged_sheets,
        "dropped_shells": r.dropped_shells,
        "dropped_pieces": r.dropped_pieces,
        "doubled_pieces": r.doubled_pieces,
        "moved": r.moved,
    })
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// The `--stats` line of a result's exact volume beside the written file's.
fn volume_line(what: &str, exact: &boolean::Volume, written: f64) -> String {
    format!("{what} volume {} exact (± {:.1e}; written, rounded to f64: {written})", exact.value, exact.error)
}

fn volume(mesh: &Mesh) -> f64 {
    if mesh.num_faces() == 0 { 0.0 } else { covering::measures(mesh).0 }
}

/// Evaluates `expr` over `operands` (checked against it by the caller) into `output`
/// (checked too): the body of `csg` and of `boolean` with more than two operands. `title`
/// names the result in the report line.
pub fn run_expression(
    device: Option<&str>,
    expr: &Expr,
    operands: &[Operand],
    output: &Path,
    evaluate: &Evaluate,
    title: &str,
) -> anyhow::Result<()> {
    if evaluate.json {
        texgeo::json::text_to_stderr();
    }
    let total = Instant::now();
    let read = Instant::now();
    let meshes: Vec<anyhow::Result<Mesh>> =
        operands.par_iter().map(|o| load_operand(&o.mesh, o.transform, evaluate.flip_inverted)).collect();
    let mut named = Vec::with_capacity(operands.len());
    for (o, mesh) in operands.iter().zip(meshes) {
        named.push(expr::Operand { name: o.name.clone(), label: o.label.clone(), mesh: mesh? });
    }
    let read = read.elapsed();

    let ctx = if evaluate.method.is_cpu() { None } else { Some(crate::open_context(device)?) };
    let mut lines = Vec::new();
    let mut steps_json = Vec::new();
    let steps = expr.operations();
    // The last step computes the whole expression: its exact volume is the result's.
    let mut exact = None;
    let result = expr::evaluate(expr, &named, &evaluate.options(), ctx.as_ref(), |s| {
        if !evaluate.stats && !evaluate.json {
            return;
        }
        let exact_volume = s.evaluation.exact_volume(s.op, true);
        exact = Some(exact_volume);
        if !evaluate.stats {
            return;
        }
        let t = &s.evaluation.timings;
        if evaluate.json {
            let mut step = evaluation_json(s.names.a, s.names.b, s.evaluation);
            step["expr"] = s.expr.to_string().into();
            step["op"] = s.op.name().into();
            step["triangles"] = s.triangles.into();
            step["exact_volume"] = exact_volume.value.into();
            step["exact_volume_error"] = exact_volume.error.into();
            step["repair"] = match &s.repair {
                Some(r) => repair_json(r),
                None => serde_json::Value::Null,
            };
            step["time"] = serde_json::json!({
                "check_ms": ms(t.check),
                "refine_ms": ms(t.refine),
                "classifiers_ms": ms(t.classifiers),
                "classify_ms": ms(t.classify),
                "assemble_ms": ms(s.assemble),
            });
            steps_json.push(step);
        }
        lines.push(format!(
            "step {}/{steps}: {} {} {} = {}: {} triangles",
            s.index,
            s.names.a,
            s.op.symbol(),
            s.names.b,
            s.expr,
            s.triangles
        ));
        lines.extend(evaluation_lines(s.names.a, s.names.b, s.evaluation).map(|l| format!("  {l}")));
        lines.push(match &s.repair {
            Some(r) => format!("  after rounding to f64: {r}"),
            None => "  kept exact for the next operation (not rounded)".to_string(),
        });
        lines.push(format!(
            "  volume {} exact (± {:.1e}), before rounding to f64",
            exact_volume.value, exact_volume.error
        ));
        lines.push(format!(
            "  time: checks {:.1} ms, phase 1 (index + refinement) {:.1} ms, phase 2 (classifiers {:.1} ms + tests {:.1} ms + assembly and output check {:.1} ms)",
            ms(t.check),
            ms(t.refine),
            ms(t.classifiers),
            ms(t.classify),
            ms(s.assemble)
        ));
    })?;
    let booleans = total.elapsed() - read;
    let write = Instant::now();
    // The volume reported is measured while the file is written.
    let (written, volume) = rayon::join(|| write_mesh(output, &result), || volume(&result));
    written?;
    let write = write.elapsed();
    say!("{title}: {} triangles, volume {} -> {}", result.num_faces(), volume, output.display());
    if evaluate.json {
        let mut object = serde_json::json!({
            "expr": title,
            "triangles": result.num_faces(),
            "volume": volume,
            "exact_volume": exact.map(|v| v.value),
            "exact_volume_error": exact.map(|v| v.error),
            "output": output.display().to_string(),
        });
        if evaluate.stats {
            object["steps"] = steps_json.into();
            object["time"] = serde_json::json!({
                "read_ms": ms(read),
                "operations_ms": ms(booleans),
                "write_ms": ms(write),
                "total_ms": ms(total.elapsed()),
            });
            object["device"] = ctx.as_ref().map(|c| c.info().label()).into();
        }
        texgeo::json::print(&object);
    }
    if evaluate.stats {
        for l in &lines {
            say!("{l}");
        }
        if let Some(v) = exact {
            say!("{}", volume_line(title, &v, volume));
        }
        say!(
            "time: read {:.1} ms, {steps} operation(s) {:.1} ms, write {:.1} ms, total {:.1} ms",
            ms(read),
            ms(booleans),
            ms(write),
            ms(total.elapsed())
        );
        if let Some(ctx) = &ctx {
            say!("device: {}", ctx.info().label());
        }
    }
    Ok(())
}

/// `boolean` with more than two operands: the left fold of --op, as an expression.
fn run_many(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    let refused = [
        (args.all.is_some(), "--all"),
        (args.pictures.is_some(), "--pictures"),
        (args.non_regularized, "--non-regularized"),
        (args.transform_a.is_some(), "--transform-a"),
        (args.transform_b.is_some(), "--transform-b"),
    ];
    if let Some((_, flag)) = refused.iter().find(|(given, _)| *given) {
        anyhow::bail!(
            "{flag} takes exactly two operands (for a transform of each of more, use `texgeo csg` with NAME=MESH@STEPS)"
        );
    }
    let op: Operation = args.op.as_deref().context("--op is needed")?.parse().map_err(anyhow::Error::msg)?;
    let output = args.output.as_deref().context("-o is needed")?;
    check_mesh_output(output, &args.operands.iter().collect::<Vec<_>>())?;
    // Operands are A, B, C, … in the report (A27, … past Z).
    let letter =
        |i: usize| if i < 26 { char::from(b'A' + i as u8).to_string() } else { format!("A{}", i + 1) };
    let operands: Vec<Operand> = args
        .operands
        .iter()
        .enumerate()
        .map(|(i, spec)| Operand {
            name: letter(i),
            label: spec.to_string(),
            mesh: spec.clone(),
            transform: None,
        })
        .collect();
    let expr = Expr::fold(op, operands.iter().map(|o| o.name.clone())).context("no operands")?;
    let title =
        operands.iter().map(|o| o.name.as_str()).collect::<Vec<_>>().join(&format!(" {} ", op.symbol()));
    run_expression(device, &expr, &operands, output, &args.evaluate, &title)
}

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    if args.operands.len() > 2 {
        return run_many(device, args);
    }
    if args.evaluate.json {
        texgeo::json::text_to_stderr();
    }
    let total = Instant::now();
    // Everything a user can get wrong is checked before any work.
    let method = args.evaluate.method;
    let (arg_a, arg_b) = (&args.operands[0], &args.operands[1]);
    let outputs = planned_outputs(&args)?;
    if let Some(dir) = &args.pictures {
        texgeo::output::check_dir(dir)?;
    }
    let ta = args.transform_a.as_deref().map(Transform::parse).transpose().map_err(anyhow::Error::msg)?;
    let tb = args.transform_b.as_deref().map(Transform::parse).transpose().map_err(anyhow::Error::msg)?;

    let read = Instant::now();
    let flip = args.evaluate.flip_inverted;
    let (a, b) = rayon::join(|| load_operand(arg_a, ta, flip), || load_operand(arg_b, tb, flip));
    let (a, b) = (a?, b?);
    let read = read.elapsed();

    let ctx = if method.is_cpu() { None } else { Some(crate::open_context(device)?) };
    let options = args.evaluate.options();
    let (a_name, b_name) = (arg_a.to_string(), arg_b.to_string());
    let names = Names { a: &a_name, b: &b_name };
    let ev = boolean::evaluate(&a, &b, names, &options, ctx.as_ref())?;

    let assemble = Instant::now();
    let regularized = !args.non_regularized;
    let results: Vec<Written> = outputs
        .into_iter()
        .map(|(op, path)| Ok((op, path, ev.output(op, regularized)?)))
        .collect::<anyhow::Result<_>>()?;
    let assemble = assemble.elapsed();
    let write = Instant::now();
    // The volumes reported are measured while the files are written.
    let (written, volumes) = rayon::join(
        || results.iter().try_for_each(|(_, path, out)| write_mesh(path, &out.mesh)),
        || results.iter().map(|(_, _, out)| volume(&out.mesh)).collect::<Vec<f64>>(),
    );
    written?;
    if let Some(dir) = &args.pictures {
        let ctx = match &ctx {
            Some(ctx) => ctx.clone(),
            None => crate::open_context(device)?,
        };
        for (op, _, _) in &results {
            let path = dir.join(format!("{}.png", op.name()));
            picture(&ctx, &ev, *op, regularized, &path)?;
            say!("wrote {}", path.display());
        }
    }
    let write = write.elapsed();

    for ((op, path, out), volume) in results.iter().zip(&volumes) {
        say!(
            "A {} B{}: {} triangles, volume {} -> {}",
            op.symbol(),
            if regularized { "" } else { " (non-regularized)" },
            out.mesh.num_faces(),
            volume,
            path.display()
        );
    }
    let exact: Vec<boolean::Volume> = if args.evaluate.stats || args.evaluate.json {
        results.iter().map(|(op, _, _)| ev.exact_volume(*op, regularized)).collect()
    } else {
        Vec::new()
    };
    let run = Finished {
        names: [&a_name, &b_name],
        ev: &ev,
        results: &results,
        volumes: &volumes,
        exact: &exact,
        regularized,
        ctx: ctx.as_ref(),
    };
    let phases = Phases { read, assemble, write, total };
    if args.evaluate.json {
        texgeo::json::print(&run.json(args.evaluate.stats, &phases));
    }
    if args.evaluate.stats {
        run.print_stats(&phases);
    }
    Ok(())
}

/// One operation's result and where it was written.
type Written = (Operation, PathBuf, boolean::Output);

/// The outputs asked for: `-o OUT` (with `--op`), or one file per operation under `--all
/// DIR`; checked before any work (format, folder, not an input).
fn planned_outputs(args: &Args) -> anyhow::Result<Vec<(Operation, PathBuf)>> {
    let (arg_a, arg_b) = (&args.operands[0], &args.operands[1]);
    let op: Option<Operation> = args.op.as_deref().map(str::parse).transpose().map_err(anyhow::Error::msg)?;
    Ok(match (&args.output, &args.all) {
        (Some(path), _) => {
            check_mesh_output(path, &[arg_a, arg_b])?;
            let op = op.context("--op is needed with -o")?;
            vec![(op, path.clone())]
        }
        (None, Some(dir)) => {
            let probe = dir.join(format!("union.{}", args.format));
            Format::from_path(&probe).with_context(|| format!("--format {}", args.format))?;
            texgeo::output::check_dir(dir)?;
            let ops: Vec<Operation> = op.map_or(Operation::ALL.to_vec(), |o| vec![o]);
            let paths: Vec<(Operation, PathBuf)> =
                ops.into_iter().map(|o| (o, dir.join(format!("{}.{}", o.name(), args.format)))).collect();
            for (_, path) in &paths {
                texgeo::output::check_not_input(path, &MeshArg::files([arg_a, arg_b]))?;
            }
            paths
        }
        (None, None) => anyhow::bail!("give -o OUT or --all DIR"),
    })
}

/// The times of a run's steps around the evaluation (its own are in its timings).
struct Phases {
    read: Duration,
    assemble: Duration,
    write: Duration,
    /// When the run started.
    total: Instant,
}

/// A finished two-operand run, for its summaries.
struct Finished<'a> {
    names: [&'a str; 2],
    ev: &'a Evaluation,
    results: &'a [Written],
    /// Each result's volume.
    volumes: &'a [f64],
    /// Each result's exact volume before rounding (with --stats or --json; else empty).
    exact: &'a [boolean::Volume],
    regularized: bool,
    ctx: Option<&'a Context>,
}

impl Finished<'_> {
    /// `--json`: every operation's result; with `--stats`, the evaluation's counts, the
    /// times and the device.
    fn json(&self, stats: bool, phases: &Phases) -> serde_json::Value {
        let [a_name, b_name] = self.names;
        let operations: Vec<serde_json::Value> = self
            .results
            .iter()
            .zip(self.volumes)
            .enumerate()
            .map(|(i, ((op, path, out), volume))| {
                let mut o = serde_json::json!({
                    "op": op.name(),
                    "regularized": self.regularized,
                    "triangles": out.mesh.num_faces(),
                    "volume": volume,
                    "exact_volume": self.exact.get(i).map(|v| v.value),
                    "exact_volume_error": self.exact.get(i).map(|v| v.error),
                    "output": path.display().to_string(),
                });
                if stats && self.regularized {
                    o["repair"] = repair_json(&out.repair);
                }
                o
            })
            .collect();
        let mut object = serde_json::json!({ "operations": operations });
        if stats {
            let t = &self.ev.timings;
            object["stats"] = evaluation_json(a_name, b_name, self.ev);
            object["time"] = serde_json::json!({
                "read_ms": ms(phases.read),
                "check_ms": ms(t.check),
                "refine_ms": ms(t.refine),
                "classifiers_ms": ms(t.classifiers),
                "classify_ms": ms(t.classify),
                "assemble_ms": ms(phases.assemble),
                "write_ms": ms(phases.write),
                "total_ms": ms(phases.total.elapsed()),
            });
            object["device"] = self.ctx.map(|c| c.info().label()).into();
        }
        object
    }

    /// `--stats` for a person: the evaluation's counts, each result's repair, the times
    /// of both phases and the device.
    fn print_stats(&self, phases: &Phases) {
        let [a_name, b_name] = self.names;
        let t = &self.ev.timings;
        for line in evaluation_lines(a_name, b_name, self.ev) {
            say!("{line}");
        }
        for (op, _, out) in self.results.iter().filter(|_| self.regularized) {
            say!("{op} after rounding to f64: {}", out.repair);
        }
        for (i, ((op, _, _), &written)) in self.results.iter().zip(self.volumes).enumerate() {
            if let Some(exact) = self.exact.get(i) {
                say!("{}", volume_line(op.name(), exact, written));
            }
        }
        say!(
            "time: read {:.1} ms, checks {:.1} ms, phase 1 (index + refinement) {:.1} ms, phase 2 (classifiers {:.1} ms + tests {:.1} ms + assembly and output check {:.1} ms), write {:.1} ms, total {:.1} ms",
            ms(phases.read),
            ms(t.check),
            ms(t.refine),
            ms(t.classifiers),
            ms(t.classify),
            ms(phases.assemble),
            ms(phases.write),
            ms(phases.total.elapsed())
        );
        if let Some(ctx) = self.ctx {
            say!("device: {}", ctx.info().label());
        }
    }
}

/// The Fig. 6-9 … 6-12 picture of `op` (800×600, 4 samples per pixel).
fn picture(
    ctx: &Context,
    ev: &Evaluation,
    op: Operation,
    regularized: bool,
    path: &Path,
) -> anyhow::Result<()> {
    let content = render::boolean::content(ev, op, regularized)?;
    let mut model = Model::new(ctx, content, 0, Look::default(), None)?;
    let scene = model.scene(ctx)?;
    let mut renderer = Renderer::new(ctx, 4)?;
    let prepared = renderer.prepare(&scene)?;
    let view = View::fit(&scene, 800, 600)?;
    renderer.render(&prepared, &view)?.save_png(path)?;
    Ok(())
}

fn write_mesh(path: &Path, mesh: &Mesh) -> anyhow::Result<()> {
    formats::write(path, mesh).with_context(|| format!("writing {}", path.display()))
}

//! `texgeo boolean`: Boolean operations on two closed solids (2006 thesis Ch. 6).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context as _;
use texgeo::boolean::{self, Evaluation, Grouping, Names, Operation, Options, Transform};
use texgeo::gpu::Context;
use texgeo::inclusion::Method;
use texgeo::mesh::formats::{self, Format};
use texgeo::mesh::frame::Frame;
use texgeo::mesh::{Mesh, covering, covering::Covering, solidity};
use texgeo::render::{self, Look, Model, Renderer, View};

use crate::mesh::MeshArg;

#[derive(clap::Args)]
pub struct Args {
    /// The first solid: a closed mesh file or `builtin:NAME`.
    a: MeshArg,
    /// The second solid.
    b: MeshArg,
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
    /// Inclusion method for the point tests: octants, gpu, cpu+gpu, gpu+tetragrid, cpu,
    /// bvh, tetragrid, jordan, jordan-octree, winding. The default is the fastest exact one
    /// for the few points grouped classification tests (measured: `texgeo bench boolean`);
    /// `gpu` is the thesis' GPU test, with its exact fallback.
    #[arg(long, value_enum, default_value_t = Method::Octants)]
    method: Method,
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
    /// Output mesh (.obj .off .ply .stl) of --op.
    #[arg(short, long, conflicts_with = "all", required_unless_present = "all")]
    output: Option<PathBuf>,
    /// Write every operation from the one refinement into DIR (union.EXT, …).
    #[arg(long, value_name = "DIR")]
    all: Option<PathBuf>,
    /// File extension for --all.
    #[arg(long, default_value = "off", requires = "all")]
    format: String,
    /// Print triangle counts, cut triangles, groups, point tests saved and phase times.
    #[arg(long)]
    stats: bool,
    /// Also draw each written operation into DIR/OP.png (2006 thesis Figs. 6-9 … 6-12: the
    /// operands in two colours with the cut curve, and beside them the result, its faces
    /// coloured by operand).
    #[arg(long, value_name = "DIR")]
    pictures: Option<PathBuf>,
}

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    let total = Instant::now();
    // Everything a user can get wrong is checked before any work.
    let method = args.method;
    let op: Option<Operation> = args.op.as_deref().map(str::parse).transpose().map_err(anyhow::Error::msg)?;
    let outputs: Vec<(Operation, PathBuf)> = match (&args.output, &args.all) {
        (Some(path), _) => {
            Format::from_path(path).with_context(|| format!("output {}", path.display()))?;
            texgeo::output::check_output(path, &MeshArg::files([&args.a, &args.b]))?;
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
                texgeo::output::check_not_input(path, &MeshArg::files([&args.a, &args.b]))?;
            }
            paths
        }
        (None, None) => anyhow::bail!("give -o OUT or --all DIR"),
    };
    if let Some(dir) = &args.pictures {
        texgeo::output::check_dir(dir)?;
    }
    let ta = args.transform_a.as_deref().map(Transform::parse).transpose().map_err(anyhow::Error::msg)?;
    let tb = args.transform_b.as_deref().map(Transform::parse).transpose().map_err(anyhow::Error::msg)?;

    let read = Instant::now();
    let load = |spec: &MeshArg, t: Option<Transform>| -> anyhow::Result<Mesh> {
        let m = crate::mesh::load(spec)?;
        let m = match t {
            Some(t) => t.apply(&m).with_context(|| format!("transforming {spec}"))?,
            None => m,
        };
        // The operand checks refuse an inverted solid; asked to, flip it first (its sign
        // taken in its frame, where the volume cannot underflow).
        let inverted = || {
            let frame = Frame::of(&[&m]);
            Covering::new(&frame.mesh_in_ref(&m)).volume() < 0.0
        };
        Ok(if args.flip_inverted && inverted() { solidity::flipped(&m) } else { m })
    };
    let (a, b) = rayon::join(|| load(&args.a, ta), || load(&args.b, tb));
    let (a, b) = (a?, b?);
    let read = read.elapsed();

    let ctx = if method.is_cpu() { None } else { Some(crate::open_context(device)?) };
    let options = Options {
        method,
        grouping: if args.plain { Grouping::Plain } else { Grouping::Grouped },
        allow_self_intersections: args.allow_self_intersections,
        ..Options::default()
    };
    let (a_name, b_name) = (args.a.to_string(), args.b.to_string());
    let names = Names { a: &a_name, b: &b_name };
    let ev = boolean::evaluate(&a, &b, names, &options, ctx.as_ref())?;

    let assemble = Instant::now();
    let regularized = !args.non_regularized;
    let results: Vec<(Operation, PathBuf, Mesh)> = outputs
        .into_iter()
        .map(|(op, path)| Ok((op, path, ev.result(op, regularized)?)))
        .collect::<anyhow::Result<_>>()?;
    let assemble = assemble.elapsed();
    let write = Instant::now();
    for (_, path, mesh) in &results {
        write_mesh(path, mesh)?;
    }
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

    for (op, path, mesh) in &results {
        let (volume, _) = covering::measures(mesh);
        say!(
            "A {} B{}: {} triangles, volume {volume} -> {}",
            op.symbol(),
            if regularized { "" } else { " (non-regularized)" },
            mesh.num_faces(),
            path.display()
        );
    }
    if args.stats {
        let r = &ev.refinement.stats;
        let c = &ev.classification.stats;
        let t = &ev.timings;
        let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
        say!(
            "A: {}  ({} triangles) | B: {}  ({} triangles)",
            args.a,
            ev.a.triangles.len(),
            args.b,
            ev.b.triangles.len()
        );
        say!(
            "refinement: {} candidate pairs, {} meeting ({} coplanar), {} new points ({} merged), cut triangles A {} B {}, refined triangles A {} B {}",
            r.candidate_pairs,
            r.meeting_pairs,
            r.coplanar_pairs,
            r.new_points,
            r.merged_points,
            r.cut_a,
            r.cut_b,
            ev.refinement.a.triangles.len(),
            ev.refinement.b.triangles.len()
        );
        say!(
            "classification ({}): {} triangles, {} on the other surface, {} groups, {} point tests ({:.1} % saved), {} exact fallbacks",
            ev.method,
            c.triangles,
            c.on,
            c.groups,
            c.point_tests,
            100.0 * c.saved_share(),
            c.exact_fallbacks
        );
        say!(
            "time: read {:.1} ms, checks {:.1} ms, phase 1 (index + refinement) {:.1} ms, phase 2 (classifiers {:.1} ms + tests {:.1} ms + assembly {:.1} ms), write {:.1} ms, total {:.1} ms",
            ms(read),
            ms(t.check),
            ms(t.refine),
            ms(t.classifiers),
            ms(t.classify),
            ms(assemble),
            ms(write),
            ms(total.elapsed())
        );
        if let Some(ctx) = &ctx {
            say!("device: {}", ctx.info().label());
        }
    }
    Ok(())
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

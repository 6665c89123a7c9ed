//! `texgeo inclusion`: classify query points against a closed solid.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context as _;
use texgeo::inclusion::solver::Solver;
use texgeo::inclusion::{Class, Method, Options, points};
use texgeo::random::Rng;

#[derive(clap::Args)]
pub struct Args {
    /// The solid: a closed mesh file or `builtin:NAME`.
    mesh: String,
    /// Query points: one `x y z` per line, `#` comments allowed.
    #[arg(long, value_name = "FILE", conflicts_with = "random", required_unless_present = "random")]
    points: Option<PathBuf>,
    /// N uniform random points in the mesh's bounding box.
    #[arg(long, value_name = "N")]
    random: Option<usize>,
    /// Seed for `--random`.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// cpu, bvh, octants, tetragrid, gpu, cpu+gpu, gpu+tetragrid, jordan, jordan-octree, winding.
    #[arg(long, default_value = "gpu")]
    method: String,
    /// TetraGrid resolution n (n³ cells, 2..=64), for tetragrid and gpu+tetragrid.
    #[arg(long, default_value_t = 32)]
    grid: usize,
    /// GPU methods: tetrahedra per point-vertex (1 = the thesis' one point per tetrahedron).
    #[arg(long)]
    batch: Option<u32>,
    /// Accept a mesh that is not closed and consistently oriented (with a warning).
    #[arg(long)]
    allow_open: bool,
    /// Write one line per point: 1 inside, 0 outside, 2 on the boundary.
    #[arg(short, long)]
    output: Option<PathBuf>,
}

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    let method: Method = args.method.parse()?;
    let mesh = crate::mesh::load(&args.mesh)?;
    let pts = match (&args.points, args.random) {
        (Some(file), _) => points::read(file)?,
        (None, Some(n)) => {
            let (lo, hi) = mesh.bounds();
            Rng::new(args.seed).points_in_box(n, lo, hi)
        }
        (None, None) => anyhow::bail!("give --points FILE or --random N"),
    };
    let ctx = if method.is_cpu() { None } else { Some(crate::open_context(device)?) };
    let options =
        Options { tetragrid_resolution: args.grid, allow_open: args.allow_open, ..Options::default() };
    if args.allow_open {
        if let Some(e) = texgeo::mesh::covering::Covering::new(&mesh).unbalanced_edge() {
            eprintln!(
                "texgeo: warning: {} is not closed and consistently oriented (edge {}-{} used {}x one way, {}x the other); \
                 answers follow the covering's winding number and may not describe a solid",
                args.mesh, e.a, e.b, e.forward, e.backward
            );
        }
    }
    let t = Instant::now();
    let mut solver = Solver::new(method, &mesh, &options, ctx.as_ref(), args.batch)
        .with_context(|| format!("preparing {} for {}", method, args.mesh))?;
    let build = t.elapsed();
    let t = Instant::now();
    let classes = solver.classify_all(&pts)?;
    let run = t.elapsed();
    match &args.output {
        Some(path) => {
            let mut f =
                std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?;
            points::write_classes(&mut f, &classes).with_context(|| format!("writing {}", path.display()))?;
        }
        None => {
            let count = |c: Class| classes.iter().filter(|&&x| x == c).count();
            println!(
                "{}: {} points, {} inside, {} outside, {} on the boundary",
                args.mesh,
                pts.len(),
                count(Class::Inside),
                count(Class::Outside),
                count(Class::OnBoundary)
            );
            let stats = solver.build_stats();
            println!(
                "method {}: build {:.3} ms ({:.1} KiB of structures), classify {:.3} ms",
                solver.name(),
                build.as_secs_f64() * 1e3,
                stats.bytes as f64 / 1024.0,
                run.as_secs_f64() * 1e3
            );
            if let Some(g) = solver.gpu_stats() {
                println!(
                    "GPU: {} points drawn in {} draw(s), {:.3} ms; {} flagged and answered exactly on the CPU in {:.3} ms",
                    g.gpu_points,
                    g.draws,
                    g.gpu.as_secs_f64() * 1e3,
                    g.flagged,
                    g.fallback.as_secs_f64() * 1e3
                );
                if let Some(ctx) = &ctx {
                    println!("device: {}", ctx.info().label());
                }
            }
        }
    }
    Ok(())
}

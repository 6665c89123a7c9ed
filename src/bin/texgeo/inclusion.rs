//! `texgeo inclusion`: classify query points against a solid.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context as _;
use texgeo::inclusion::solver::{Solver, resolve};
use texgeo::inclusion::{Class, Method, Options, points};
use texgeo::mesh::solidity::Policy;
use texgeo::random::Rng;

#[derive(clap::Args)]
pub struct Args {
    /// The solid: a mesh file (.obj .off .ply .stl) or `builtin:NAME` (see `texgeo mesh builtins`).
    mesh: String,
    /// Query points: one `x y z` per line (`#` comments allowed), or a NumPy `.npy` N×3
    /// array of float64 or float32.
    #[arg(long, value_name = "FILE", conflicts_with = "random", required_unless_present = "random")]
    points: Option<PathBuf>,
    /// N uniform random points in the mesh's bounding box (N ≥ 1).
    #[arg(long, value_name = "N", value_parser = crate::args::positive_usize)]
    random: Option<usize>,
    /// Seed for `--random`.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// `auto` picks the fastest exact method for the mesh and the number of points (and says
    /// which on stderr); every method gives the same answers.
    #[arg(long, value_enum, default_value_t = Method::Auto)]
    method: Method,
    /// Grid resolution n (n³ cells): for tetragrid and gpu+tetragrid 2..=64 (default 32), for
    /// voxel-space 2..=512 (default: from the mesh and the number of points).
    #[arg(long)]
    grid: Option<usize>,
    /// GPU methods: tetrahedra per point-vertex (1 = the thesis' one point per tetrahedron).
    #[arg(long, value_parser = crate::args::positive_u32)]
    batch: Option<u32>,
    /// Accept a mesh that is not closed: a point is then inside iff the generalized winding
    /// number of the open surface is at least ½, which only `--method winding` computes.
    #[arg(long)]
    allow_open: bool,
    /// Reverse every face of an inverted solid (faces pointing inwards) instead of refusing it.
    #[arg(long)]
    flip_inverted: bool,
    /// Write one line per point: 1 inside, 0 outside, 2 on the boundary (to a `.npy` path:
    /// a uint8 array of those values).
    #[arg(short, long)]
    output: Option<PathBuf>,
}

/// Bytes per query point while classifying: the point (24), its class, the GPU paths'
/// per-point bookkeeping (flags, cell keys, sorted order), with margin.
const BYTES_PER_POINT: u64 = 64;

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    if let Some(out) = &args.output {
        texgeo::output::check_file(out)?;
    }
    // The size of the request, before anything is read or allocated.
    let count = match (&args.points, args.random) {
        (Some(file), _) => {
            // A point takes at least 6 bytes of text ("0 0 0\n"), 12 of .npy.
            let bytes = std::fs::metadata(file).map_err(|e| texgeo::output::Error::new(file, e))?.len();
            if points::is_npy(file) { bytes / 12 + 1 } else { bytes / 6 + 1 }
        }
        (None, Some(n)) => n as u64,
        (None, None) => anyhow::bail!("give --points FILE or --random N"),
    };
    check_size(count, args.points.is_some(), args.output.is_some())?;
    let policy =
        Policy { allow_open: args.allow_open, flip_inverted: args.flip_inverted, ..Policy::default() };
    let solid = crate::mesh::load_solid(&args.mesh, policy, &["--allow-open", "--flip-inverted"])?;
    let mesh = solid.mesh;
    if solid.flipped {
        eprintln!("texgeo: note: {} was inverted; its faces were reversed (--flip-inverted)", args.mesh);
    }
    let pts = match (&args.points, args.random) {
        (Some(file), _) => points::read(file)?,
        (_, Some(n)) => {
            let (lo, hi) = mesh.bounds();
            Rng::new(args.seed).points_in_box(n, lo, hi)
        }
        (None, None) => unreachable!("checked above"),
    };
    let ctx = if args.method.is_cpu() { None } else { Some(crate::open_context_for(device, "cpu")?) };
    let options = Options {
        tetragrid_resolution: args.grid.unwrap_or(texgeo::inclusion::tetragrid::DEFAULT_RESOLUTION),
        voxel_space_resolution: args.grid,
        points: pts.len(),
        allow_open: args.allow_open,
        ..Options::default()
    };
    let t = Instant::now();
    let (method, options, choice) = resolve(args.method, &mesh, &options);
    if let Some(choice) = &choice {
        eprintln!("texgeo: --method auto: {choice} for {} faces and {} points", mesh.num_faces(), pts.len());
    }
    let mut solver = Solver::new(method, &mesh, &options, ctx.as_ref(), args.batch)
        .with_context(|| format!("preparing {} for {}", method, args.mesh))?;
    let build = t.elapsed();
    if solid.open {
        eprintln!(
            "texgeo: warning: {} is not closed; points are classified by the generalized winding number",
            args.mesh
        );
    }
    let t = Instant::now();
    let classes = solver.classify_all(&pts)?;
    let run = t.elapsed();
    match &args.output {
        Some(path) if points::is_npy(path) => {
            texgeo::output::write_with(path, |w| points::write_classes_npy(w, &classes))?
        }
        Some(path) => texgeo::output::write_with(path, |w| points::write_classes(w, &classes))?,
        None => {
            let count = |c: Class| classes.iter().filter(|&&x| x == c).count();
            say!(
                "{}: {} points, {} inside, {} outside, {} on the boundary",
                args.mesh,
                pts.len(),
                count(Class::Inside),
                count(Class::Outside),
                count(Class::OnBoundary)
            );
            let stats = solver.build_stats();
            say!(
                "method {}: build {:.3} ms ({:.1} KiB of structures), classify {:.3} ms",
                solver.name(),
                build.as_secs_f64() * 1e3,
                stats.bytes as f64 / 1024.0,
                run.as_secs_f64() * 1e3
            );
            if let Some(g) = solver.gpu_stats() {
                say!(
                    "GPU: {} points drawn in {} draw(s), {:.3} ms; {} flagged and answered exactly on the CPU in {:.3} ms",
                    g.gpu_points,
                    g.draws,
                    g.gpu.as_secs_f64() * 1e3,
                    g.flagged,
                    g.fallback.as_secs_f64() * 1e3
                );
                if let Some(ctx) = &ctx {
                    say!("device: {}", ctx.info().label());
                }
            }
        }
    }
    Ok(())
}

/// Refuses, before any work, a point count whose memory exceeds what is available; the
/// message gives the estimate and the size of the output text.
fn check_size(count: u64, from_file: bool, to_file: bool) -> anyhow::Result<()> {
    let bytes = count.saturating_mul(BYTES_PER_POINT);
    if let Err((need, have)) = texgeo::host::check_available(bytes) {
        let what = if from_file { "the points of that file (at most)" } else { "that many points" };
        let text =
            if to_file { format!("; -o would be {} MiB of text", (count * 2) >> 20) } else { String::new() };
        anyhow::bail!(
            "{count} points: {what} need about {need} MiB of memory, but only {have} MiB are available{text}"
        );
    }
    Ok(())
}

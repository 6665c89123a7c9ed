//! `texgeo inclusion`: classify query points against a solid.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context as _;
use texgeo::inclusion::method::AUTO;
use texgeo::inclusion::solver::{self, Solver, resolve};
use texgeo::inclusion::{Choice, Class, Method, Options, points};
use texgeo::mesh::solidity::Policy;
use texgeo::random::Rng;

#[derive(clap::Args)]
pub struct Args {
    /// The solid: a mesh file (.obj .off .ply .stl) or `builtin:NAME` (see `texgeo mesh builtins`).
    mesh: crate::mesh::MeshArg,
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
    #[arg(long, value_parser = texgeo::choice::value_parser::<Method>(AUTO), default_value_t = Choice::Auto)]
    method: Choice,
    /// Grid resolution n (n³ cells): for tetragrid and gpu+tetragrid 2..=64 (default 32), for
    /// voxel-space 2..=512 (default: from the mesh and the number of points).
    #[arg(long)]
    grid: Option<usize>,
    /// GPU methods: tetrahedra per point-vertex (1 = the thesis' one point per tetrahedron).
    #[arg(long, value_parser = crate::args::positive_u32)]
    batch: Option<u32>,
    /// Accept a mesh that is not a solid (open, self-intersecting, nested or inverted): a
    /// point is then inside iff the generalized winding number of its faces is at least ½,
    /// computed with a certified error bound by every CPU method (`auto` included); the GPU
    /// methods (gpu, cpu+gpu, gpu+tetragrid) refuse such a mesh. Solids are unchanged.
    #[arg(long)]
    allow_open: bool,
    /// Reverse every face of an inverted solid (faces pointing inwards) instead of refusing it.
    #[arg(long)]
    flip_inverted: bool,
    /// Write one line per point: 1 inside, 0 outside, 2 on the boundary (a text file:
    /// `.txt`, `.dat`, `.csv`, `.labels` or no extension), or to a `.npy` path a uint8 array
    /// of those values.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Print one JSON object: the counts, the method, its times (ms) and the GPU's.
    #[arg(long)]
    json: bool,
}

/// Extensions of `-o`: text, or NumPy.
const LABEL_EXTENSIONS: [&str; 5] = ["txt", "dat", "csv", "labels", "npy"];

/// Bytes per query point while classifying: the point (24), its class, the GPU paths'
/// per-point bookkeeping (flags, cell keys, sorted order), with margin.
const BYTES_PER_POINT: u64 = 64;

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    check_request(&args)?;
    let policy =
        Policy { allow_open: args.allow_open, flip_inverted: args.flip_inverted, ..Policy::default() };
    let solid = crate::mesh::load_solid(&args.mesh, policy, &["--allow-open", "--flip-inverted"])?;
    let mesh = &solid.mesh;
    if solid.flipped {
        note!("texgeo: note: {} was inverted; its faces were reversed (--flip-inverted)", args.mesh);
    }
    if let Some(defect) = &solid.non_solid {
        solver::check_method(&solid, args.method).map_err(|e| anyhow::anyhow!("{}: {e}", args.mesh))?;
        crate::mesh::warn_non_solid(&args.mesh, defect);
    }
    // Points are given in the mesh's units and classified in its frame.
    let mut source = point_source(&args, mesh, solid.frame)?.in_frame(solid.frame);
    let first = source.next_block()?;
    let ctx = if args.method.is_cpu() { None } else { Some(crate::open_context_for(device, "cpu")?) };
    let options = Options {
        tetragrid_resolution: args.grid.unwrap_or(texgeo::inclusion::tetragrid::DEFAULT_RESOLUTION),
        voxel_space_resolution: args.grid,
        ..solver::options_for(&solid, source.estimated_total(), args.allow_open)
    };
    let t = Instant::now();
    let (method, options, choice) = resolve(args.method, mesh, &options);
    let auto = choice
        .as_ref()
        .map(|c| if solid.non_solid.is_some() { "fast-winding".to_string() } else { c.to_string() });
    match &choice {
        Some(_) if solid.non_solid.is_some() => note!(
            "texgeo: --method auto: the generalized winding number (fast-winding) for {} faces and {} points",
            mesh.num_faces(),
            options.points
        ),
        Some(choice) => {
            note!(
                "texgeo: --method auto: {choice} for {} faces and {} points",
                mesh.num_faces(),
                options.points
            )
        }
        None => {}
    }
    let mut solver = Solver::new(method, mesh, &options, ctx.as_ref(), args.batch)
        .with_context(|| format!("preparing {} for {}", method, args.mesh))?;
    let build = t.elapsed();
    let streamed = classify_into(&mut solver, first, &mut source, args.output.as_deref())?;
    if args.output.is_some() && !args.json {
        return Ok(());
    }
    if args.json {
        texgeo::json::print(&solver::Summary {
            points: streamed.total(),
            inside: streamed.count(Class::Inside),
            outside: streamed.count(Class::Outside),
            boundary: streamed.count(Class::OnBoundary),
            method: solver.name().to_string(),
            auto,
            build,
            structure_bytes: solver.build_stats().bytes,
            classify: streamed.classify,
            gpu: streamed.gpu.clone(),
            device: ctx.as_ref().filter(|_| solver.gpu_stats().is_some()).map(|c| c.info().label()),
        });
        return Ok(());
    }
    print_summary(&args.mesh, &solver, &streamed, build, ctx.as_ref());
    Ok(())
}

/// Refuses, before anything is read or allocated, an output that is not a labels file
/// or would overwrite an input, and a point count that does not fit in memory (random
/// points and `.npy` files are held whole; text files are read a block at a time).
fn check_request(args: &Args) -> anyhow::Result<()> {
    if let Some(out) = &args.output {
        if out.extension().is_some() {
            texgeo::output::check_extension(
                out,
                &LABEL_EXTENSIONS,
                "labels are written as text (or NumPy), not in the format that name says",
            )?;
        }
        let mut inputs = crate::mesh::MeshArg::files([&args.mesh]);
        inputs.extend(args.points.as_deref());
        texgeo::output::check_output(out, &inputs)?;
    }
    match (&args.points, args.random) {
        (Some(file), _) if points::is_npy(file) => {
            // A point takes 12 bytes of .npy at least.
            let bytes = std::fs::metadata(file).map_err(|e| texgeo::output::Error::new(file, e))?.len();
            check_size(bytes / 12 + 1, true, args.output.is_some())?;
        }
        (None, Some(n)) => check_size(n as u64, false, args.output.is_some())?,
        _ => {}
    }
    Ok(())
}

/// The points: `--points FILE`, or `--random N` in the mesh's bounding box (in the
/// mesh's units).
fn point_source(
    args: &Args,
    mesh: &texgeo::mesh::Mesh,
    frame: texgeo::mesh::frame::Frame,
) -> anyhow::Result<points::PointReader> {
    Ok(match (&args.points, args.random) {
        (Some(file), _) => points::PointReader::open(file)?,
        (_, Some(n)) => {
            let (lo, hi) = mesh.bounds();
            let (lo, hi) = (frame.point_out(lo), frame.point_out(hi));
            points::PointReader::from_points(Rng::new(args.seed).points_in_box(n, lo, hi), "--random")
        }
        (None, None) => anyhow::bail!("give --points FILE or --random N"),
    })
}

/// Classifies every point block by block, writing the labels to `output` when given (a
/// text output as it goes; a `.npy` output needs the count in its header, so its one
/// byte per point waits for the end).
fn classify_into(
    solver: &mut Solver,
    first: Option<Vec<glam::DVec3>>,
    source: &mut points::PointReader,
    output: Option<&std::path::Path>,
) -> anyhow::Result<solver::Streamed> {
    let mut out = match output {
        Some(path) => Some(texgeo::output::AtomicFile::create(path)?),
        None => None,
    };
    let npy_out = output.is_some_and(points::is_npy);
    let mut all = Vec::new();
    let streamed = solver.classify_stream(first, source, |classes| -> anyhow::Result<()> {
        match &mut out {
            Some(_) if npy_out => all.extend_from_slice(classes),
            Some(file) => points::write_classes(file, classes).map_err(|e| file.error(e))?,
            None => {}
        }
        Ok(())
    })?;
    if let Some(mut file) = out {
        if npy_out {
            points::write_classes_npy(&mut file, &all).map_err(|e| file.error(e))?;
        }
        file.commit()?;
    }
    Ok(streamed)
}

/// The counts, the method's build and classification times and the GPU's share, for a
/// person.
fn print_summary(
    mesh: &crate::mesh::MeshArg,
    solver: &Solver,
    streamed: &solver::Streamed,
    build: std::time::Duration,
    ctx: Option<&texgeo::gpu::Context>,
) {
    say!(
        "{}: {} points, {} inside, {} outside, {} on the boundary",
        mesh,
        streamed.total(),
        streamed.count(Class::Inside),
        streamed.count(Class::Outside),
        streamed.count(Class::OnBoundary)
    );
    let stats = solver.build_stats();
    say!(
        "method {}: build {:.3} ms ({:.1} KiB of structures), read and classify {:.3} ms",
        solver.name(),
        build.as_secs_f64() * 1e3,
        stats.bytes as f64 / 1024.0,
        streamed.classify.as_secs_f64() * 1e3
    );
    if let Some(gpu) = &streamed.gpu {
        say!(
            "GPU: {} points drawn in {} draw(s), {:.3} ms; {} flagged and answered exactly on the CPU in {:.3} ms",
            gpu.gpu_points,
            gpu.draws,
            gpu.gpu.as_secs_f64() * 1e3,
            gpu.flagged,
            gpu.fallback.as_secs_f64() * 1e3
        );
        if let Some(ctx) = ctx {
            say!("device: {}", ctx.info().label());
        }
    }
}

/// Refuses, before any work, a point count whose memory exceeds what is available; the
/// message gives the estimate and the size of the output text. Also what `bench
/// inclusion` and `bench scale` check their point counts with.
pub fn check_size(count: u64, from_file: bool, to_file: bool) -> anyhow::Result<()> {
    let bytes = count.saturating_mul(BYTES_PER_POINT);
    if let Err((need, have)) = texgeo::host::check_available(bytes) {
        let what = if from_file { "the points of that file (at most)" } else { "that many points" };
        let text = if to_file {
            format!("; -o would be {} MiB of text", texgeo::host::Mib::of(count.saturating_mul(2)))
        } else {
            String::new()
        };
        anyhow::bail!(
            "{count} points: {what} need {need} MiB of memory, but only {have} MiB are available{text}"
        );
    }
    Ok(())
}

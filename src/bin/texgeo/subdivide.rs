//! `texgeo subdivide`: Catmull-Clark to a level, on the GPU with fragment meshes (2010
//! thesis Ch. 3) or with the CPU reference, optionally checked against OpenSubdiv. Sharp
//! features come from the OBJ file's tags (OpenSubdiv's `t crease`, `t corner`, `t hole`,
//! …); the scheme-wide options from its tags, overridden by the command's options.

use std::path::PathBuf;
use std::time::Instant;

use texgeo::host::{Mib, count_text};
use texgeo::mesh::{Mesh, formats};
use texgeo::subdiv::compare::Comparison;
use texgeo::subdiv::gpu::{Options, Run, Subdivider};
use texgeo::subdiv::{
    Boundary, CreaseMethod, Features, Method, SubdivError, Surface, Triangles, cpu, crease, osd,
};

/// Boundary interpolation (OpenSubdiv's VtxBoundaryInterpolation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BoundaryArg {
    /// Faces at untagged boundary vertices become holes.
    None,
    /// Boundary edges are creases (the default).
    EdgeOnly,
    /// Boundary edges are creases and vertices with one face are corners.
    EdgeAndCorner,
}

/// How semi-sharp creases decay (OpenSubdiv's CreasingMethod).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum CreaseMethodArg {
    /// Sharpness loses 1 per level (the default).
    Uniform,
    /// Chaikin's rule along crease chains.
    Chaikin,
}

/// Weights next to triangles (OpenSubdiv's TriangleSubdivision).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TrianglesArg {
    /// Catmull-Clark's masks (the default).
    Catmark,
    /// "Smooth triangle" weights.
    Smooth,
}

#[derive(clap::Args)]
pub struct Args {
    /// A mesh file (.obj .off .ply .stl) or `builtin:NAME` (see `texgeo mesh builtins`).
    /// An OBJ file's tags (OpenSubdiv's `t crease`, `t corner`, `t hole`,
    /// `t interpolateboundary`, `t creasemethod`, `t smoothtriangles`) are applied.
    input: crate::mesh::MeshArg,
    /// Subdivision level (each level splits every quad into four).
    #[arg(short, long)]
    level: u32,
    /// Output mesh (.obj or .off; .ply and .stl work too). Faces under holes are left out.
    #[arg(short, long)]
    output: Option<PathBuf>,
    #[arg(long, value_enum, default_value_t = Method::Gpu)]
    method: Method,
    /// Boundary interpolation (overrides the file's `t interpolateboundary`).
    #[arg(long, value_enum)]
    boundary: Option<BoundaryArg>,
    /// Creasing method (overrides the file's `t creasemethod`).
    #[arg(long, value_enum)]
    crease_method: Option<CreaseMethodArg>,
    /// Triangle weights (overrides the file's `t smoothtriangles`).
    #[arg(long, value_enum)]
    triangles: Option<TrianglesArg>,
    /// Also crease every edge whose two faces meet at more than DEGREES (feature edges).
    #[arg(long, value_name = "DEGREES")]
    crease_angle: Option<f64>,
    /// Sharpness of the --crease-angle creases (10 or more: infinitely sharp).
    #[arg(long, default_value_t = 10.0, requires = "crease_angle")]
    crease_sharpness: f32,
    /// Also refine with OpenSubdiv (tools/setup builds its helper) and compare: vertex and
    /// face counts, max/RMS position error; exit status 1 if the tolerance is exceeded
    /// (1e-5 × bounding-box diagonal for the GPU, 1e-12 for the CPU).
    #[arg(long)]
    validate: bool,
    /// Print one JSON object on stdout (counts, features, times in ms, the GPU run and the
    /// --validate comparison); the text lines go to stderr.
    #[arg(long)]
    json: bool,
}

/// Relative tolerances of `--validate` (SPEC §5.1, §5.4).
const GPU_TOLERANCE: f64 = 1e-5;
const CPU_TOLERANCE: f64 = 1e-12;

fn ms(d: std::time::Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn describe_gpu(run: &Run) {
    let t = &run.times;
    for reason in &run.cpu_reasons {
        say!("the fragments cannot express this yet; {reason}");
    }
    if run.gpu_levels == 0 && run.fragments == 0 {
        say!(
            "level {} {}: computed on the CPU ({:.1} ms)",
            run.cpu_levels,
            if run.cpu_reasons.is_empty() {
                "is below the base level"
            } else {
                "is reached before fragments"
            },
            ms(t.total)
        );
        return;
    }
    say!(
        "GPU: {} CPU level(s), {} fragment pass(es); {} fragments ({} with sharpness data) in {} runs; \
         targets 2 × {}×{} RGBA32F",
        run.cpu_levels,
        run.gpu_levels,
        run.fragments,
        run.sharp_fragments,
        run.classes,
        run.texture[0],
        run.texture[1]
    );
    let passes: Vec<String> = t.passes.iter().map(|&p| format!("{:.1}", ms(p))).collect();
    say!(
        "time: {:.1} ms = base level {:.1} + fragments {:.1} + submission {:.1} (upload {:.1}, passes [{}], \
         readback {:.1}; GPU timestamps) + assembly {:.1}",
        ms(t.total),
        ms(t.base),
        ms(t.fragments),
        ms(t.submit),
        ms(t.upload),
        passes.join(", "),
        ms(t.readback),
        ms(t.assembly)
    );
}

/// Counts at or above this are "more than 2^64 − 1" (the estimate stops there).
const COUNT_LIMIT: u128 = 1 << 64;

/// Exact vertex, face and edge counts after `level` Catmull-Clark steps: one step makes
/// V + E + F vertices, Σ degrees quads and 2E + Σ degrees edges, whatever the mesh.
/// Counts stop at [`COUNT_LIMIT`].
fn refined_counts(mesh: &Mesh, level: u32) -> (u128, u128, u128) {
    let r = mesh.report();
    let corners: usize = mesh.faces().map(<[u32]>::len).sum();
    let (mut v, mut f, mut e) = ((r.vertices - r.unused_vertices) as u128, r.faces as u128, r.edges as u128);
    let mut c = corners as u128;
    for _ in 0..level {
        let next = [v + e + f, c, 2 * e + c, 4 * c].map(|x| x.min(COUNT_LIMIT));
        // Saturated or unchanged (no faces): every further level is the same.
        if next == [v, f, e, c] {
            break;
        }
        [v, f, e, c] = next;
    }
    (v, f, e)
}

/// Refuses, before any level is built, a level whose result does not fit: 32-bit vertex
/// indices, or the memory of the last level and the refined mesh (plus the GPU's
/// ping-pong targets and readback); the message gives the estimate and the output size.
fn check_size(
    mesh: &Mesh,
    level: u32,
    method: Method,
    output: Option<&std::path::Path>,
) -> anyhow::Result<()> {
    let (v, f, e) = refined_counts(mesh, level);
    let text = match output {
        Some(p) => format!("; {} would be about {} MiB", p.display(), Mib::of_wide(60 * v + 30 * f)),
        None => String::new(),
    };
    let (vs, fs) = (count_text(v, COUNT_LIMIT), count_text(f, COUNT_LIMIT));
    if v >= u64::from(u32::MAX) as u128 || 4 * f >= u64::from(u32::MAX) as u128 {
        anyhow::bail!(
            "level {level} would have {vs} vertices and {fs} faces, more than 32-bit indices hold{text}"
        );
    }
    // The last level and the mesh built from it (as `cpu::refine` counts them), and for
    // the GPU two RGBA32F targets and a readback, fragments overlapping by up to 2×.
    let gpu = if method == Method::Gpu { 3 * 16 * 2 * v } else { 0 };
    let bytes = 48 * v + 64 * f + 9 * e + gpu;
    if let Err((need, have)) = texgeo::host::check_available(Mib::saturate(bytes)) {
        anyhow::bail!(
            "level {level} ({vs} vertices, {fs} faces) needs {need} MiB, but only {have} MiB are available{text}; \
             use a lower level"
        );
    }
    Ok(())
}

/// One line on the sharp features and options in force.
fn describe_features(surface: &Surface) {
    let f = &surface.features;
    let infinite = f.creases.iter().filter(|c| crease::is_infinite(c.sharpness)).count();
    let o = &surface.options;
    say!(
        "features: {} crease edge(s) ({infinite} infinitely sharp), {} corner(s), {} hole(s); boundary {}, \
         creasing {}, triangles {}",
        f.creases.len(),
        f.corners.len(),
        f.holes.len(),
        match o.boundary {
            Boundary::None => "none",
            Boundary::EdgeOnly => "edge-only",
            Boundary::EdgeAndCorner => "edge-and-corner",
        },
        match o.crease_method {
            CreaseMethod::Uniform => "uniform",
            CreaseMethod::Chaikin => "chaikin",
        },
        match o.triangles {
            Triangles::Catmark => "catmark",
            Triangles::Smooth => "smooth",
        },
    );
}

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    if let Some(out) = &args.output {
        // A wrong extension or an unwritable folder fails now, not after the subdivision.
        formats::Format::from_path(out)?;
        texgeo::output::check_output(out, &crate::mesh::MeshArg::files([&args.input]))?;
    }
    if args.json {
        texgeo::json::text_to_stderr();
    }
    let tagged = crate::mesh::load_tagged(&args.input)?;
    for ignored in &tagged.ignored {
        say!("{}:{}: tag '{}' ignored: {}", args.input, ignored.line, ignored.name, ignored.why);
    }
    let mut surface = tagged.surface(Default::default());
    if let Some(b) = args.boundary {
        surface.options.boundary = match b {
            BoundaryArg::None => Boundary::None,
            BoundaryArg::EdgeOnly => Boundary::EdgeOnly,
            BoundaryArg::EdgeAndCorner => Boundary::EdgeAndCorner,
        };
    }
    if let Some(m) = args.crease_method {
        surface.options.crease_method = match m {
            CreaseMethodArg::Uniform => CreaseMethod::Uniform,
            CreaseMethodArg::Chaikin => CreaseMethod::Chaikin,
        };
    }
    if let Some(t) = args.triangles {
        surface.options.triangles = match t {
            TrianglesArg::Catmark => Triangles::Catmark,
            TrianglesArg::Smooth => Triangles::Smooth,
        };
    }
    if let Some(degrees) = args.crease_angle {
        anyhow::ensure!((0.0..=180.0).contains(&degrees), "--crease-angle must be in 0..=180 degrees");
        anyhow::ensure!(
            args.crease_sharpness.is_finite() && args.crease_sharpness >= 0.0,
            "--crease-sharpness must be a finite number ≥ 0"
        );
        let features = Features::feature_edges(&surface.mesh, degrees, args.crease_sharpness);
        surface.features.creases.extend(features.creases);
    }
    let mesh = &surface.mesh;
    check_size(mesh, args.level, args.method, args.output.as_deref())?;
    say!("{}: {} vertices, {} faces", args.input, mesh.num_vertices(), mesh.num_faces());
    describe_features(&surface);
    let start = Instant::now();
    let mut gpu_run = None;
    let refined = match args.method {
        Method::Gpu => {
            let ctx = crate::open_context_for(device, "cpu")?;
            say!("device: {}", ctx.info().label());
            let mut subdivider = Subdivider::new(&ctx)?;
            let run = subdivider
                .refine_surface(&ctx, &surface, args.level, &Options::default())
                .map_err(explain)?;
            describe_gpu(&run);
            gpu_run = Some(serde_json::to_value(&run)?);
            run.mesh
        }
        Method::Cpu => {
            let start = Instant::now();
            let refined = cpu::refine_surface(&surface, args.level).map_err(explain)?;
            say!("CPU reference: {:.1} ms", ms(start.elapsed()));
            refined.mesh
        }
    };
    say!("level {}: {} vertices, {} faces", args.level, refined.num_vertices(), refined.num_faces());
    if let Some(out) = &args.output {
        let t = Instant::now();
        formats::write(out, &refined)?;
        say!("wrote {} in {:.1} ms", out.display(), ms(t.elapsed()));
    }
    let time = start.elapsed();
    let comparison =
        if args.validate { Some(validate(&surface, &refined, args.level, args.method)?) } else { None };
    if args.json {
        let f = &surface.features;
        texgeo::json::print(&serde_json::json!({
            "input": args.input.to_string(),
            "vertices": mesh.num_vertices(),
            "faces": mesh.num_faces(),
            "level": args.level,
            "method": texgeo::choice::name(&args.method),
            "features": {
                "creases": f.creases.len(),
                "infinite_creases": f.creases.iter().filter(|c| crease::is_infinite(c.sharpness)).count(),
                "corners": f.corners.len(),
                "holes": f.holes.len(),
            },
            "refined_vertices": refined.num_vertices(),
            "refined_faces": refined.num_faces(),
            "time_ms": ms(time),
            "gpu": gpu_run,
            "output": args.output.as_ref().map(|p| p.display().to_string()),
            "validation": comparison.as_ref().map(|(c, tolerance)| serde_json::json!({
                "passed": c.is_match(),
                "tolerance": tolerance,
                "comparison": c,
            })),
        }));
    }
    if comparison.is_some_and(|(c, _)| !c.is_match()) {
        std::process::exit(1);
    }
    Ok(())
}

/// Compares with OpenSubdiv; prints the comparison and whether it is within tolerance.
/// Returns it and the relative tolerance.
fn validate(
    surface: &Surface,
    refined: &Mesh,
    level: u32,
    method: Method,
) -> anyhow::Result<(Comparison, f64)> {
    let start = Instant::now();
    let reference = osd::refine_surface(surface, level)?;
    let tolerance = if method == Method::Gpu { GPU_TOLERANCE } else { CPU_TOLERANCE };
    let c = Comparison::new(refined, &reference, tolerance);
    say!("OpenSubdiv ({:.1} ms incl. files): {c}", ms(start.elapsed()));
    say!(
        "validation {}: tolerance {tolerance:e} × bounding-box diagonal",
        if c.is_match() { "passed" } else { "FAILED" }
    );
    Ok((c, tolerance))
}

/// Adds what to do about input that cannot be refined.
fn explain(e: SubdivError) -> anyhow::Error {
    let hint = match &e {
        SubdivError::Feature(_) => "check the mesh's tags (t crease, t corner, t hole)",
        SubdivError::GpuLimit(_) => "try --method cpu or a lower level",
        _ => return e.into(),
    };
    anyhow::Error::new(e).context(format!("cannot subdivide: {hint}"))
}

//! `texgeo subdivide`: Catmull-Clark to a level, on the GPU with fragment meshes (2010
//! thesis Ch. 3) or with the CPU reference, optionally checked against OpenSubdiv.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context as _;
use texgeo::mesh::{Mesh, formats};
use texgeo::subdiv::compare::Comparison;
use texgeo::subdiv::gpu::{Options, Run, Subdivider};
use texgeo::subdiv::{SubdivError, cpu, osd};

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Method {
    /// Base level on the CPU, then one fragment pass per level on the GPU.
    Gpu,
    /// The f64 CPU reference (same vertex order as OpenSubdiv).
    Cpu,
}

#[derive(clap::Args)]
pub struct Args {
    /// A mesh file (.obj .off .ply .stl) or `builtin:NAME` (see `texgeo mesh builtins`).
    input: String,
    /// Subdivision level (each level splits every quad into four).
    #[arg(short, long)]
    level: u32,
    /// Output mesh (.obj or .off; .ply and .stl work too).
    #[arg(short, long)]
    output: Option<PathBuf>,
    #[arg(long, value_enum, default_value_t = Method::Gpu)]
    method: Method,
    /// Also refine with OpenSubdiv (tools/setup builds its helper) and compare: vertex and
    /// face counts, max/RMS position error; exit status 1 if the tolerance is exceeded
    /// (1e-5 × bounding-box diagonal for the GPU, 1e-12 for the CPU).
    #[arg(long)]
    validate: bool,
}

/// Relative tolerances of `--validate` (SPEC §5.1, §5.4).
const GPU_TOLERANCE: f64 = 1e-5;
const CPU_TOLERANCE: f64 = 1e-12;

fn ms(d: std::time::Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn describe_gpu(run: &Run) {
    let t = &run.times;
    if run.gpu_levels == 0 && run.fragments == 0 {
        println!(
            "level {} is below the base level: computed on the CPU ({:.1} ms)",
            run.cpu_levels,
            ms(t.total)
        );
        return;
    }
    println!(
        "GPU: {} CPU level(s), {} fragment pass(es); {} fragments in {} classes; targets 2 × {}×{} RGBA32F",
        run.cpu_levels, run.gpu_levels, run.fragments, run.classes, run.texture[0], run.texture[1]
    );
    let passes: Vec<String> = t.passes.iter().map(|&p| format!("{:.1}", ms(p))).collect();
    println!(
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

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    if let Some(out) = &args.output {
        // A wrong extension fails now, not after the subdivision.
        formats::Format::from_path(out)?;
    }
    let mesh = crate::mesh::load(&args.input)?;
    println!("{}: {} vertices, {} faces", args.input, mesh.num_vertices(), mesh.num_faces());
    let refined = match args.method {
        Method::Gpu => {
            let ctx = crate::open_context(device)?;
            println!("device: {}", ctx.info().label());
            let mut subdivider = Subdivider::new(&ctx)?;
            let run = subdivider.refine(&ctx, &mesh, args.level, &Options::default()).map_err(explain)?;
            describe_gpu(&run);
            run.mesh
        }
        Method::Cpu => {
            let start = Instant::now();
            let refined = cpu::refine(&mesh, args.level).map_err(explain)?;
            println!("CPU reference: {:.1} ms", ms(start.elapsed()));
            refined
        }
    };
    println!("level {}: {} vertices, {} faces", args.level, refined.num_vertices(), refined.num_faces());
    if let Some(out) = &args.output {
        formats::write(out, &refined).with_context(|| format!("writing {}", out.display()))?;
        println!("wrote {}", out.display());
    }
    if args.validate && !validate(&mesh, &refined, args.level, args.method)? {
        std::process::exit(1);
    }
    Ok(())
}

/// Compares with OpenSubdiv; prints the comparison and whether it is within tolerance.
fn validate(mesh: &Mesh, refined: &Mesh, level: u32, method: Method) -> anyhow::Result<bool> {
    let start = Instant::now();
    let reference = osd::refine(mesh, level)?;
    let tolerance = if method == Method::Gpu { GPU_TOLERANCE } else { CPU_TOLERANCE };
    let c = Comparison::new(refined, &reference, tolerance);
    println!("OpenSubdiv ({:.1} ms incl. files): {c}", ms(start.elapsed()));
    let ok = c.is_match();
    println!(
        "validation {}: tolerance {tolerance:e} × bounding-box diagonal",
        if ok { "passed" } else { "FAILED" }
    );
    Ok(ok)
}

/// Adds what to do about input Catmull-Clark cannot refine.
fn explain(e: SubdivError) -> anyhow::Error {
    let hint = match &e {
        SubdivError::Feature(_) => "check the mesh's tags (t crease, t corner, t hole)",
        SubdivError::GpuLimit(_) => "try --method cpu or a lower level",
        _ => return e.into(),
    };
    anyhow::Error::new(e).context(format!("cannot subdivide: {hint}"))
}

//! The `texgeo` command line. Errors print one message and exit with status 2 (a failed
//! `--validate` comparison exits with status 1). Every output file is written atomically
//! ([`texgeo::output`]) after its path was checked, before any work; SIGINT, SIGTERM and
//! SIGHUP remove the temporary files of unfinished outputs. Every message goes through
//! [`texgeo::terminal`]: control bytes from files are escaped, and a closed stdout or
//! stderr (`texgeo … 2>&1 | head`) only loses the printed lines.

// `say!` (stdout) and `note!` (stderr): see `texgeo::terminal`.
#[macro_use]
extern crate texgeo;

mod args;
mod bench;
mod boolean;
mod check;
mod csg;
mod demo;
mod inclusion;
mod info;
mod mesh;
mod render;
mod reproduce;
mod subdivide;
mod sweep;
mod view;
mod voxelize;

use clap::{Parser, Subcommand};
use texgeo::gpu::{Context, ContextOptions, DeviceChoice};

#[derive(Parser)]
#[command(
    name = "texgeo",
    version,
    about = "GPGPU-texture-era geometry on raw Vulkan: point-in-solid, voxelization, Catmull-Clark"
)]
struct Cli {
    /// Vulkan device: a name part (e.g. `lavapipe`) or an index from `texgeo info --all`.
    /// Default: TEXGEO_DEVICE, else the first GPU, else lavapipe.
    #[arg(long, global = true, value_name = "NAME|INDEX")]
    device: Option<String>,
    /// Worker threads for every command's CPU work (default: every core; at most 1024); the
    /// output is the same for any count.
    #[arg(long, global = true, value_name = "N", value_parser = args::threads)]
    threads: Option<usize>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Show the Vulkan device texgeo would use: driver, limits, logicOp, texture sizes.
    Info(info::Args),
    /// Check every shader on this device against the CPU references (the first thing to
    /// run on a new GPU or driver); exits 1 when a check fails.
    Check(check::Args),
    /// Inspect and convert meshes (OBJ, OFF, PLY, STL).
    #[command(subcommand)]
    Mesh(mesh::Command),
    /// Point in solid (Feito-Torres): classify query points as inside, outside or on the boundary.
    Inclusion(inclusion::Args),
    /// Catmull-Clark subdivision: fragment meshes on the GPU, or the CPU reference.
    Subdivide(subdivide::Args),
    /// Run a benchmark and write Markdown + CSV tables.
    #[command(subcommand)]
    Bench(bench::Command),
    /// A short tour on built-in data: reduction, XOR raster, model statistics, Catmull-Clark.
    Demo(demo::Args),
    /// Solid voxelization by slicing tetrahedra with XOR; writes .binvox (+ PNG slices).
    Voxelize(voxelize::Args),
    /// Run a task over a mesh collection: each mesh isolated, resumable, shardable; `sweep merge DIR`.
    Sweep(sweep::Args),
    /// An offscreen picture (PNG) of a mesh, a subdivision level or a voxel volume.
    Render(render::Args),
    /// An interactive window: orbit a mesh, step through subdivision levels live, voxels.
    View(view::Args),
    /// Every experiment of both theses in one report: tables beside the thesis', plots,
    /// pictures and a verdict on every claim (`--compare OLD NEW` compares two runs).
    Reproduce(reproduce::Args),
    /// Boolean operations on closed solids: union, intersection, difference, symmetric difference.
    Boolean(boolean::Args),
    /// A CSG expression over named solids: "(a | b) - c" with Python's set operators.
    Csg(csg::Args),
}

/// Opens the device chosen by `--device` / `TEXGEO_DEVICE`.
pub fn open_context(device: Option<&str>) -> anyhow::Result<Context> {
    let options = ContextOptions { device: DeviceChoice::from_env_or(device), validation: None };
    Ok(Context::new(&options)?)
}

/// Opens the device for a GPU method of a command that also has CPU methods: without a
/// Vulkan driver, the message says which CPU method to use instead.
pub fn open_context_for(device: Option<&str>, cpu_method: &str) -> anyhow::Result<Context> {
    let options = ContextOptions { device: DeviceChoice::from_env_or(device), validation: None };
    Context::new(&options).map_err(|e| {
        if e.is_missing_driver() {
            anyhow::anyhow!("{e}; without a Vulkan driver, use a CPU method (--method {cpu_method})")
        } else {
            e.into()
        }
    })
}

fn main() {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help, --version: not errors.
            let _ = e.print();
            return;
        }
        Err(e) => {
            // clap's usage errors, on one line like every other error (without the usage
            // block, which --help shows).
            let text = e.to_string();
            let parts: Vec<&str> = text
                .lines()
                .map(str::trim)
                .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
                .filter(|l| !l.is_empty())
                .collect();
            note!("texgeo: error: {} (see --help)", parts.join(" ").trim_start_matches("error: "));
            std::process::exit(2);
        }
    };
    let device = cli.device.as_deref();
    if let Err(e) = args::use_threads(cli.threads) {
        note!("texgeo: error: {}", one_line(&e));
        std::process::exit(2);
    }
    // Without it an interrupted write leaves its temporary file (removed by the next run
    // of the same output, which is all that is lost).
    if let Err(e) = texgeo::output::remove_temporaries_on_signals() {
        note!("texgeo: warning: no signal handler ({e}); Ctrl-C may leave temporary files");
    }
    let result = match cli.command {
        Command::Info(a) => info::run(device, a),
        Command::Check(a) => check::run(device, a),
        Command::Mesh(c) => mesh::run(c),
        Command::Inclusion(a) => inclusion::run(device, a),
        Command::Subdivide(a) => subdivide::run(device, a),
        Command::Bench(c) => bench::run(device, c),
        Command::Demo(a) => demo::run(device, a),
        Command::Voxelize(a) => voxelize::run(device, a),
        Command::Sweep(a) => sweep::run(device, a),
        Command::Render(a) => render::run(device, a),
        Command::View(a) => view::run(device, a),
        Command::Reproduce(a) => reproduce::run(device, a),
        Command::Boolean(a) => boolean::run(device, a),
        Command::Csg(a) => csg::run(device, a),
    };
    if let Err(e) = result {
        note!("texgeo: error: {}", one_line(&e));
        std::process::exit(2);
    }
}

/// The error and its causes on one line, each cause once (a cause whose text its
/// context already repeats is not printed again).
fn one_line(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if out.contains(&text) {
            continue;
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        out.push_str(&text);
    }
    out.lines().map(str::trim).collect::<Vec<_>>().join(" ")
}

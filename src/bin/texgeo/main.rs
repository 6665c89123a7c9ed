//! The `texgeo` command line. Errors print one message and exit with status 2 (a failed
//! `--validate` comparison exits with status 1).

mod bench;
mod boolean;
mod demo;
mod inclusion;
mod info;
mod mesh;
mod subdivide;
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
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Show the Vulkan device texgeo would use: driver, limits, logicOp, texture sizes.
    Info(info::Args),
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
    /// Boolean operations on two closed solids: union, intersection, difference, symmetric difference.
    Boolean(boolean::Args),
}

/// Opens the device chosen by `--device` / `TEXGEO_DEVICE`.
pub fn open_context(device: Option<&str>) -> anyhow::Result<Context> {
    let options = ContextOptions { device: DeviceChoice::from_env_or(device), validation: None };
    Ok(Context::new(&options)?)
}

fn main() {
    let cli = Cli::parse();
    let device = cli.device.as_deref();
    let result = match cli.command {
        Command::Info(a) => info::run(device, a),
        Command::Mesh(c) => mesh::run(c),
        Command::Inclusion(a) => inclusion::run(device, a),
        Command::Subdivide(a) => subdivide::run(device, a),
        Command::Bench(c) => bench::run(device, c),
        Command::Demo(a) => demo::run(device, a),
        Command::Voxelize(a) => voxelize::run(device, a),
        Command::Boolean(a) => boolean::run(device, a),
    };
    if let Err(e) = result {
        eprintln!("texgeo: error: {e:#}");
        std::process::exit(2);
    }
}

//! `texgeo bench …`: each suite writes Markdown + CSV into `--out` and prints the Markdown.

use std::path::PathBuf;

use anyhow::Context as _;

use texgeo::gpu::Context;
use texgeo::mesh::Mesh;
use texgeo::report::{Report, bench};

use crate::mesh::MeshArg;

#[derive(clap::Subcommand)]
pub enum Command {
    /// Point in solid: the thesis' Tables 4-4 to 4-9 for every method.
    Inclusion(InclusionArgs),
    /// Voxelization: the thesis' Table 5-2 (64³ … 512³, every method), time split and ratios.
    Voxelize(VoxelizeArgs),
    /// Booleans: the thesis' Table 6-1 (phases, plain vs grouped, CPU vs GPU point tests,
    /// CGAL) on stand-in pairs, and the growth from 1 k to 100 k triangles.
    Boolean(BooleanArgs),
    /// Inclusion and voxelization at scale: inclusion at 1 k / 100 k / 1 M points (every method, `auto`
    /// included) and voxelization at 128³ … 1024³, time and peak memory per method and
    /// thread count; point-file and label throughput.
    Scale(ScaleArgs),
    /// XOR rasterization (logic op) of random triangles against the CPU scanline rasterizer.
    Xor(XorArgs),
    /// 2×2 ping-pong sum reduction (512², 2048², 4096²) against a plain CPU sum.
    Reduce(ReduceArgs),
    /// The 2010 thesis' Table 5: Catmull-Clark to level 5 with fragment meshes on the GPU
    /// vs the CPU reference and OpenSubdiv, on built-in models and fetched ones.
    Subdivide(SubdivideArgs),
}

#[derive(clap::Args)]
pub struct InclusionArgs {
    #[command(flatten)]
    models: Models,
    /// Point sets per model (the thesis: 10).
    #[arg(long, default_value_t = 10, value_parser = crate::args::positive_usize)]
    sets: usize,
    /// Points per set (the thesis: 1000).
    #[arg(long, default_value_t = 1000, value_parser = crate::args::positive_usize)]
    points: usize,
    /// TetraGrid resolutions for Tables 4-4 and 4-5 (2..=64).
    #[arg(long, value_delimiter = ',', default_values_t = vec![2, 4, 8, 16, 32, 64])]
    resolutions: Vec<usize>,
    /// Folder for the Markdown and CSV files.
    #[arg(short, long = "output", alias = "out", value_name = "DIR", default_value = "out/bench")]
    out: PathBuf,
}

#[derive(clap::Args)]
pub struct VoxelizeArgs {
    #[command(flatten)]
    models: Models,
    /// Resolutions N (N³ voxels, 1..=1024).
    #[arg(long, value_delimiter = ',', default_values_t = bench::voxelize::DEFAULT_RESOLUTIONS.to_vec())]
    sizes: Vec<usize>,
    /// Methods to measure (default: all).
    #[arg(long, value_delimiter = ',', value_enum)]
    methods: Vec<texgeo::voxel::Method>,
    /// Zone height in slices for `zoned`: a number ≥ 1, or `auto` (N/8, between 4 and 32).
    #[arg(long, default_value_t = texgeo::voxel::Zone::Auto)]
    zone: texgeo::voxel::Zone,
    /// Timed runs per measurement (the median is reported).
    #[arg(long, default_value_t = 3, value_parser = crate::args::positive_usize)]
    runs: usize,
    /// Folder for the Markdown and CSV files.
    #[arg(short, long = "output", alias = "out", value_name = "DIR", default_value = "out/bench")]
    out: PathBuf,
}

#[derive(clap::Args)]
pub struct BooleanArgs {
    #[command(flatten)]
    models: Models,
    /// CPU inclusion method for the point tests.
    #[arg(
        long,
        value_parser = texgeo::choice::value_parser::<texgeo::inclusion::Method>(texgeo::inclusion::method::AUTO),
        default_value_t = texgeo::inclusion::Choice::Fixed(texgeo::inclusion::Method::Octants)
    )]
    method: texgeo::inclusion::Choice,
    /// Skip the plain classification (one point test per triangle; slow on big models).
    #[arg(long)]
    no_plain: bool,
    /// Skip CGAL.
    #[arg(long)]
    no_cgal: bool,
    /// Triangle counts of the scaling series (sphere − turned copy); 0 = none.
    #[arg(long, value_delimiter = ',', default_values_t = vec![1_000, 4_000, 16_000, 64_000, 100_000])]
    scaling: Vec<usize>,
    /// Only the scaling series, not Table 6-1.
    #[arg(long)]
    scaling_only: bool,
    /// Also write each scaling pair as DIR/sphere-N-a.off and DIR/sphere-N-b.off (N
    /// the --scaling count), so that peers can be timed on the same inputs
    /// (tools/boolean-scaling).
    #[arg(long, value_name = "DIR")]
    write_scaling: Option<PathBuf>,
    #[command(flatten)]
    common: Common,
}

#[derive(clap::Args)]
pub struct ScaleArgs {
    /// The inclusion solid (default: armadillo.off in --models-dir, else builtin:knot).
    #[arg(long)]
    mesh: Option<MeshArg>,
    /// The voxelization solid (default: the inclusion one).
    #[arg(long)]
    voxel_mesh: Option<MeshArg>,
    /// Where `tools/fetch-models` put the meshes.
    #[arg(long, default_value = "models")]
    models_dir: PathBuf,
    /// Query-point counts.
    #[arg(long, value_delimiter = ',', default_values_t = bench::scale::DEFAULT_POINTS.to_vec())]
    points: Vec<usize>,
    /// Inclusion methods (default: all, `auto` first).
    #[arg(
        long,
        value_delimiter = ',',
        value_parser = texgeo::choice::value_parser::<texgeo::inclusion::Method>(texgeo::inclusion::method::AUTO)
    )]
    methods: Vec<texgeo::inclusion::Choice>,
    /// Voxel grid sizes N (N³; empty: no voxelization).
    #[arg(long, value_delimiter = ',', default_values_t = bench::scale::DEFAULT_SIZES.to_vec())]
    sizes: Vec<usize>,
    /// Voxelization methods (default: all).
    #[arg(long, value_delimiter = ',', value_enum)]
    voxel_methods: Vec<texgeo::voxel::Method>,
    /// Pool sizes to measure (default: 1 and every core; at most 1024).
    #[arg(long, value_delimiter = ',', value_parser = crate::args::threads)]
    thread_counts: Vec<usize>,
    /// Skip a measurement predicted to take longer than this many seconds (at most 10⁶).
    #[arg(long, default_value = "60", value_parser = |s: &str| crate::args::seconds(s, 1e6))]
    budget: std::time::Duration,
    #[arg(long, default_value_t = 3, value_parser = crate::args::positive_usize)]
    /// Timed runs per measurement (the median is reported).
    runs: usize,
    /// Folder for the Markdown and CSV files.
    #[arg(short, long = "output", alias = "out", value_name = "DIR", default_value = "out/bench")]
    out: PathBuf,
}

#[derive(clap::Args)]
pub struct XorArgs {
    /// Target sides to measure.
    #[arg(long, value_delimiter = ',', default_values_t = bench::xor::DEFAULT_SIDES.to_vec())]
    sizes: Vec<u32>,
    /// Triangles per target.
    #[arg(long, default_value_t = 20_000, value_parser = crate::args::positive_usize)]
    triangles: usize,
    #[command(flatten)]
    common: Common,
}

#[derive(clap::Args)]
pub struct ReduceArgs {
    /// Texture sides to measure.
    #[arg(long, value_delimiter = ',', default_values_t = bench::reduce::DEFAULT_SIDES.to_vec())]
    sizes: Vec<u32>,
    #[command(flatten)]
    common: Common,
}

#[derive(clap::Args)]
pub struct SubdivideArgs {
    /// Subdivision level (≥ 1).
    #[arg(long, short, default_value_t = 5, value_parser = crate::args::positive_u32)]
    level: u32,
    /// Extra mesh files (or `builtin:NAME`) to measure after the default models.
    #[arg(long = "mesh", value_name = "MESH")]
    meshes: Vec<MeshArg>,
    /// Folder of fetched models (tools/fetch-models); those of the default set found
    /// there are measured.
    #[arg(long, default_value = "models")]
    models: PathBuf,
    /// Measure only the given --mesh files.
    #[arg(long)]
    only: bool,
    /// Also compare every GPU result with OpenSubdiv (slow on millions of faces).
    #[arg(long)]
    validate: bool,
    /// Instead of Table 5: sharp features — each model with its feature edges creased
    /// against itself without creases (default models: fandisk.off and
    /// couplingdown.off when fetched, builtin:knot).
    #[arg(long)]
    creases: bool,
    /// With --creases: edges whose faces meet at more than this many degrees are creased.
    #[arg(long, default_value_t = 30.0)]
    crease_angle: f64,
    #[command(flatten)]
    common: Common,
}

/// Models for the thesis-table benchmarks: `--models` or the stand-ins found in `--models-dir`.
#[derive(clap::Args)]
pub struct Models {
    /// Meshes to use (files or `builtin:NAME`), instead of the thesis stand-ins.
    #[arg(long, value_delimiter = ',')]
    models: Vec<MeshArg>,
    /// Where `tools/fetch-models` put the CGAL meshes.
    #[arg(long, default_value = "models")]
    models_dir: PathBuf,
}

impl Models {
    /// `model(thesis model, name, mesh)` for each model to run.
    fn load<M>(
        &self,
        stand_ins: &[(&'static str, &'static str)],
        model: impl Fn(&'static str, String, Mesh) -> anyhow::Result<M>,
    ) -> anyhow::Result<Vec<M>> {
        if !self.models.is_empty() {
            return self.models.iter().map(|m| model("–", m.to_string(), crate::mesh::load(m)?)).collect();
        }
        let mut out = Vec::new();
        for &(thesis, spec) in stand_ins {
            let arg = MeshArg::from(spec).in_folder(&self.models_dir);
            if arg.file().is_none_or(std::path::Path::exists) {
                out.push(model(thesis, spec.to_string(), crate::mesh::load(&arg)?)?);
            } else {
                note!("texgeo: {arg} not found (run tools/fetch-models); skipping the {thesis} stand-in");
            }
        }
        Ok(out)
    }
}

#[derive(clap::Args)]
pub struct Common {
    /// Timed runs per measurement (the median is reported).
    #[arg(long, default_value_t = 5, value_parser = crate::args::positive_usize)]
    runs: usize,
    /// Folder for the Markdown and CSV files.
    #[arg(short, long = "output", alias = "out", value_name = "DIR", default_value = "out/bench")]
    out: PathBuf,
}

/// Bytes per triangle of a Boolean in the scaling series (both operands, their
/// intersections, classification and result), generously.
const BOOLEAN_BYTES_PER_TRIANGLE: u128 = 4096;

/// Refuses, before the device opens, a size whose memory the machine does not have (the
/// same estimate-and-refuse check as the commands').
fn check_memory(what: String, bytes: u128) -> anyhow::Result<()> {
    texgeo::host::check_memory(what, bytes).map_err(anyhow::Error::msg)
}

fn finish(report: Report, common: &Common) -> anyhow::Result<()> {
    say!("{}", report.to_markdown());
    for f in report.write(&common.out)? {
        note!("wrote {}", f.display());
    }
    Ok(())
}

/// Every size that drives an allocation, checked before anything is measured.
fn check_sizes(cmd: &Command) -> anyhow::Result<()> {
    match cmd {
        Command::Inclusion(a) => {
            crate::inclusion::check_size((a.sets as u64).saturating_mul(a.points as u64), false, false)
        }
        Command::Scale(a) => {
            a.points.iter().try_for_each(|&n| crate::inclusion::check_size(n as u64, false, false))
        }
        Command::Boolean(a) => a.scaling.iter().try_for_each(|&n| {
            // Sphere operands: about n/8 vertices each, indexed by 32 bits.
            anyhow::ensure!(
                n as u128 / 8 < u128::from(u32::MAX),
                "--scaling {n}: more triangles than 32-bit vertex indices allow"
            );
            check_memory(
                format!("--scaling {n}: two {n}-triangle operands"),
                n as u128 * BOOLEAN_BYTES_PER_TRIANGLE,
            )
        }),
        Command::Xor(XorArgs { sizes, triangles, .. }) => {
            anyhow::ensure!(
                (*triangles as u128) * 3 <= u128::from(u32::MAX),
                "--triangles {triangles}: more vertices than one draw takes (at most {} triangles)",
                u32::MAX / 3
            );
            sizes.iter().try_for_each(|&n| {
                // Triangles twice (list and vertex buffer) and three n² words (the CPU
                // reference, the target, its readback).
                let bytes = *triangles as u128 * 48 + 12 * u128::from(n) * u128::from(n);
                check_memory(format!("{triangles} triangles into a {n}² target"), bytes)
            })
        }
        Command::Reduce(a) => a.sizes.iter().try_for_each(|&n| {
            // An RGBA32F texture, its data and the ping-pong targets (a third of it).
            check_memory(format!("a {n}² reduction"), 16 * u128::from(n) * u128::from(n) * 3)
        }),
        Command::Voxelize(_) | Command::Subdivide(_) => Ok(()),
    }
}

impl Command {
    /// The suite's name, as `texgeo bench NAME` spells it.
    fn name(&self) -> &'static str {
        match self {
            Command::Inclusion(_) => "inclusion",
            Command::Voxelize(_) => "voxelize",
            Command::Scale(_) => "scale",
            Command::Xor(_) => "xor",
            Command::Reduce(_) => "reduce",
            Command::Subdivide(_) => "subdivide",
            Command::Boolean(_) => "boolean",
        }
    }

    /// The report folder.
    fn out(&self) -> &std::path::Path {
        match self {
            Command::Inclusion(InclusionArgs { out, .. })
            | Command::Voxelize(VoxelizeArgs { out, .. })
            | Command::Scale(ScaleArgs { out, .. }) => out,
            Command::Xor(XorArgs { common, .. })
            | Command::Reduce(ReduceArgs { common, .. })
            | Command::Subdivide(SubdivideArgs { common, .. })
            | Command::Boolean(BooleanArgs { common, .. }) => &common.out,
        }
    }
}

pub fn run(device: Option<&str>, cmd: Command) -> anyhow::Result<()> {
    // The report folder must take files before hours of measuring start.
    texgeo::output::check_dir(cmd.out())?;
    check_sizes(&cmd)?;
    let ctx = crate::open_context(device)?;
    let around = Around { lines: texgeo::report::Lines::new("texgeo bench"), name: cmd.name() };
    measure(&ctx, cmd, &around)
}

/// A start and an end line with the time taken around the measuring, once the options
/// are checked (a refused option stays one line): a log of a long run is never silent.
struct Around {
    lines: texgeo::report::Lines,
    name: &'static str,
}

impl Around {
    fn run<T>(&self, f: impl FnOnce() -> T) -> T {
        self.lines.started(self.name);
        let start = std::time::Instant::now();
        let v = f();
        self.lines.ended(self.name, start.elapsed());
        v
    }
}

/// Runs the suite: each checks its own options and loads its models, then measures.
fn measure(ctx: &Context, cmd: Command, around: &Around) -> anyhow::Result<()> {
    match cmd {
        Command::Inclusion(a) => measure_inclusion(ctx, a, around),
        Command::Voxelize(a) => measure_voxelize(ctx, a, around),
        Command::Scale(a) => measure_scale(ctx, a, around),
        Command::Boolean(a) => measure_boolean(ctx, a, around),
        Command::Xor(a) => {
            check_sides(ctx, &a.sizes)?;
            finish(around.run(|| bench::xor::run(ctx, &a.sizes, a.triangles, a.common.runs))?, &a.common)
        }
        Command::Reduce(a) => {
            check_sides(ctx, &a.sizes)?;
            finish(around.run(|| bench::reduce::run(ctx, &a.sizes, a.common.runs))?, &a.common)
        }
        Command::Subdivide(a) => measure_subdivide(ctx, a, around),
    }
}

fn measure_inclusion(ctx: &Context, a: InclusionArgs, around: &Around) -> anyhow::Result<()> {
    let models = a.models.load(bench::inclusion::STAND_INS, |thesis, name, mesh| {
        Ok(bench::inclusion::Model { thesis, name, mesh })
    })?;
    let cfg = bench::inclusion::Config { sets: a.sets, points: a.points, resolutions: a.resolutions };
    finish(around.run(|| bench::inclusion::run(ctx, &models, &cfg))?, &Common { runs: 0, out: a.out })
}

fn measure_voxelize(ctx: &Context, a: VoxelizeArgs, around: &Around) -> anyhow::Result<()> {
    let methods = if a.methods.is_empty() { texgeo::voxel::Method::ALL.to_vec() } else { a.methods };
    for &n in &a.sizes {
        texgeo::voxel::grid::check_resolution(n)?;
    }
    let models = a.models.load(bench::voxelize::STAND_INS, |thesis, name, mesh| {
        Ok(bench::voxelize::Model { thesis, name, mesh })
    })?;
    anyhow::ensure!(!models.is_empty(), "no models to measure");
    let cfg = bench::voxelize::Config { resolutions: a.sizes, methods, runs: a.runs, zone: a.zone };
    finish(around.run(|| bench::voxelize::run(ctx, &models, &cfg))?, &Common { runs: a.runs, out: a.out })
}

fn measure_scale(ctx: &Context, a: ScaleArgs, around: &Around) -> anyhow::Result<()> {
    use texgeo::inclusion::{Choice, Method};
    let (inclusion, voxel) = scale_models(a.mesh, a.voxel_mesh, &a.models_dir)?;
    anyhow::ensure!(a.points.iter().all(|&n| n > 0), "--points takes counts ≥ 1");
    for &n in &a.sizes {
        texgeo::voxel::grid::check_resolution(n)?;
    }
    let methods = if a.methods.is_empty() {
        std::iter::once(Choice::Auto).chain(Method::ALL.map(Choice::Fixed)).collect()
    } else {
        a.methods
    };
    let voxel_methods =
        if a.voxel_methods.is_empty() { texgeo::voxel::Method::ALL.to_vec() } else { a.voxel_methods };
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut threads = if a.thread_counts.is_empty() { vec![1, cores] } else { a.thread_counts };
    threads.dedup();
    let (points, sizes, runs, budget) = (a.points, a.sizes, a.runs, a.budget);
    let cfg = bench::scale::Config { points, methods, sizes, voxel_methods, threads, runs, budget };
    finish(around.run(|| bench::scale::run(ctx, &inclusion, &voxel, &cfg))?, &Common { runs, out: a.out })
}

fn measure_boolean(ctx: &Context, a: BooleanArgs, around: &Around) -> anyhow::Result<()> {
    use bench::boolean::{Config, Pair, STAND_INS};
    anyhow::ensure!(a.method.is_cpu(), "--method takes a CPU inclusion method (the GPU one always runs)");
    let pairs = if a.scaling_only {
        Vec::new()
    } else {
        a.models.load(STAND_INS, |thesis, name, mesh| Ok(Pair::with_turned_copy(thesis, name, mesh)?))?
    };
    if let Some(dir) = &a.write_scaling {
        write_scaling_pairs(dir, &a.scaling)?;
    }
    let cfg = Config {
        runs: a.common.runs,
        cpu_method: a.method,
        plain: !a.no_plain,
        cgal: !a.no_cgal,
        scaling: a.scaling.into_iter().filter(|&n| n > 0).collect(),
    };
    finish(around.run(|| bench::boolean::run(ctx, &pairs, &cfg))?, &a.common)
}

fn measure_subdivide(ctx: &Context, a: SubdivideArgs, around: &Around) -> anyhow::Result<()> {
    use bench::subdiv::{CreaseSettings, Settings, crease_models, default_models};
    let common = &a.common;
    if a.creases {
        anyhow::ensure!((0.0..=180.0).contains(&a.crease_angle), "--crease-angle must be in 0..=180");
        let list = subdivide_models(if a.only { Vec::new() } else { crease_models(&a.models)? }, &a.meshes)?;
        let settings = CreaseSettings {
            level: a.level,
            runs: common.runs,
            angle_degrees: a.crease_angle,
            sharpness: &[10.0, 2.5],
        };
        return finish(around.run(|| bench::subdiv::run_creases(ctx, &list, settings))?, common);
    }
    let list = subdivide_models(if a.only { Vec::new() } else { default_models(&a.models)? }, &a.meshes)?;
    let settings = Settings { level: a.level, runs: common.runs, validate: a.validate };
    finish(around.run(|| bench::subdiv::run(ctx, &list, settings))?, common)
}

/// `bench xor` and `bench reduce`: every side a 2D texture of the device takes.
fn check_sides(ctx: &Context, sizes: &[u32]) -> anyhow::Result<()> {
    if let Some(bad) = sizes.iter().find(|&&s| s == 0 || s > ctx.info().max_image_2d) {
        anyhow::bail!("size {bad} is outside 1..={}", ctx.info().max_image_2d);
    }
    Ok(())
}

/// The meshes of `bench scale`: the inclusion mesh (`--mesh`, else the armadillo when
/// fetched, else the knot) and the voxelization mesh (`--voxel-mesh`, else the same).
fn scale_models(
    mesh: Option<MeshArg>,
    voxel_mesh: Option<MeshArg>,
    models_dir: &std::path::Path,
) -> anyhow::Result<(bench::scale::Model, bench::scale::Model)> {
    use bench::scale::Model;
    let mesh = mesh.unwrap_or_else(|| {
        let armadillo = models_dir.join("armadillo.off");
        if armadillo.exists() { armadillo.into() } else { "builtin:knot".into() }
    });
    let inclusion = Model { name: mesh.to_string(), mesh: solid_in_its_units(&mesh)? };
    let voxel = match voxel_mesh {
        Some(v) => Model { name: v.to_string(), mesh: solid_in_its_units(&v)? },
        None => Model { name: inclusion.name.clone(), mesh: inclusion.mesh.clone() },
    };
    Ok((inclusion, voxel))
}

/// `--write-scaling DIR`: both operands of every scaling size as `sphere-N-a.off` and
/// `sphere-N-b.off`.
fn write_scaling_pairs(dir: &std::path::Path, scaling: &[usize]) -> anyhow::Result<()> {
    texgeo::output::check_dir(dir)?;
    for &n in scaling.iter().filter(|&&n| n > 0) {
        let pair = bench::boolean::scaling_pair(n)?;
        for (side, mesh) in [("a", &pair.a), ("b", &pair.b)] {
            let path = dir.join(format!("sphere-{n}-{side}.off"));
            texgeo::mesh::formats::write(&path, mesh)
                .with_context(|| format!("writing {}", path.display()))?;
        }
    }
    Ok(())
}

/// The models of `bench subdivide`: `list` and then the `--mesh` ones; at least one.
fn subdivide_models(
    mut list: Vec<bench::subdiv::Model>,
    meshes: &[MeshArg],
) -> anyhow::Result<Vec<bench::subdiv::Model>> {
    for m in meshes {
        list.push(bench::subdiv::Model { name: m.to_string(), mesh: crate::mesh::load(m)? });
    }
    anyhow::ensure!(!list.is_empty(), "no models to measure");
    Ok(list)
}

/// A mesh that must be a solid, in its own units (the benchmark writes its voxels and
/// times the methods on the mesh as given).
fn solid_in_its_units(spec: &crate::mesh::MeshArg) -> anyhow::Result<texgeo::mesh::Mesh> {
    let solid = crate::mesh::load_solid(spec, Default::default(), &[])?;
    Ok(solid.frame.mesh_out(solid.mesh)?)
}

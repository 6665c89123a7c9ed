//! `texgeo voxelize MESH --res N [--method …] -o OUT.binvox [--slices DIR]
//! [--aspect perlin --aspect-out DIR]`: solid voxelization by tetra slicing.

use std::path::PathBuf;

use texgeo::mesh::solidity::Policy;
use texgeo::voxel::aspect::{self, Aspect, Material};
use texgeo::voxel::{
    Choice, Grid, Method, Solid, Summary, Timings, Voxelizer, Zone, binvox, choose_method, npy, pictures,
};

/// Aspect functions (Fig. 5-9).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum AspectKind {
    /// 3D Perlin noise in a fragment shader.
    Perlin,
}

#[derive(clap::Args)]
pub struct Args {
    /// The solid: a mesh file (.obj .off .ply .stl) or `builtin:NAME` (see `texgeo mesh builtins`).
    mesh: crate::mesh::MeshArg,
    /// Voxels per side (N×N×N over the mesh's bounding cube), 1..=1024.
    #[arg(long, short)]
    res: usize,
    /// auto (the fastest for this device, mesh and resolution, by measured cost models;
    /// named on stderr), cpu, fgpu, pgpu, zoned, fang or scanline: all give the same voxels.
    #[arg(long, short, default_value_t = Choice::Auto)]
    method: Choice,
    /// Output file, written atomically: .binvox, or .npy (an N×N×N bool array indexed
    /// [x, y, z]; the grid — origin, pitch — in a .json file of the same stem beside it).
    #[arg(long, short)]
    output: PathBuf,
    /// Also write one PNG per y slice into this folder.
    #[arg(long)]
    slices: Option<PathBuf>,
    /// Colour the voxels with an aspect function.
    #[arg(long, value_enum)]
    aspect: Option<AspectKind>,
    /// Folder for the coloured slices (default: OUTPUT's stem + `-aspect`).
    #[arg(long)]
    aspect_out: Option<PathBuf>,
    /// Perlin material.
    #[arg(long, value_enum, default_value_t = Material::Marble)]
    material: Material,
    /// Noise periods across the grid (a finite number > 0).
    #[arg(long, default_value_t = 4.0, value_parser = crate::args::positive_f32)]
    frequency: f32,
    /// Zone height in slices for `zoned`: a number ≥ 1, or `auto` (N/8, between 4 and 32).
    #[arg(long, default_value_t = Zone::Auto)]
    zone: Zone,
    /// Reverse every face of an inverted solid (faces pointing inwards) instead of refusing it.
    #[arg(long)]
    flip_inverted: bool,
    /// Accept a mesh that is not a solid (open, self-intersecting, nested or inverted): a
    /// voxel is then occupied iff its centre is inside by `inclusion --allow-open` (the
    /// generalized winding number at least ½; centres on the boundary are empty), computed
    /// on the CPU with a certified error bound (`auto`, `cpu` and `scanline` do this; the
    /// GPU methods refuse such a mesh). Solids are voxelized as without the flag.
    #[arg(long)]
    allow_open: bool,
    /// Print one JSON object on stdout (resolution, occupied voxels, method, grid, times in
    /// ms); the text lines go to stderr.
    #[arg(long)]
    json: bool,
}

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    let aspect_dir = check_outputs(&args)?;
    let npy = npy::is_npy(&args.output);
    let policy =
        Policy { flip_inverted: args.flip_inverted, allow_open: args.allow_open, ..Policy::default() };
    let solid = crate::mesh::load_solid(&args.mesh, policy, &["--flip-inverted", "--allow-open"])?;
    if solid.flipped {
        note!("texgeo: note: {} was inverted; its faces were reversed (--flip-inverted)", args.mesh);
    }
    let mesh = solid.mesh;
    let grid = Grid::for_mesh(&mesh, args.res)?.in_frame(solid.frame);
    if let Some(defect) = &solid.non_solid {
        texgeo::voxel::check_non_solid(args.method).map_err(|e| anyhow::anyhow!("{}: {e}", args.mesh))?;
        crate::mesh::warn_non_solid(&args.mesh, defect);
        return by_winding_number(device, &args, &mesh, &grid, aspect_dir.as_deref());
    }
    let solid = Solid::new(&mesh)?;
    let chosen = choose_method(args.method, &solid, &grid, args.aspect.is_some(), |fixed| {
        let hint = match fixed {
            None => "scanline",
            Some(m) if m.uses_gpu() => "cpu or scanline",
            Some(_) => "cpu, without --aspect",
        };
        crate::open_context_for(device, hint)
    })?;
    if let Some(plan) = &chosen.plan {
        note!("texgeo: --method auto: {}", plan.describe());
    }
    let (method, ctx) = (chosen.method, chosen.ctx);
    if let Some(ctx) = &ctx {
        say!("device: {}", ctx.info().label());
    }
    if method == Method::Scanline && args.slices.is_none() && args.aspect.is_none() && !npy {
        return scanline_to_file(&args, &grid, &solid);
    }
    let mut voxelizer = Voxelizer::new(ctx.clone());
    voxelizer.zone = args.zone;
    let result = voxelizer.run(&solid, &grid, method)?;
    let t = result.timings;
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    say!(
        "{}: {}³ voxels, {} occupied, method {} in {:.1} ms (prepare {:.1}, draw {:.1}, copy {:.1}, readback {:.1}, exact fallback {:.1})",
        args.mesh,
        args.res,
        result.volume.count(),
        method,
        ms(t.total),
        ms(t.prepare),
        ms(t.draw),
        ms(t.copy),
        ms(t.readback),
        ms(t.fallback)
    );
    if result.band.tolerance > 0.0 {
        say!(
            "exact fallback: {} voxel centres within {:.3e} voxels of the surface decided exactly, {} corrected",
            result.band.candidates,
            result.band.tolerance,
            result.band.changed
        );
    }
    write_outputs(&args, &grid, &result.volume, ctx.as_ref(), aspect_dir.as_deref())?;
    if args.json {
        let mut summary = Summary::new(&grid, result.volume.count(), method.name(), t, &args.output);
        summary.exact_fallback = (result.band.tolerance > 0.0).then_some(result.band);
        summary.device = ctx.as_ref().map(|c| c.info().label());
        texgeo::json::print(&summary);
    }
    Ok(())
}

/// Checks the request and every output path before touching the mesh or the device;
/// the folder of the aspect pictures, when asked for.
fn check_outputs(args: &Args) -> anyhow::Result<Option<PathBuf>> {
    texgeo::voxel::grid::check_resolution(args.res)?;
    texgeo::output::check_extension(
        &args.output,
        &["binvox", "npy"],
        "the volume is written as binvox or NumPy",
    )?;
    let inputs = crate::mesh::MeshArg::files([&args.mesh]);
    texgeo::output::check_output(&args.output, &inputs)?;
    if npy::is_npy(&args.output) {
        texgeo::output::check_output(npy::sidecar(&args.output), &inputs)?;
    }
    if args.json {
        texgeo::json::text_to_stderr();
    }
    if let Some(dir) = &args.slices {
        texgeo::output::check_dir(dir)?;
    }
    let aspect_dir = args.aspect.map(|_| {
        args.aspect_out.clone().unwrap_or_else(|| {
            let stem = args.output.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            args.output.with_file_name(format!("{stem}-aspect"))
        })
    });
    if let Some(dir) = &aspect_dir {
        texgeo::output::check_dir(dir)?;
    }
    Ok(aspect_dir)
}

/// A mesh that is not a solid (`--allow-open`): the voxels whose centres are inside by
/// the generalized winding number.
fn by_winding_number(
    device: Option<&str>,
    args: &Args,
    mesh: &texgeo::mesh::Mesh,
    grid: &Grid,
    aspect_dir: Option<&std::path::Path>,
) -> anyhow::Result<()> {
    let t = std::time::Instant::now();
    let volume = texgeo::voxel::voxelize_non_solid(mesh, grid)?;
    say!(
        "{}: {}³ voxels, {} occupied, generalized winding number ≥ ½ (fast-winding) in {:.1} ms",
        args.mesh,
        args.res,
        volume.count(),
        t.elapsed().as_secs_f64() * 1e3
    );
    let timings = Timings { total: t.elapsed(), ..Timings::default() };
    let ctx = match args.aspect {
        Some(_) => Some(crate::open_context_for(device, "cpu, without --aspect")?),
        None => None,
    };
    write_outputs(args, grid, &volume, ctx.as_ref(), aspect_dir)?;
    if args.json {
        texgeo::json::print(&Summary::new(grid, volume.count(), "fast-winding", timings, &args.output));
    }
    Ok(())
}

/// Only the file is wanted: it is written while the volume is computed, a few x planes
/// in memory at a time instead of N³ bits.
fn scanline_to_file(args: &Args, grid: &Grid, solid: &Solid) -> anyhow::Result<()> {
    let t = std::time::Instant::now();
    let streamed = binvox::write_scanline(&args.output, grid, solid)?;
    say!(
        "{}: {}³ voxels, {} occupied, method scanline in {:.1} ms, written to {} as computed{}",
        args.mesh,
        args.res,
        streamed.occupied,
        t.elapsed().as_secs_f64() * 1e3,
        args.output.display(),
        if streamed.whole_volume {
            " (a row met the surface an odd number of times: whole volume)"
        } else {
            ""
        }
    );
    if args.json {
        let timings = Timings { total: t.elapsed(), ..Timings::default() };
        texgeo::json::print(&Summary::new(grid, streamed.occupied, "scanline", timings, &args.output));
    }
    Ok(())
}

/// Writes the volume (binvox or .npy), and the slices and aspect pictures when asked for.
fn write_outputs(
    args: &Args,
    grid: &Grid,
    volume: &texgeo::voxel::Volume,
    ctx: Option<&texgeo::gpu::Context>,
    aspect_dir: Option<&std::path::Path>,
) -> anyhow::Result<()> {
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    let t = std::time::Instant::now();
    npy::write_by_extension(&args.output, grid, volume)?;
    say!("wrote {} in {:.1} ms", args.output.display(), ms(t.elapsed()));
    if let Some(dir) = &args.slices {
        let files = pictures::write_slices(volume, dir)?;
        say!("wrote {} slice PNGs into {}", files.len(), dir.display());
    }
    if let (Some(dir), Some(ctx)) = (aspect_dir, ctx) {
        let params = Aspect { material: args.material, frequency: args.frequency, ..Aspect::default() };
        // Slices stream to PNG files a group at a time; the front view is built as they pass.
        let mut picture = pictures::front_canvas(args.res);
        let mut count = 0;
        aspect::render_each(ctx, volume, &params, |j, pixels| {
            pictures::write_rgba_slice(args.res, j, pixels, dir)?;
            pictures::front_row(volume, j, Some(pixels), &mut picture);
            count += 1;
            Ok(())
        })?;
        let front = dir.join("front.png");
        texgeo::output::write_png(&front, &picture)?;
        say!(
            "wrote {} {} aspect slices and a rendered view front.png into {}",
            count,
            args.material.name(),
            dir.display()
        );
    }
    Ok(())
}

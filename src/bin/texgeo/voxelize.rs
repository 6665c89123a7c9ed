//! `texgeo voxelize MESH --res N [--method …] -o OUT.binvox [--slices DIR]
//! [--aspect perlin --aspect-out DIR]`: solid voxelization by tetra slicing (issue 4).

use std::path::PathBuf;

use anyhow::Context as _;
use texgeo::voxel::aspect::{self, Aspect, Material};
use texgeo::voxel::{Grid, Method, Solid, Voxelizer, binvox, pictures};

#[derive(clap::Args)]
pub struct Args {
    /// A closed mesh (.obj .off .ply .stl).
    mesh: String,
    /// Voxels per side (N×N×N over the mesh's bounding cube), 1..=1024.
    #[arg(long, short)]
    res: usize,
    /// cpu | fgpu | pgpu | zoned | fang | scanline (all give the same voxels).
    #[arg(long, short, default_value = "zoned", value_parser = parse_method)]
    method: Method,
    /// Output .binvox file.
    #[arg(long, short)]
    output: PathBuf,
    /// Also write one PNG per y slice into this folder.
    #[arg(long)]
    slices: Option<PathBuf>,
    /// Colour the voxels with an aspect function (Fig. 5-9); only `perlin` exists.
    #[arg(long, value_parser = ["perlin"])]
    aspect: Option<String>,
    /// Folder for the coloured slices (default: OUTPUT's stem + `-aspect`).
    #[arg(long)]
    aspect_out: Option<PathBuf>,
    /// Perlin material: marble | wood | granite.
    #[arg(long, default_value = "marble", value_parser = parse_material)]
    material: Material,
    /// Noise periods across the grid.
    #[arg(long, default_value_t = 4.0)]
    frequency: f32,
    /// Zone height in slices for `zoned` (default: chosen from the mesh and memory).
    #[arg(long)]
    zone: Option<usize>,
}

fn parse_method(s: &str) -> Result<Method, String> {
    Method::parse(s).ok_or_else(|| {
        format!("unknown method '{s}' (expected {})", Method::ALL.map(|m| m.name()).join(", "))
    })
}

fn parse_material(s: &str) -> Result<Material, String> {
    Material::parse(s).ok_or_else(|| format!("unknown material '{s}' (expected marble, wood or granite)"))
}

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    let mesh = crate::mesh::load(&args.mesh)?;
    // Check the request before touching the mesh or the device.
    let grid = Grid::for_mesh(&mesh, args.res)?;
    let solid = Solid::new(&mesh).with_context(|| format!("voxelizing {}", args.mesh))?;
    let needs_gpu = args.method.uses_gpu() || args.aspect.is_some();
    let ctx = if needs_gpu { Some(crate::open_context(device)?) } else { None };
    if let Some(ctx) = &ctx {
        println!("device: {}", ctx.info().label());
    }
    let mut voxelizer = Voxelizer::new(ctx.clone());
    voxelizer.zone = args.zone;
    let result = voxelizer.run(&solid, &grid, args.method)?;
    let t = result.timings;
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    println!(
        "{}: {}³ voxels, {} occupied, method {} in {:.1} ms (prepare {:.1}, draw {:.1}, copy {:.1}, readback {:.1}, exact fallback {:.1})",
        args.mesh,
        args.res,
        result.volume.count(),
        args.method,
        ms(t.total),
        ms(t.prepare),
        ms(t.draw),
        ms(t.copy),
        ms(t.readback),
        ms(t.fallback)
    );
    if result.band.tolerance > 0.0 {
        println!(
            "exact fallback: {} voxel centres within {:.3e} voxels of the surface decided exactly, {} corrected",
            result.band.candidates, result.band.tolerance, result.band.changed
        );
    }
    binvox::write(&args.output, &grid, &result.volume)?;
    println!("wrote {}", args.output.display());
    if let Some(dir) = &args.slices {
        let files = pictures::write_slices(&result.volume, dir)?;
        println!("wrote {} slice PNGs into {}", files.len(), dir.display());
    }
    if args.aspect.is_some() {
        let ctx = ctx.as_ref().context("the aspect function needs a Vulkan device")?;
        let dir = args.aspect_out.clone().unwrap_or_else(|| {
            let stem = args.output.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            args.output.with_file_name(format!("{stem}-aspect"))
        });
        let params = Aspect { material: args.material, frequency: args.frequency, ..Aspect::default() };
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        // Slices stream to PNG files a group at a time; the front view is built as they pass.
        let mut picture = pictures::front_canvas(args.res);
        let mut count = 0;
        aspect::render_each(ctx, &result.volume, &params, |j, pixels| {
            pictures::write_rgba_slice(args.res, j, pixels, &dir)?;
            pictures::front_row(&result.volume, j, Some(pixels), &mut picture);
            count += 1;
            Ok(())
        })?;
        let front = dir.join("front.png");
        picture.save(&front).with_context(|| format!("writing {}", front.display()))?;
        println!(
            "wrote {} {} aspect slices and a rendered view {} into {}",
            count,
            args.material.name(),
            front.file_name().map(|f| f.to_string_lossy()).unwrap_or_default(),
            dir.display()
        );
    }
    Ok(())
}

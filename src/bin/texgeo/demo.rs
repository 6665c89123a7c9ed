//! `texgeo demo`: a short run of each algorithm on built-in data, for a first look.

use std::path::PathBuf;

use anyhow::Context as _;
use texgeo::gpu::{TexFormat, XorRaster, reduce_sum};
use texgeo::mesh::procedural;
use texgeo::random::Rng;
use texgeo::voxel;

#[derive(clap::Args)]
pub struct Args {
    /// Folder for pictures and outputs.
    #[arg(short, long = "output", alias = "out", value_name = "DIR", default_value = "out/demo")]
    out: PathBuf,
}

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    texgeo::output::check_dir(&args.out)?;
    let ctx = crate::open_context(device)?;
    say!("device: {}", ctx.info().label());

    // 1. Reduction: sum a 512×512 texture of random integers on the GPU and on the CPU.
    let n = 512u32;
    let mut rng = Rng::new(1);
    let data: Vec<[f32; 4]> =
        (0..n * n).map(|_| std::array::from_fn(|_| rng.below(5) as f32 - 2.0)).collect();
    let t = std::time::Instant::now();
    let gpu = reduce_sum(&ctx, &data, n, n)?;
    let gpu_ms = t.elapsed().as_secs_f64() * 1e3;
    let cpu = texgeo::report::bench::reduce::cpu_sum(&data);
    say!(
        "reduce_sum {n}x{n} RGBA32F: GPU {gpu:?} ({gpu_ms:.1} ms incl. upload), CPU {cpu:?}: {}",
        if gpu == cpu { "equal" } else { "DIFFERENT" }
    );
    anyhow::ensure!(gpu == cpu, "GPU and CPU sums differ");

    // 2. XOR raster: a fan of overlapping triangles; parity leaves a star pattern.
    let size = 256u32;
    let c = size as f32 / 2.0;
    let k = 7;
    let tris: Vec<[[f32; 2]; 3]> = (0..k)
        .map(|i| {
            let a = |j: usize| {
                let t = std::f32::consts::TAU * ((i * 3 + j) % k) as f32 / k as f32;
                [c + 0.45 * size as f32 * t.cos(), c + 0.45 * size as f32 * t.sin()]
            };
            [a(0), a(1), a(2)]
        })
        .collect();
    let xor = XorRaster::new(&ctx, TexFormat::R8Ui)?;
    let bits = xor.rasterize(&ctx, size, size, &tris, 1)?;
    let pixels: Vec<u8> = bits.iter().map(|&b| if b & 1 == 1 { 255 } else { 0 }).collect();
    let png = args.out.join("xor-star.png");
    texgeo::output::write_png(&png, &image::GrayImage::from_raw(size, size, pixels).context("image size")?)?;
    let set = bits.iter().filter(|&&b| b & 1 == 1).count();
    say!("XOR raster: {k} overlapping triangles -> {set} texels of odd parity, picture {}", png.display());

    // 3. The built-in models and what the mesh checks say about them.
    say!("\nbuilt-in models:");
    say!(
        "{:<12} {:>6} {:>6} {:>7} {:>9} {:>9} {:>4}",
        "name",
        "V",
        "F",
        "closed",
        "oriented",
        "manifold",
        "chi"
    );
    for name in procedural::BUILTIN_NAMES {
        let Some(m) = procedural::by_name(name) else { continue };
        let r = m.report();
        let yn = |b: bool| if b { "yes" } else { "no" };
        say!(
            "{name:<12} {:>6} {:>6} {:>7} {:>9} {:>9} {:>4}",
            m.num_vertices(),
            m.num_faces(),
            yn(r.is_closed()),
            yn(r.is_oriented()),
            yn(r.is_manifold()),
            r.euler_characteristic
        );
    }

    // 4. Point in solid on the GPU, checked against the exact CPU test and the oracle.
    inclusion(&ctx, &args.out)?;

    // 5. Catmull-Clark with fragment meshes on the GPU, checked against the references.
    subdivision(&ctx, &args.out)?;

    // 6. Solid voxelization by tetra slicing, checked against the exact scanline.
    voxelization(&ctx, &args.out)
}

/// A 256×256 grid of points on the plane z = 0 through the torus knot, classified by the
/// GPU Feito-Torres test, the exact CPU test and Jordan ray crossings, as a picture.
fn inclusion(ctx: &texgeo::gpu::Context, out: &std::path::Path) -> anyhow::Result<()> {
    use texgeo::inclusion::solver::Solver;
    use texgeo::inclusion::{Class, Method, Options};
    let knot = procedural::torus_knot();
    let (lo, hi) = knot.bounds();
    let n = 256;
    let points: Vec<glam::DVec3> = (0..n * n)
        .map(|k| {
            let (i, j) = ((k % n) as f64 + 0.5, (k / n) as f64 + 0.5);
            glam::DVec3::new(lo.x + (hi.x - lo.x) * i / n as f64, hi.y - (hi.y - lo.y) * j / n as f64, 0.0)
        })
        .collect();
    say!(
        "
point in solid, {} points on the plane z = 0 through builtin:knot:",
        points.len()
    );
    let mut answers = Vec::new();
    for method in [Method::Gpu, Method::GpuTetraGrid, Method::Cpu, Method::TetraGrid, Method::JordanOctree] {
        let mut solver = Solver::new(method, &knot, &Options::default(), Some(ctx), None)?;
        let t = std::time::Instant::now();
        let classes = solver.classify_all(&points)?;
        let inside = classes.iter().filter(|&&c| c == Class::Inside).count();
        say!("  {:<14} {inside:>6} inside in {:>7.1} ms", method.name(), t.elapsed().as_secs_f64() * 1e3);
        answers.push(classes);
    }
    let agree = answers.windows(2).all(|w| w[0] == w[1]);
    say!("  all methods agree point for point: {}", if agree { "yes" } else { "NO" });
    anyhow::ensure!(agree, "inclusion methods disagree");
    let pixels: Vec<u8> = answers[0]
        .iter()
        .map(|c| match c {
            Class::Inside => 255,
            Class::OnBoundary => 128,
            Class::Outside => 0,
        })
        .collect();
    let png = out.join("inclusion-knot-slice.png");
    texgeo::output::write_png(
        &png,
        &image::GrayImage::from_raw(n as u32, n as u32, pixels).context("image size")?,
    )?;
    say!("  picture {}", png.display());
    Ok(())
}

/// The cube (the thesis' 8 fragments) and the 1200-triangle torus knot to level 3 on the
/// GPU, compared with the CPU reference and OpenSubdiv, written as OBJ.
fn subdivision(ctx: &texgeo::gpu::Context, out: &std::path::Path) -> anyhow::Result<()> {
    use texgeo::subdiv::{compare::Comparison, cpu, gpu, osd};
    say!("\nCatmull-Clark, level 3 (fragment passes on the GPU vs references):");
    let mut subdivider = gpu::Subdivider::new(ctx)?;
    for name in ["cube", "knot"] {
        let Some(mesh) = procedural::by_name(name) else { continue };
        let run = subdivider.refine(ctx, &mesh, 3, &gpu::Options::default())?;
        let refined = &run.mesh;
        let error = |reference: &texgeo::mesh::Mesh| {
            let c = Comparison::new(refined, reference, 1e-5);
            let verdict = if c.is_match() { "match" } else { "MISMATCH" };
            format!("{verdict}, max error {:.1e} × diagonal", c.max_error / c.diagonal.max(f64::MIN_POSITIVE))
        };
        let vs_cpu = error(&cpu::refine(&mesh, 3)?);
        let vs_osd = match osd::refine(&mesh, 3) {
            Ok(reference) => error(&reference),
            Err(e) => format!("not run ({e})"),
        };
        let file = out.join(format!("subdiv-{name}-level3.obj"));
        texgeo::mesh::formats::write(&file, refined)?;
        say!(
            "{name}: {} fragments, {} CPU + {} GPU levels -> {} vertices, {} quads in {:.1} ms, {}",
            run.fragments,
            run.cpu_levels,
            run.gpu_levels,
            refined.num_vertices(),
            refined.num_faces(),
            run.times.total.as_secs_f64() * 1e3,
            file.display()
        );
        say!("  vs CPU reference: {vs_cpu}; vs OpenSubdiv: {vs_osd}");
    }
    Ok(())
}

/// The torus knot voxelized at 96³ by the zoned vertex shader (Alg. 5-2, PGPU-MP),
/// checked against the exact scanline, written as binvox, PNG slices, Perlin marble
/// slices (Fig. 5-9) and a rendered view.
fn voxelization(ctx: &texgeo::gpu::Context, out: &std::path::Path) -> anyhow::Result<()> {
    let knot = procedural::torus_knot();
    let n = 96;
    let grid = voxel::Grid::for_mesh(&knot, n)?;
    let solid = voxel::Solid::new(&knot)?;
    let mut voxelizer = voxel::Voxelizer::new(Some(ctx.clone()));
    let zoned = voxelizer.run(&solid, &grid, voxel::Method::Zoned)?;
    let exact = voxelizer.run(&solid, &grid, voxel::Method::Scanline)?;
    anyhow::ensure!(zoned.volume == exact.volume, "zoned and scanline voxelizations differ");
    let binvox_path = out.join("knot.binvox");
    voxel::binvox::write(&binvox_path, &grid, &zoned.volume)?;
    let slices = voxel::pictures::write_slices(&zoned.volume, &out.join("knot-slices"))?;
    let colours = voxel::aspect::render(ctx, &zoned.volume, &voxel::aspect::Aspect::default())?;
    voxel::pictures::write_rgba_slices(n, &colours, &out.join("knot-aspect"))?;
    let picture = out.join("knot-voxels.png");
    texgeo::output::write_png(&picture, &voxel::pictures::render_front(&zoned.volume, Some(&colours)))?;
    say!(
        "\nvoxelized the torus knot at {n}³ (zoned, {:.0} ms): {} voxels occupied, equal to the exact scanline; \
         {} centres near the surface decided exactly; wrote {}, {} slice PNGs, marble slices and {}",
        zoned.timings.total.as_secs_f64() * 1e3,
        zoned.volume.count(),
        zoned.band.candidates,
        binvox_path.display(),
        slices.len(),
        picture.display()
    );
    Ok(())
}

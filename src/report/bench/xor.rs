//! `texgeo bench xor`: triangles XOR-rasterized into an integer target with the logic op,
//! against the CPU's half-open scanline rasterizer (`voxel::raster`), bit for bit.

use std::time::{Duration, Instant};

use crate::gpu::{
    Attachment, Buffer, Context, GpuError, Load, Result, TexFormat, Texture, Timestamps, XorRaster,
};
use crate::random::Rng;
use crate::report::{Environment, Report, Samples, Table, time_runs};
use crate::voxel::raster::triangle_spans;

/// Target sides measured by default.
pub const DEFAULT_SIDES: &[u32] = &[256, 1024, 4096];

/// `count` random triangles in an n×n target (texel units), up to n/16 across, with
/// vertices on the 1/256 sub-pixel grid so the GPU's fixed-point snapping is exact.
fn triangles(n: u32, count: usize) -> Vec<[[f32; 2]; 3]> {
    let mut rng = Rng::new(u64::from(n) * 7919 + count as u64);
    let n = f64::from(n);
    let snap = |v: f64| ((v.clamp(0.0, n) * 256.0).round() / 256.0) as f32;
    (0..count)
        .map(|_| {
            let (cx, cy, r) =
                (rng.range_f64(0.0, n), rng.range_f64(0.0, n), rng.range_f64(0.5, n / 32.0 + 1.0));
            std::array::from_fn(|_| {
                let a = rng.range_f64(0.0, std::f64::consts::TAU);
                [snap(cx + r * a.cos()), snap(cy + r * a.sin())]
            })
        })
        .collect()
}

/// The CPU reference: one u32 per texel, bit 0 flipped by every covering triangle.
pub fn cpu_xor(n: u32, tris: &[[[f32; 2]; 3]]) -> Vec<u32> {
    let side = n as usize;
    let mut bits = vec![0u32; side * side];
    for t in tris {
        let tri = t.map(|v| [f64::from(v[0]), f64::from(v[1])]);
        triangle_spans(tri, side, |row, first, end| {
            for b in &mut bits[row * side + first..row * side + end] {
                *b ^= 1;
            }
        });
    }
    bits
}

pub fn run(ctx: &Context, sides: &[u32], count: usize, runs: usize) -> Result<Report> {
    let mut table = Table::new(
        format!("XOR rasterization of {count} random triangles into an n×n R32UI target (medians)"),
        &[
            "n",
            "GPU draw ms (timestamps)",
            "GPU submit + readback ms",
            "CPU scanline ms",
            "CPU / GPU draw",
            "texels differing",
        ],
    );
    let xor = XorRaster::new(ctx, TexFormat::R32Ui)?;
    let timer = Timestamps::new(ctx, 2)?;
    for &n in sides {
        let tris = triangles(n, count);
        let flat: Vec<[f32; 2]> = tris.iter().flatten().copied().collect();
        let vertices = Buffer::with_data(ctx, &flat, "xor bench triangles")?;
        let target = Texture::new(ctx, TexFormat::R32Ui, n, n, "xor bench target")?;
        let verts = u32::try_from(flat.len()).map_err(|_| GpuError::Usage("too many triangles".into()))?;
        let mut draw = Samples::default();
        let mut gpu_bits = Vec::new();
        let wall = time_runs(runs, || {
            let t = Instant::now();
            let out = ctx.submit(|rec| {
                rec.reset_timestamps(&timer);
                rec.timestamp(&timer, 0)?;
                rec.render(&[Attachment::new(&target, Load::Zero)], None, &[], |pass| {
                    xor.draw(pass, &vertices, verts, [n, n], 1)
                })?;
                rec.timestamp(&timer, 1)?;
                rec.readback(&target)
            })?;
            let elapsed = t.elapsed();
            draw.push(Duration::from_secs_f64(timer.read_ms(2)?[1] / 1e3));
            gpu_bits = out.to_vec::<u32>()?;
            Ok::<_, GpuError>(elapsed)
        })?;
        let mut cpu_bits = Vec::new();
        let cpu = time_runs(runs, || {
            let t = Instant::now();
            cpu_bits = cpu_xor(n, &tris);
            Ok::<_, GpuError>(t.elapsed())
        })?;
        let differing = gpu_bits.iter().zip(&cpu_bits).filter(|(a, b)| a != b).count();
        table.row(vec![
            n.to_string(),
            format!("{:.3}", draw.median_ms()),
            format!("{:.3}", wall.median_ms()),
            format!("{:.3}", cpu.median_ms()),
            format!("{:.2}", cpu.median_ms() / draw.median_ms().max(1e-9)),
            differing.to_string(),
        ]);
    }
    table.note(format!(
        "{runs} timed runs after one warm-up. Triangles up to n/16 texels across, vertices on the 1/256 sub-pixel \
         grid; both sides use the top-left (half-open) rule, so every texel must agree. GPU draw: timestamps around \
         the one draw (logic op XOR into R32UI); submit + readback: wall time including the copy of the n×n target \
         to the host. CPU: one thread, the voxelizer's scanline rasterizer."
    ));
    Ok(Report { name: "xor".into(), environment: Environment::new(ctx.info().label()), tables: vec![table] })
}

//! `texgeo bench reduce`: the 2×2 ping-pong reduction against a plain CPU sum.

use std::time::{Duration, Instant};

use crate::gpu::{Context, Reducer, Result, TexFormat, Texture, Timestamps};
use crate::random::Rng;
use crate::report::{Environment, Report, Samples, Table, time_runs};

/// Sides measured by default (512², 2048², 4096²: from a small to the largest common texture side).
pub const DEFAULT_SIDES: &[u32] = &[512, 2048, 4096];

pub fn run(ctx: &Context, sides: &[u32], runs: usize) -> Result<Report> {
    let mut table = Table::new(
        "2×2 sum reduction of an n×n RGBA32F texture vs a CPU sum (medians)",
        &[
            "n",
            "passes",
            "GPU passes ms (timestamps)",
            "GPU submit+readback ms",
            "upload ms",
            "CPU sum ms",
            "CPU / GPU passes",
            "exact",
        ],
    );
    for &n in sides {
        let mut rng = Rng::new(n as u64);
        let texels = n as usize * n as usize;
        let data: Vec<[f32; 4]> =
            (0..texels).map(|_| std::array::from_fn(|_| rng.below(3) as f32 - 1.0)).collect();
        let tex = Texture::new(ctx, TexFormat::Rgba32F, n, n, "bench input")?;
        let mut reducer = Reducer::new(ctx, n, n, 1)?;
        let timer = Timestamps::new(ctx, 2)?;

        let upload = time_runs(runs, || {
            let t = Instant::now();
            ctx.submit(|rec| rec.upload(&tex, 0, &data))?;
            Ok::<_, crate::gpu::GpuError>(t.elapsed())
        })?;

        let mut gpu_passes = Samples::default();
        let mut result = [0.0f32; 4];
        let wall = time_runs(runs, || {
            let t = Instant::now();
            let buf = ctx.submit(|rec| {
                rec.reset_timestamps(&timer);
                rec.timestamp(&timer, 0)?;
                let out = reducer.record(rec, &tex, n, n)?;
                rec.timestamp(&timer, 1)?;
                rec.readback_region(out, 0..1, [0, 0, 1, 1])
            })?;
            let elapsed = t.elapsed();
            result = buf.to_vec::<[f32; 4]>()?.first().copied().unwrap_or_default();
            let ms = timer.read_ms(2)?;
            gpu_passes.push(Duration::from_secs_f64(ms[1] / 1e3));
            Ok::<_, crate::gpu::GpuError>(elapsed)
        })?;

        let mut cpu = [0.0f32; 4];
        let cpu_time = time_runs(runs, || {
            let t = Instant::now();
            cpu = cpu_sum(&data);
            Ok::<_, crate::gpu::GpuError>(t.elapsed())
        })?;
        let passes = n.max(1).ilog2();
        table.row(vec![
            format!("{n}"),
            format!("{passes}"),
            format!("{:.3}", gpu_passes.median_ms()),
            format!("{:.3}", wall.median_ms()),
            format!("{:.3}", upload.median_ms()),
            format!("{:.3}", cpu_time.median_ms()),
            format!("{:.2}", cpu_time.median_ms() / gpu_passes.median_ms().max(1e-9)),
            format!("{}", if result == cpu { "yes" } else { "NO" }),
        ]);
    }
    table.note(format!(
        "{runs} timed runs after one warm-up. GPU passes: timestamps around the reduction passes only; \
         submit+readback: wall time of one submission that reduces and copies the 1×1 result to the host. \
         CPU sum: one thread, sequential f32 sums per channel. Data: random integers in {{-1, 0, 1}}, so both sums are exact."
    ));
    Ok(Report {
        name: "reduce".into(),
        environment: Environment::new(ctx.info().label()),
        tables: vec![table],
    })
}

/// The plain CPU reference: four sequential f32 channel sums.
pub fn cpu_sum(data: &[[f32; 4]]) -> [f32; 4] {
    let mut s = [0.0f32; 4];
    for t in data {
        for c in 0..4 {
            s[c] += t[c];
        }
    }
    s
}

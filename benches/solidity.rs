//! The solidity check (`mesh::solidity::check`, whose exact self-intersection test is the
//! costly part) on shapes that defeat box-based candidate search, as CSV on stdout:
//!
//!     cargo bench --bench solidity -- [--faces 10000,100000] [--repeat N] [--shape NAME]
//!
//! Shapes (each about `faces` triangles): `bicone`, two fans of long slivers meeting at
//! a ring; `needle`, a cone 100 times taller than wide over a base fanned from its centre
//! (long slivers over a flat fan); `cone`, one apex of valence `faces / 2` over a base
//! kept as one polygon; `sliver`, a cylinder 5 times taller than wide whose sides are
//! long parallel slivers, its caps fanned; `valence`, one apex of valence `faces − 1`
//! over a base kept as one polygon (about `2 · faces` triangles). Seconds are the median and
//! minimum of N runs (default 3), wall clock and CPU (user + system, all threads: what a
//! busy machine does not hide); `load` is the one-minute load average when the row's runs
//! ended (on a shared machine, wall seconds mean little without it).

use std::time::Instant;

use anyhow::{Context, bail};
use texgeo::mesh::{Mesh, procedural, solidity};

/// CPU seconds this process has used so far, all threads.
fn cpu_seconds() -> f64 {
    // SAFETY: getrusage only writes the struct it is given.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) };
    let secs = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    secs(usage.ru_utime) + secs(usage.ru_stime)
}

/// The one-minute load average (Linux), or NaN where it cannot be read.
fn load_average() -> f64 {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().and_then(|x| x.parse().ok()))
        .unwrap_or(f64::NAN)
}

fn shape(name: &str, faces: u32) -> Option<Mesh> {
    let sides = (faces / 2).max(3);
    Some(match name {
        "bicone" => procedural::bicone(sides, 1.0, 1.0),
        "needle" => procedural::bicone(sides, 100.0, 0.0),
        "cone" => procedural::cone(sides),
        "sliver" => procedural::sliver_cylinder((faces / 4).max(3), 10.0),
        "valence" => procedural::cone(faces.saturating_sub(1).max(3)),
        _ => return None,
    })
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).filter(|a| a != "--bench").collect();
    let value = |flag: &str| args.iter().position(|a| a == flag).and_then(|i| args.get(i + 1));
    let repeat: usize = value("--repeat").map_or(Ok(3), |v| v.parse()).context("--repeat")?;
    let faces: Vec<u32> = value("--faces")
        .map_or("10000,100000", String::as_str)
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()
        .context("--faces")?;
    let shapes: Vec<&str> = match value("--shape") {
        Some(s) => vec![s.as_str()],
        None => vec!["bicone", "needle", "cone", "sliver", "valence"],
    };
    println!("shape,faces,triangles,median_s,min_s,median_cpu_s,solid,load");
    for name in shapes {
        for &n in &faces {
            let Some(mesh) = shape(name, n) else { bail!("unknown shape {name}") };
            let triangles: usize = mesh.faces().map(|f| f.len() - 2).sum();
            let (mut seconds, mut cpu) = (Vec::new(), Vec::new());
            let mut solid = false;
            for _ in 0..repeat.max(1) {
                let (start, cpu_start) = (Instant::now(), cpu_seconds());
                let report = solidity::check(&mesh);
                seconds.push(start.elapsed().as_secs_f64());
                cpu.push(cpu_seconds() - cpu_start);
                solid = report.is_solid();
            }
            seconds.sort_by(f64::total_cmp);
            cpu.sort_by(f64::total_cmp);
            let (median, median_cpu) = (seconds[seconds.len() / 2], cpu[cpu.len() / 2]);
            println!(
                "{name},{},{triangles},{median:.3},{:.3},{median_cpu:.3},{solid},{:.1}",
                mesh.num_faces(),
                seconds[0],
                load_average()
            );
        }
    }
    Ok(())
}

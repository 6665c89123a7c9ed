//! `cargo bench --bench sweep`: the per-mesh cost of a sweep over many tiny meshes (200
//! perturbed tetrahedra), for each task: wall time per mesh, the work the worker
//! recorded per mesh (reading, checks and the task itself), and the rest — process and
//! device start amortized, the JSON lines, the fsync'd results line — per mesh. CSV on
//! stdout (`tools/results` saves it under docs/bench/).

use std::process::Command;
use std::time::Instant;

const MESHES: usize = 200;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::temp_dir().join(format!("texgeo-bench-sweep-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let mut rng = texgeo::random::Rng::new(7);
    let mut list = String::new();
    for i in 0..MESHES {
        let jitter = rng.points_in_box(4, glam::DVec3::splat(-0.1), glam::DVec3::splat(0.1));
        let corners = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let mut off = String::from("OFF\n4 4 0\n");
        for (c, d) in corners.iter().zip(&jitter) {
            off += &format!("{} {} {}\n", c[0] + d.x, c[1] + d.y, c[2] + d.z);
        }
        off += "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
        let name = format!("t{i:03}.off");
        std::fs::write(dir.join(&name), off)?;
        list += &name;
        list.push('\n');
    }
    let manifest = dir.join("tiny.txt");
    std::fs::write(&manifest, list)?;

    eprintln!("{MESHES} tetrahedra per sweep, one worker; ms per mesh");
    println!(
        "task,meshes,wall (ms per mesh),in the worker (ms per mesh),rest: start-up + protocol + results line (ms per mesh)"
    );
    for (label, args) in [
        ("inclusion (gpu, 1000 points, cpu check)", &["--task", "inclusion"][..]),
        ("inclusion (cpu, 1000 points, cpu check)", &["--task", "inclusion", "--method", "cpu"][..]),
        ("voxelize (zoned, 32³, scanline check)", &["--task", "voxelize", "--res", "32"][..]),
        ("subdivide (gpu, level 2, cpu check)", &["--task", "subdivide"][..]),
    ] {
        let out = dir.join("out");
        let _ = std::fs::remove_dir_all(&out);
        let start = Instant::now();
        let status = Command::new(env!("CARGO_BIN_EXE_texgeo"))
            .arg("sweep")
            .arg(&manifest)
            .arg("-o")
            .arg(&out)
            .args(args)
            .stdout(std::process::Stdio::null())
            .status()?;
        let wall = start.elapsed().as_secs_f64() * 1e3;
        if !status.success() {
            return Err(format!("sweep {label} failed").into());
        }
        let records = texgeo::sweep::record::read(&out.join("results-0-of-1.jsonl"))?;
        let ok = records.iter().filter(|r| r.outcome == texgeo::sweep::Outcome::Ok).count();
        if ok != MESHES {
            return Err(format!("{label}: only {ok} of {MESHES} meshes ok").into());
        }
        let work: f64 = records.iter().filter_map(|r| r.total_ms()).sum();
        let n = MESHES as f64;
        println!("\"{label}\",{MESHES},{:.2},{:.2},{:.2}", wall / n, work / n, (wall - work) / n);
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok(())
}

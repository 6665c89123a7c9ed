//! CPU Catmull-Clark reference vs OpenSubdiv (refine + interpolate, one thread, minimum
//! of N runs), as CSV on stdout:
//!
//!     cargo bench --bench subdiv_cpu -- [--mesh FILE.off] [--level L] [--repeat N] [--compare]
//!
//! Without `--mesh` the mesh is a 6400-triangle (2,3) torus knot tube, the size of
//! CGAL's `knot1.off`; level 5 gives 4.9 M quads. OpenSubdiv is timed with full topology
//! in the last level (as the comparisons use it) and sparse (drawing only). `--compare`
//! also checks the two results agree (slow: OpenSubdiv's output goes through an OFF file).

#[path = "../tests/common/shapes.rs"]
mod shapes;

use std::time::Instant;

use anyhow::Context;
use texgeo::subdiv::{compare::Comparison, cpu, osd};

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).filter(|a| a != "--bench").collect();
    let value = |flag: &str| args.iter().position(|a| a == flag).and_then(|i| args.get(i + 1));
    let level: u32 = value("--level").map_or(Ok(5), |v| v.parse()).context("--level")?;
    let repeat: u32 = value("--repeat").map_or(Ok(3), |v| v.parse()).context("--repeat")?;
    let (name, mesh) = match value("--mesh") {
        Some(path) => (path.clone(), texgeo::mesh::formats::read(path)?),
        None => ("torus_knot(400,8)".to_string(), shapes::torus_knot(400, 8)),
    };

    let mut cpu_seconds = f64::INFINITY;
    let mut refined = None;
    for _ in 0..repeat.max(1) {
        let start = Instant::now();
        let result = cpu::refine(&mesh, level)?;
        cpu_seconds = cpu_seconds.min(start.elapsed().as_secs_f64());
        refined = Some(result);
    }
    let refined = refined.context("no run")?;
    let surface = texgeo::subdiv::Surface::smooth(mesh.clone());
    let osd_full = osd::time(&surface, level, repeat)?;
    let sparse = osd::Options { repeat: Some(repeat.max(1)), sparse: true, no_output: true };
    let osd_sparse = osd::run(&surface, level, &sparse)?.min_seconds.context("no timing")?;

    println!("mesh,faces,level,refined_vertices,refined_faces,cpu_s,osd_full_s,osd_sparse_s");
    println!(
        "{name},{},{level},{},{},{cpu_seconds:.4},{osd_full:.4},{osd_sparse:.4}",
        mesh.num_faces(),
        refined.num_vertices(),
        refined.num_faces()
    );
    if args.iter().any(|a| a == "--compare") {
        let reference = osd::refine(&mesh, level)?;
        eprintln!("{}", Comparison::new(&refined, &reference, 1e-12));
    }
    Ok(())
}

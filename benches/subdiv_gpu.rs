//! `cargo bench --bench subdiv_gpu`: the same suites as `texgeo bench subdivide` (built-in
//! models, and `models/knot1.off` when `tools/fetch-models` has fetched it) and
//! `texgeo bench subdivide --creases` (sharp features: `models/fandisk.off` and built-ins,
//! creased vs not). Under `cargo test` (no `--bench` argument) it only checks that the
//! suites run: the cube to level 2, one run, nothing written.

use texgeo::report::bench::subdiv::{
    CreaseSettings, Model, Settings, crease_models, default_models, run, run_creases,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let ctx = texgeo::gpu::Context::from_env()?;
    if !std::env::args().any(|a| a == "--bench") {
        let cube = Model { name: "builtin:cube".into(), mesh: texgeo::mesh::procedural::cube() };
        let report = run(&ctx, &[cube], Settings { level: 2, runs: 1, validate: true })?;
        let markdown = report.to_markdown();
        if !markdown.contains("| builtin:cube | 6 | 8 | 96 | 98 |") || !markdown.contains("match") {
            return Err(format!("unexpected report:\n{markdown}").into());
        }
        let cube = Model { name: "builtin:cube".into(), mesh: texgeo::mesh::procedural::cube() };
        let creases = CreaseSettings { level: 2, runs: 1, angle_degrees: 30.0, sharpness: &[10.0] };
        let markdown = run_creases(&ctx, &[cube], creases)?.to_markdown();
        if !markdown.contains("| builtin:cube | 6 | 12 | ∞ | 8 of 8 (100 %) |") {
            return Err(format!("unexpected crease report:\n{markdown}").into());
        }
        return Ok(());
    }
    let models = default_models(std::path::Path::new("models"))?;
    let report = run(&ctx, &models, Settings { level: 5, runs: 5, validate: false })?;
    println!("{}", report.to_markdown());
    report.write(std::path::Path::new("out/bench"))?;
    let models = crease_models(std::path::Path::new("models"))?;
    let creases = CreaseSettings { level: 5, runs: 5, angle_degrees: 30.0, sharpness: &[10.0, 2.5] };
    let report = run_creases(&ctx, &models, creases)?;
    println!("{}", report.to_markdown());
    report.write(std::path::Path::new("out/bench"))?;
    Ok(())
}

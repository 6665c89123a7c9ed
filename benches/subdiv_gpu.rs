//! `cargo bench --bench subdiv_gpu`: the same suite as `texgeo bench subdivide` (built-in
//! models, and `models/knot1.off` when `tools/fetch-models` has fetched it). Under
//! `cargo test` (no `--bench` argument) it only checks that the suite runs: the cube to
//! level 2, one run, nothing written.

use texgeo::report::bench::subdiv::{Model, Settings, default_models, run};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let ctx = texgeo::gpu::Context::from_env()?;
    if !std::env::args().any(|a| a == "--bench") {
        let cube = Model { name: "builtin:cube".into(), mesh: texgeo::mesh::procedural::cube() };
        let report = run(&ctx, &[cube], Settings { level: 2, runs: 1, validate: true })?;
        let markdown = report.to_markdown();
        if !markdown.contains("| builtin:cube | 6 | 8 | 96 | 98 |") || !markdown.contains("match") {
            return Err(format!("unexpected report:\n{markdown}").into());
        }
        return Ok(());
    }
    let models = default_models(std::path::Path::new("models"))?;
    let report = run(&ctx, &models, Settings { level: 5, runs: 5, validate: false })?;
    println!("{}", report.to_markdown());
    report.write(std::path::Path::new("out/bench"))?;
    Ok(())
}
